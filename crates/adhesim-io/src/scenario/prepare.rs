//! Pre-processing of a scenario document before it is read into typed structs:
//!
//! 1. a named variant (`[variants.NAME]`, a table of dotted keys and values) is applied;
//! 2. command-line overrides (`key=value`) are applied;
//! 3. `[parameters]` are evaluated, and every string value that starts with `=` anywhere in
//!    the document is replaced by the number its expression gives.
//!
//! Dotted keys address tables by key and arrays of tables by index or by the `name` of the
//! entry: `contact.indentor.adhesion.cn`, `body.0.material.g`, `time.dt`. A key without a
//! dot that names a parameter addresses that parameter (`v_descent` = `parameters.v_descent`).

use std::collections::BTreeMap;
use toml::{Table, Value};

/// An override `key = value` from the command line or a variant.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// Dotted key.
    pub key: String,
    /// New value.
    pub value: Value,
}

impl Override {
    /// Parses `key=value`; the value is read as a TOML value (number, boolean, array, quoted
    /// string) and, when that fails, taken as a bare string (`model=neo-hookean`).
    pub fn parse(text: &str) -> Result<Override, String> {
        let (key, value) = text
            .split_once('=')
            .ok_or_else(|| format!("`{text}` is not of the form key=value (e.g. time.dt=1e-4)"))?;
        let key = key.trim();
        if key.is_empty() {
            return Err(format!("`{text}` has an empty key"));
        }
        Ok(Override {
            key: key.to_string(),
            value: parse_value(value.trim()),
        })
    }
}

/// Reads a command-line value as TOML, or as a bare string when it is not valid TOML.
pub fn parse_value(text: &str) -> Value {
    match toml::from_str::<Table>(&format!("v = {text}")) {
        Ok(mut t) => t.remove("v").unwrap_or(Value::String(text.into())),
        Err(_) => Value::String(text.into()),
    }
}

/// Splits a comma-separated list of values at top level (commas inside brackets or quotes
/// belong to the value): `1,2,[3,4]` → `1`, `2`, `[3,4]`.
pub fn split_values(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut quote: Option<char> = None;
    let mut cur = String::new();
    for c in text.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, ',') if depth == 0 => {
                out.push(std::mem::take(&mut cur).trim().to_string());
                continue;
            }
            _ => {}
        }
        cur.push(c);
    }
    out.push(cur.trim().to_string());
    out
}

/// What pre-processing did, for the run record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Prepared {
    /// Whether the document differs from the file as written (then error messages cannot
    /// point at lines).
    pub changed: bool,
    /// Keys whose expression gave a number with a fractional part, as `key = value`, to
    /// explain a type error when such a key needs an integer.
    pub fractional: Vec<String>,
}

/// Applies `variant`, then `overrides`, then evaluates parameters and expressions, in place.
/// Errors name the key and what is valid.
pub fn prepare(
    doc: &mut Table,
    variant: Option<&str>,
    overrides: &[Override],
) -> Result<Prepared, String> {
    let mut changed = false;
    let variants = doc.remove("variants");
    if variants.is_some() {
        changed = true;
    }
    if let Some(name) = variant {
        let table = match &variants {
            Some(Value::Table(t)) => t.get(name),
            _ => None,
        };
        let Some(Value::Table(entries)) = table else {
            let known: Vec<String> = match &variants {
                Some(Value::Table(t)) => t.keys().cloned().collect(),
                _ => Vec::new(),
            };
            return Err(format!(
                "variant {name:?} is not defined; {}",
                if known.is_empty() {
                    "this scenario defines no [variants.NAME] table".to_string()
                } else {
                    format!("its variants are: {}", known.join(", "))
                }
            ));
        };
        for (key, value) in entries {
            set_key(doc, key, value.clone())
                .map_err(|e| format!("`variants.{name}.{key}`: {e}"))?;
        }
    } else if let Some(v) = &variants {
        if !matches!(v, Value::Table(_)) {
            return Err("`variants` must be a table of [variants.NAME] tables".into());
        }
    }
    for o in overrides {
        set_key(doc, &o.key, o.value.clone()).map_err(|e| format!("override `{}`: {e}", o.key))?;
        changed = true;
    }
    let params = evaluate_parameters(doc)?;
    if doc.remove("parameters").is_some() {
        changed = true;
    }
    let mut path = Vec::new();
    let mut fractional = Vec::new();
    changed |= substitute(doc, &params, &mut path, &mut fractional)?;
    Ok(Prepared {
        changed,
        fractional,
    })
}

/// Sets a dotted key. The key must exist already (a typo would otherwise silently add an
/// unused key), except for a key whose parent table exists and whose last part is new: that
/// is allowed so that optional settings can be given (`time.dt_min=1e-6`); unknown keys are
/// then rejected when the document is read.
pub fn set_key(doc: &mut Table, key: &str, value: Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err("empty part in the dotted key".into());
    }
    if parts.len() == 1 {
        if let Some(Value::Table(p)) = doc.get_mut("parameters") {
            if p.contains_key(parts[0]) {
                p.insert(parts[0].to_string(), value);
                return Ok(());
            }
        }
        doc.insert(parts[0].to_string(), value);
        return Ok(());
    }
    let mut cur: &mut Value = doc
        .get_mut(parts[0])
        .ok_or_else(|| format!("there is no `{}` in the scenario", parts[0]))?;
    for (i, part) in parts[1..parts.len() - 1].iter().enumerate() {
        let here = parts[..=i].join(".");
        cur = step_into(cur, part, &here)?;
    }
    let last = parts[parts.len() - 1];
    let here = parts[..parts.len() - 1].join(".");
    match cur {
        Value::Table(t) => {
            let value = match t.get(last) {
                Some(old) => coerce_like(old, value),
                None => value,
            };
            t.insert(last.to_string(), value);
            Ok(())
        }
        Value::Array(a) => {
            let idx = array_index(a, last, &here)?;
            let value = coerce_like(&a[idx], value);
            a[idx] = value;
            Ok(())
        }
        _ => Err(format!("`{here}` is a value, not a table")),
    }
}

/// An integer given where the file has a float is taken as that float (`cn=2` → 2.0).
fn coerce_like(old: &Value, new: Value) -> Value {
    match (old, &new) {
        (Value::Float(_), Value::Integer(i)) => Value::Float(*i as f64),
        _ => new,
    }
}

fn step_into<'a>(cur: &'a mut Value, part: &str, here: &str) -> Result<&'a mut Value, String> {
    match cur {
        Value::Table(t) => t
            .get_mut(part)
            .ok_or_else(|| format!("`{here}` has no key `{part}`")),
        Value::Array(a) => {
            let idx = array_index(a, part, here)?;
            Ok(&mut a[idx])
        }
        _ => Err(format!("`{here}` is a value, not a table")),
    }
}

/// Index into an array (of tables) by position or by the `name` of the entry.
fn array_index(a: &[Value], part: &str, here: &str) -> Result<usize, String> {
    if let Ok(i) = part.parse::<usize>() {
        return if i < a.len() {
            Ok(i)
        } else {
            Err(format!(
                "`{here}` has {} entries (0 to {}), not {i}",
                a.len(),
                a.len().saturating_sub(1)
            ))
        };
    }
    let names: Vec<String> = a
        .iter()
        .filter_map(|v| v.get("name").and_then(|n| n.as_str()).map(String::from))
        .collect();
    a.iter()
        .position(|v| v.get("name").and_then(|n| n.as_str()) == Some(part))
        .ok_or_else(|| {
            format!(
                "`{here}` has no entry named {part:?}; give an index or one of: {}",
                names.join(", ")
            )
        })
}

/// Evaluates `[parameters]`: numbers, or expressions (strings starting with `=`) of other
/// parameters, in any order.
fn evaluate_parameters(doc: &Table) -> Result<BTreeMap<String, f64>, String> {
    let mut values = BTreeMap::new();
    let Some(p) = doc.get("parameters") else {
        return Ok(values);
    };
    let Value::Table(p) = p else {
        return Err("`parameters` must be a table of name = number".into());
    };
    let mut pending: Vec<(String, String)> = Vec::new();
    for (name, v) in p {
        if !is_identifier(name) {
            return Err(format!(
                "`parameters.{name}`: a parameter name holds letters, digits and _ and starts with a letter"
            ));
        }
        match v {
            Value::Float(x) => {
                values.insert(name.clone(), *x);
            }
            Value::Integer(i) => {
                values.insert(name.clone(), *i as f64);
            }
            Value::String(s) if s.trim_start().starts_with('=') => {
                pending.push((name.clone(), s.trim_start()[1..].to_string()));
            }
            other => {
                return Err(format!(
                    "`parameters.{name}` must be a number or an expression \"= ...\", got {other}"
                ))
            }
        }
    }
    while !pending.is_empty() {
        let before = pending.len();
        let mut last_err = String::new();
        pending.retain(|(name, expr)| match eval(expr, &values) {
            Ok(x) => {
                values.insert(name.clone(), x);
                false
            }
            Err(e) => {
                last_err = format!("`parameters.{name}` = \"={expr}\": {e}");
                true
            }
        });
        if pending.len() == before {
            // Nothing could be evaluated: either an unknown name, or parameters that wait on
            // each other.
            let waiting: Vec<&str> = pending.iter().map(|(n, _)| n.as_str()).collect();
            let circular = pending.iter().all(|(_, expr)| {
                tokenize(expr).is_ok_and(|tokens| {
                    tokens
                        .iter()
                        .any(|t| matches!(t, Token::Ident(n) if waiting.contains(&n.as_str())))
                })
            });
            if circular {
                return Err(format!(
                    "the parameters {} refer to each other in a circle; give one of them a number",
                    waiting
                        .iter()
                        .map(|n| format!("`parameters.{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            return Err(last_err);
        }
    }
    for (name, x) in &values {
        if !x.is_finite() {
            return Err(format!("`parameters.{name}` is not finite ({x})"));
        }
    }
    Ok(values)
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(f) if f.is_ascii_alphabetic())
        && c.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Replaces every `"= expr"` string by its value; returns whether anything changed.
fn substitute(
    t: &mut Table,
    params: &BTreeMap<String, f64>,
    path: &mut Vec<String>,
    fractional: &mut Vec<String>,
) -> Result<bool, String> {
    let mut changed = false;
    for (k, v) in t.iter_mut() {
        path.push(k.clone());
        changed |= substitute_value(v, params, path, fractional)?;
        path.pop();
    }
    Ok(changed)
}

fn substitute_value(
    v: &mut Value,
    params: &BTreeMap<String, f64>,
    path: &mut Vec<String>,
    fractional: &mut Vec<String>,
) -> Result<bool, String> {
    match v {
        Value::String(s) if s.trim_start().starts_with('=') => {
            let expr = s.trim_start()[1..].to_string();
            let x = eval(&expr, params)
                .map_err(|e| format!("`{}` = \"={expr}\": {e}", path.join(".")))?;
            *v = number_value(x);
            if matches!(v, Value::Float(_)) {
                fractional.push(format!("`{}` = {x}", path.join(".")));
            }
            Ok(true)
        }
        Value::Table(t) => substitute(t, params, path, fractional),
        Value::Array(a) => {
            let mut changed = false;
            for (i, x) in a.iter_mut().enumerate() {
                path.push(i.to_string());
                changed |= substitute_value(x, params, path, fractional)?;
                path.pop();
            }
            Ok(changed)
        }
        _ => Ok(false),
    }
}

/// The TOML value of an evaluated expression: an integer when the number is a whole number
/// that an `i64` holds exactly (so that integer keys such as `divisions` take expressions;
/// real keys read integers as well), a float otherwise.
fn number_value(x: f64) -> Value {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    if x.fract() == 0.0 && x.abs() <= EXACT {
        Value::Integer(x as i64)
    } else {
        Value::Float(x)
    }
}

/// Evaluates an arithmetic expression: numbers, parameter names, `+ - * / ^`, parentheses,
/// and the functions `min`, `max`, `sqrt`, `abs`, `sin`, `cos`, `exp`, `ln`; `pi`.
pub fn eval(expr: &str, params: &BTreeMap<String, f64>) -> Result<f64, String> {
    let tokens = tokenize(expr)?;
    let mut p = Parser {
        tokens: &tokens,
        pos: 0,
        params,
    };
    let x = p.sum()?;
    if p.pos != tokens.len() {
        return Err(format!("unexpected {} in the expression", tokens[p.pos]));
    }
    Ok(x)
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Num(f64),
    Ident(String),
    Op(char),
}

impl std::fmt::Display for Token {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Token::Num(x) => write!(f, "number {x}"),
            Token::Ident(s) => write!(f, "name `{s}`"),
            Token::Op(c) => write!(f, "`{c}`"),
        }
    }
}

fn tokenize(s: &str) -> Result<Vec<Token>, String> {
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text: String = chars[start..i].iter().collect();
            out.push(Token::Num(
                text.parse()
                    .map_err(|_| format!("`{text}` is not a number"))?,
            ));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Token::Ident(chars[start..i].iter().collect()));
        } else if "+-*/^(),".contains(c) {
            out.push(Token::Op(c));
            i += 1;
        } else {
            return Err(format!("unexpected character {c:?} in the expression"));
        }
    }
    Ok(out)
}

struct Parser<'a> {
    tokens: &'a [Token],
    pos: usize,
    params: &'a BTreeMap<String, f64>,
}

impl Parser<'_> {
    fn peek_op(&self) -> Option<char> {
        match self.tokens.get(self.pos) {
            Some(Token::Op(c)) => Some(*c),
            _ => None,
        }
    }
    fn sum(&mut self) -> Result<f64, String> {
        let mut x = self.product()?;
        while let Some(op @ ('+' | '-')) = self.peek_op() {
            self.pos += 1;
            let y = self.product()?;
            x = if op == '+' { x + y } else { x - y };
        }
        Ok(x)
    }
    fn product(&mut self) -> Result<f64, String> {
        let mut x = self.unary()?;
        while let Some(op @ ('*' | '/')) = self.peek_op() {
            self.pos += 1;
            let y = self.unary()?;
            x = if op == '*' { x * y } else { x / y };
        }
        Ok(x)
    }
    fn unary(&mut self) -> Result<f64, String> {
        match self.peek_op() {
            Some('-') => {
                self.pos += 1;
                Ok(-self.unary()?)
            }
            Some('+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }
    fn power(&mut self) -> Result<f64, String> {
        let base = self.atom()?;
        if self.peek_op() == Some('^') {
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(base.powf(exp));
        }
        Ok(base)
    }
    fn expect(&mut self, c: char) -> Result<(), String> {
        if self.peek_op() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(match self.tokens.get(self.pos) {
                Some(t) => format!("expected `{c}`, found {t}"),
                None => format!("expected `{c}` at the end"),
            })
        }
    }
    fn atom(&mut self) -> Result<f64, String> {
        let tok = self
            .tokens
            .get(self.pos)
            .cloned()
            .ok_or("the expression ends too early")?;
        self.pos += 1;
        match tok {
            Token::Num(x) => Ok(x),
            Token::Op('(') => {
                let x = self.sum()?;
                self.expect(')')?;
                Ok(x)
            }
            Token::Ident(name) => {
                if self.peek_op() == Some('(') {
                    self.pos += 1;
                    let mut args = vec![self.sum()?];
                    while self.peek_op() == Some(',') {
                        self.pos += 1;
                        args.push(self.sum()?);
                    }
                    self.expect(')')?;
                    call(&name, &args)
                } else if name == "pi" {
                    Ok(std::f64::consts::PI)
                } else {
                    self.params.get(&name).copied().ok_or_else(|| {
                        format!(
                            "unknown name `{name}`; parameters are: {}",
                            self.params.keys().cloned().collect::<Vec<_>>().join(", ")
                        )
                    })
                }
            }
            Token::Op(c) => Err(format!("unexpected `{c}`")),
        }
    }
}

fn call(name: &str, args: &[f64]) -> Result<f64, String> {
    let one = |f: fn(f64) -> f64| {
        if args.len() == 1 {
            Ok(f(args[0]))
        } else {
            Err(format!("`{name}` takes one argument, got {}", args.len()))
        }
    };
    match name {
        "min" => Ok(args.iter().copied().fold(f64::INFINITY, f64::min)),
        "max" => Ok(args.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
        "sqrt" => one(f64::sqrt),
        "abs" => one(f64::abs),
        "sin" => one(f64::sin),
        "cos" => one(f64::cos),
        "exp" => one(f64::exp),
        "ln" => one(f64::ln),
        _ => Err(format!(
            "unknown function `{name}`; valid: min, max, sqrt, abs, sin, cos, exp, ln"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(pairs: &[(&str, f64)]) -> BTreeMap<String, f64> {
        pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    #[test]
    fn expressions_follow_precedence() {
        let e = p(&[("v", 0.2), ("d", 1e-3)]);
        assert_eq!(eval("1 + 2 * 3", &e).unwrap(), 7.0);
        assert_eq!(eval("(1 + 2) * 3", &e).unwrap(), 9.0);
        assert_eq!(eval("-2^2", &e).unwrap(), -4.0);
        assert_eq!(eval("2^-1", &e).unwrap(), 0.5);
        assert_eq!(eval("d / v + 1e-3", &e).unwrap(), 1e-3 / 0.2 + 1e-3);
        assert_eq!(eval("max(d, 2e-3, 1)", &e).unwrap(), 1.0);
        assert_eq!(eval("8 / 4 / 2", &e).unwrap(), 1.0);
        assert!(eval("1 +", &e).is_err());
        assert!(eval("foo", &e).unwrap_err().contains("unknown name `foo`"));
        assert!(eval("(1", &e).is_err());
        assert!(eval("1 2", &e).is_err());
    }

    #[test]
    fn parameters_resolve_in_any_order_and_substitute() {
        let mut doc: Table = toml::from_str(
            r#"
            [parameters]
            t1 = "= d / v"
            v = 0.5
            d = 1e-3
            [time]
            t_end = "= 2 * t1"
            dt = 1e-4
            [[contact]]
            name = "a"
            table = [[0.0, 0.0], ["= t1", "= -d"]]
            "#,
        )
        .unwrap();
        let r = prepare(&mut doc, None, &[]).unwrap();
        assert!(r.changed);
        assert!(doc.get("parameters").is_none());
        assert_eq!(doc["time"]["t_end"].as_float(), Some(4e-3));
        let table = doc["contact"][0]["table"].as_array().unwrap();
        assert_eq!(table[1][0].as_float(), Some(2e-3));
        assert_eq!(table[1][1].as_float(), Some(-1e-3));
    }

    #[test]
    fn circular_parameters_are_an_error() {
        let mut doc: Table = toml::from_str("[parameters]\na = \"= b\"\nb = \"= a\"").unwrap();
        let e = prepare(&mut doc, None, &[]).unwrap_err();
        assert!(e.contains("circle") && e.contains("parameters.a"), "{e}");
    }

    #[test]
    fn overrides_address_arrays_by_name_and_index() {
        let mut doc: Table = toml::from_str(
            r#"
            [parameters]
            v = 1.0
            [time]
            dt = 1e-4
            [[body]]
            name = "wheel"
            material = { model = "blatz-ko", g = 1e7 }
            "#,
        )
        .unwrap();
        let o = [
            Override::parse("body.wheel.material.g=5e6").unwrap(),
            Override::parse("time.dt=2").unwrap(),
            Override::parse("v=0.2").unwrap(),
            Override::parse("body.0.material.model=neo-hookean").unwrap(),
        ];
        prepare(&mut doc, None, &o).unwrap();
        assert_eq!(doc["body"][0]["material"]["g"].as_float(), Some(5e6));
        assert_eq!(doc["time"]["dt"].as_float(), Some(2.0));
        assert_eq!(
            doc["body"][0]["material"]["model"].as_str(),
            Some("neo-hookean")
        );
        let e = prepare(
            &mut doc.clone(),
            None,
            &[Override::parse("body.tyre.material.g=1").unwrap()],
        )
        .unwrap_err();
        assert!(
            e.contains("no entry named \"tyre\"") && e.contains("wheel"),
            "{e}"
        );
        let e = prepare(
            &mut doc.clone(),
            None,
            &[Override::parse("tme.dt=1").unwrap()],
        )
        .unwrap_err();
        assert!(e.contains("no `tme`"), "{e}");
    }

    #[test]
    fn variants_apply_before_overrides() {
        let text = r#"
            [time]
            dt = 1e-4
            t_end = 1.0
            [variants.coarse]
            "time.dt" = 1e-3
            "time.t_end" = 0.5
        "#;
        let mut doc: Table = toml::from_str(text).unwrap();
        prepare(
            &mut doc,
            Some("coarse"),
            &[Override::parse("time.t_end=0.25").unwrap()],
        )
        .unwrap();
        assert_eq!(doc["time"]["dt"].as_float(), Some(1e-3));
        assert_eq!(doc["time"]["t_end"].as_float(), Some(0.25));
        assert!(doc.get("variants").is_none());
        let mut doc: Table = toml::from_str(text).unwrap();
        let e = prepare(&mut doc, Some("fine"), &[]).unwrap_err();
        assert!(e.contains("coarse"), "{e}");
    }

    #[test]
    fn values_split_at_top_level_commas() {
        assert_eq!(split_values("1,2e9, 3"), vec!["1", "2e9", "3"]);
        assert_eq!(
            split_values("[1,2],[3,4]"),
            vec!["[1,2]".to_string(), "[3,4]".to_string()]
        );
        assert_eq!(split_values("\"a,b\",c"), vec!["\"a,b\"", "c"]);
        assert_eq!(parse_value("2e9"), Value::Float(2e9));
        assert_eq!(
            parse_value("neo-hookean"),
            Value::String("neo-hookean".into())
        );
    }
}

//! Fuzzing of the scenario reader: the shipped scenarios, mutated at random (bytes flipped,
//! ranges deleted, files truncated, lines duplicated or deleted, numbers replaced by 0,
//! negative, huge, non-finite or rescaled values), must be accepted or rejected with an error,
//! never make the reader panic. Numbers are mutated as numbers so that most cases get past
//! the TOML parser into validation and mesh building. An accepted problem also goes through
//! the physical warnings.
//!
//! `ADHESIM_FUZZ_CASES` sets the number of cases (default 20000).

use adhesim_io::scenario::{parse, parse_with, LoadOptions};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

struct Seed {
    path: PathBuf,
    text: String,
    variants: Vec<String>,
}

fn seeds() -> &'static [Seed] {
    static SEEDS: OnceLock<Vec<Seed>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
        let mut out = Vec::new();
        for dir in [
            root.clone(),
            root.join("paper"),
            root.join("gmsh"),
            root.join("soft"),
            root.join("contact"),
            root.join("interface"),
        ] {
            let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml"))
                .collect();
            files.sort();
            for path in files {
                let text = std::fs::read_to_string(&path).unwrap();
                let variants = text
                    .lines()
                    .filter_map(|l| l.trim().strip_prefix("[variants."))
                    .filter_map(|l| l.strip_suffix(']'))
                    .map(String::from)
                    .collect();
                out.push(Seed {
                    path,
                    text,
                    variants,
                });
            }
        }
        assert!(out.len() >= 6, "expected the shipped scenarios as seeds");
        out
    })
}

/// Spans (start, end) of the number literals of a text: a digit (optionally after a sign)
/// not preceded by a letter, digit, `_` or `.`, through digits, `.`, and an exponent.
fn number_spans(text: &str) -> Vec<(usize, usize, bool)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let start = i;
        let mut j = i;
        if b[j] == b'-' || b[j] == b'+' {
            j += 1;
        }
        let prev_ok = start == 0
            || !(b[start - 1].is_ascii_alphanumeric()
                || b[start - 1] == b'_'
                || b[start - 1] == b'.');
        if prev_ok && j < b.len() && b[j].is_ascii_digit() {
            let mut integer = true;
            while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.' || b[j] == b'_') {
                integer &= b[j] != b'.';
                j += 1;
            }
            if j < b.len() && (b[j] == b'e' || b[j] == b'E') {
                integer = false;
                j += 1;
                if j < b.len() && (b[j] == b'-' || b[j] == b'+') {
                    j += 1;
                }
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
            }
            out.push((start, j, integer));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

#[derive(Clone, Debug)]
enum Number {
    Zero,
    Negate,
    Huge,
    Tiny,
    Nan,
    Inf,
    NegInf,
    Small(u32),
    Scale(f64),
}

#[derive(Clone, Debug)]
enum Mutation {
    FlipBit(usize, u8),
    Delete(usize, usize),
    Truncate(usize),
    DuplicateLine(usize),
    DeleteLine(usize),
    Number(usize, Number),
}

fn number_strategy() -> impl Strategy<Value = Number> {
    prop_oneof![
        Just(Number::Zero),
        Just(Number::Negate),
        Just(Number::Huge),
        Just(Number::Tiny),
        Just(Number::Nan),
        Just(Number::Inf),
        Just(Number::NegInf),
        (0u32..40).prop_map(Number::Small),
        prop_oneof![Just(0.01), Just(0.5), Just(2.0), Just(10.0), Just(-3.0)]
            .prop_map(Number::Scale),
    ]
}

fn mutation_strategy() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        1 => (any::<usize>(), 0u8..8).prop_map(|(p, b)| Mutation::FlipBit(p, b)),
        1 => (any::<usize>(), 1usize..40).prop_map(|(p, n)| Mutation::Delete(p, n)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
        1 => any::<usize>().prop_map(Mutation::DeleteLine),
        8 => (any::<usize>(), number_strategy()).prop_map(|(i, n)| Mutation::Number(i, n)),
    ]
}

fn replacement(old: &str, integer: bool, n: &Number) -> String {
    let x: f64 = old.replace('_', "").parse().unwrap_or(1.0);
    if integer {
        let i = x as i64;
        match n {
            Number::Zero => "0".into(),
            Number::Negate => (-i.max(1)).to_string(),
            Number::Huge => "1000000000000".into(),
            Number::Tiny => "1".into(),
            Number::Nan => "nan".into(),
            Number::Inf => "inf".into(),
            Number::NegInf => "-inf".into(),
            Number::Small(k) => k.to_string(),
            Number::Scale(s) => ((i as f64 * s).round() as i64).to_string(),
        }
    } else {
        let v = match n {
            Number::Zero => 0.0,
            Number::Negate => -x,
            Number::Huge => 1e300,
            Number::Tiny => 1e-300,
            Number::Nan => return "nan".into(),
            Number::Inf => return "inf".into(),
            Number::NegInf => return "-inf".into(),
            Number::Small(k) => *k as f64,
            Number::Scale(s) => x * s,
        };
        format!("{v:e}")
    }
}

fn apply(text: &str, m: &Mutation) -> String {
    let lines = |t: &str| -> Vec<String> { t.lines().map(String::from).collect() };
    match m {
        Mutation::FlipBit(p, bit) => {
            let mut b = text.as_bytes().to_vec();
            if !b.is_empty() {
                let k = p % b.len();
                b[k] ^= 1 << bit;
            }
            String::from_utf8_lossy(&b).into_owned()
        }
        Mutation::Delete(p, n) => {
            let mut b = text.as_bytes().to_vec();
            if !b.is_empty() {
                let k = p % b.len();
                b.drain(k..(k + n).min(b.len()));
            }
            String::from_utf8_lossy(&b).into_owned()
        }
        Mutation::Truncate(p) => {
            let b = text.as_bytes();
            String::from_utf8_lossy(&b[..p % (b.len() + 1)]).into_owned()
        }
        Mutation::DuplicateLine(p) => {
            let mut l = lines(text);
            if !l.is_empty() {
                let k = p % l.len();
                l.insert(k, l[k].clone());
            }
            l.join("\n")
        }
        Mutation::DeleteLine(p) => {
            let mut l = lines(text);
            if !l.is_empty() {
                l.remove(p % l.len());
            }
            l.join("\n")
        }
        Mutation::Number(i, n) => {
            let spans = number_spans(text);
            if spans.is_empty() {
                return text.to_string();
            }
            let (s, e, integer) = spans[i % spans.len()];
            format!(
                "{}{}{}",
                &text[..s],
                replacement(&text[s..e], integer, n),
                &text[e..]
            )
        }
    }
}

fn fuzz_cases() -> u32 {
    std::env::var("ADHESIM_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20000)
}

static ACCEPTED: AtomicUsize = AtomicUsize::new(0);
static RUN: AtomicUsize = AtomicUsize::new(0);

fn exercise(seed: usize, mutations: &[Mutation], variant: bool) {
    let seeds = seeds();
    let s = &seeds[seed % seeds.len()];
    let mut text = s.text.clone();
    for m in mutations {
        text = apply(&text, m);
    }
    RUN.fetch_add(1, Ordering::Relaxed);
    let result = match (variant, s.variants.first()) {
        (true, Some(v)) => parse_with(
            &text,
            &s.path,
            &LoadOptions {
                variant: Some(v.clone()),
                overrides: Vec::new(),
            },
        ),
        _ => parse(&text, &s.path),
    };
    match result {
        Ok(scenario) => {
            ACCEPTED.fetch_add(1, Ordering::Relaxed);
            let _ = adhesim::warnings::physical_warnings(&scenario.problem);
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains(s.path.file_name().unwrap().to_str().unwrap()),
                "the error does not name the file: {msg}"
            );
        }
    }
}

#[test]
fn every_seed_is_valid_unmutated() {
    for s in seeds() {
        parse(&s.text, &s.path).unwrap_or_else(|e| panic!("{e}"));
        for v in &s.variants {
            let opts = LoadOptions {
                variant: Some(v.clone()),
                overrides: Vec::new(),
            };
            parse_with(&s.text, &s.path, &opts).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn numbers_are_found_in_a_scenario() {
    let t = "dt = 2e-3\nsize = [0.1, -1, 3]\nname = \"n1\"\ny = \"= 1.5 * a2\"";
    let spans: Vec<&str> = number_spans(t).iter().map(|&(s, e, _)| &t[s..e]).collect();
    assert_eq!(spans, ["2e-3", "0.1", "-1", "3", "1.5"]);
}

/// The fuzz run: `fuzz_cases()` mutated scenarios (1 to 4 mutations each), each read as
/// written and, for a seed with variants, with its first variant. Prints the number of cases,
/// how many were accepted and the time (see them with `--nocapture`).
#[test]
fn mutated_scenarios_never_panic() {
    let start = std::time::Instant::now();
    let cases = fuzz_cases();
    let mut runner = proptest::test_runner::TestRunner::new(ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    });
    let strategy = (
        0usize..64,
        prop::collection::vec(mutation_strategy(), 1..5),
        any::<bool>(),
    );
    let result = runner.run(&strategy, |(seed, m, v)| {
        exercise(seed, &m, v);
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    eprintln!(
        "fuzz_scenario: {} mutated scenarios read, {} accepted, in {:.2} s",
        RUN.load(Ordering::Relaxed),
        ACCEPTED.load(Ordering::Relaxed),
        start.elapsed().as_secs_f64()
    );
}

//! Time-history CSV files: one header line of column names, then one line of numbers per
//! recorded step.
//!
//! [`HistoryWriter`] writes each row with a single `write` call straight to the file (no
//! user-space buffer), so a run that is killed leaves every completed row readable.
//! [`read_history`] parses such files back for plotting.
//!
//! Number format: finite values use Rust's shortest round-trip representation (plain decimal
//! for moderate magnitudes, `1.5e-9` style otherwise), so parsing a value back gives the same
//! `f64` bit for bit (the payload of a NaN excepted). Non-finite values are written `nan`,
//! `inf` and `-inf`. Column names that contain a comma, a double quote or surrounding blanks
//! are quoted as in RFC 4180; names containing a line break are rejected.

use std::fmt::Write as _;
use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::atomic::with_path;

/// Appends rows of numbers to a CSV history file, one flushed line per row.
#[derive(Debug)]
pub struct HistoryWriter {
    path: PathBuf,
    file: File,
    columns: Vec<String>,
    rows: u64,
    line: String,
}

impl HistoryWriter {
    /// Creates (or truncates) `path` and writes the header line with `columns`.
    ///
    /// Fails with [`io::ErrorKind::InvalidInput`] if `columns` is empty or a name contains a
    /// line break.
    pub fn create<S: AsRef<str>>(path: impl AsRef<Path>, columns: &[S]) -> io::Result<Self> {
        let path = path.as_ref().to_path_buf();
        if columns.is_empty() {
            return Err(invalid(&path, "a history file needs at least one column"));
        }
        let mut header = String::new();
        for (i, name) in columns.iter().enumerate() {
            let name = name.as_ref();
            if name.contains(['\n', '\r']) {
                return Err(invalid(
                    &path,
                    &format!("column name {name:?} contains a line break"),
                ));
            }
            if i > 0 {
                header.push(',');
            }
            push_quoted(&mut header, name);
        }
        header.push('\n');
        let mut file = File::create(&path).map_err(|e| with_path(e, "cannot create", &path))?;
        file.write_all(header.as_bytes())
            .and_then(|()| file.flush())
            .map_err(|e| with_path(e, "cannot write", &path))?;
        Ok(HistoryWriter {
            path,
            file,
            columns: columns.iter().map(|c| c.as_ref().to_owned()).collect(),
            rows: 0,
            line: String::new(),
        })
    }

    /// Reopens `path`, written by [`HistoryWriter::create`] with the same `columns`, keeps
    /// its header and first `keep_rows` rows, drops everything after them and appends from
    /// there on (a resumed run recomputes the dropped rows).
    ///
    /// Fails with [`io::ErrorKind::InvalidData`] if the header differs from `columns` or the
    /// file holds fewer than `keep_rows` complete rows.
    pub fn reopen<S: AsRef<str>>(
        path: impl AsRef<Path>,
        columns: &[S],
        keep_rows: u64,
    ) -> io::Result<Self> {
        let path = path.as_ref().to_path_buf();
        let text = fs::read(&path).map_err(|e| with_path(e, "cannot read", &path))?;
        let mut lines = text.split_inclusive(|&b| b == b'\n');
        let bad = |message: String| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: {message}", path.display()),
            )
        };
        let header = lines
            .next()
            .filter(|l| l.ends_with(b"\n"))
            .ok_or_else(|| bad("missing header line".into()))?;
        let names = parse_header(trim_eol(&String::from_utf8_lossy(header)))
            .map_err(|m| bad(format!("header: {m}")))?;
        let expected: Vec<&str> = columns.iter().map(|c| c.as_ref()).collect();
        if names != expected {
            return Err(bad(format!(
                "the columns {names:?} differ from those of this run {expected:?}"
            )));
        }
        let mut keep = header.len();
        let mut found = 0;
        for line in lines {
            if found == keep_rows || !line.ends_with(b"\n") {
                break;
            }
            keep += line.len();
            found += 1;
        }
        if found < keep_rows {
            return Err(bad(format!(
                "holds {found} complete rows, expected at least {keep_rows}"
            )));
        }
        let file = fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(|e| with_path(e, "cannot open", &path))?;
        file.set_len(keep as u64)
            .map_err(|e| with_path(e, "cannot truncate", &path))?;
        let mut file = file;
        use std::io::Seek as _;
        file.seek(io::SeekFrom::End(0))
            .map_err(|e| with_path(e, "cannot seek in", &path))?;
        Ok(HistoryWriter {
            path,
            file,
            columns: expected.iter().map(|c| c.to_string()).collect(),
            rows: keep_rows,
            line: String::new(),
        })
    }

    /// Writes one row and hands it to the operating system before returning.
    ///
    /// A row whose length differs from the number of columns is rejected with
    /// [`io::ErrorKind::InvalidInput`] and nothing is written.
    pub fn append(&mut self, row: &[f64]) -> io::Result<()> {
        if row.len() != self.columns.len() {
            return Err(invalid(
                &self.path,
                &format!(
                    "row has {} values but the file has {} columns",
                    row.len(),
                    self.columns.len()
                ),
            ));
        }
        self.line.clear();
        for (i, &v) in row.iter().enumerate() {
            if i > 0 {
                self.line.push(',');
            }
            push_f64(&mut self.line, v);
        }
        self.line.push('\n');
        self.file
            .write_all(self.line.as_bytes())
            .and_then(|()| self.file.flush())
            .map_err(|e| with_path(e, "cannot write", &self.path))?;
        self.rows += 1;
        Ok(())
    }

    /// Forces the rows written so far to stable storage (`fsync`). Not needed for a killed
    /// process to keep its rows; only for surviving a power loss.
    pub fn sync(&mut self) -> io::Result<()> {
        self.file
            .sync_data()
            .map_err(|e| with_path(e, "cannot sync", &self.path))
    }

    /// The column names, as given to [`HistoryWriter::create`].
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of rows appended so far.
    pub fn rows_written(&self) -> u64 {
        self.rows
    }
}

/// Reads a history file written by [`HistoryWriter`]: returns the column names and the rows.
///
/// Blank lines are skipped. A last line without a terminating newline is an incomplete row
/// left by an interrupted run and is ignored. Any other malformed line is an
/// [`io::ErrorKind::InvalidData`] error naming the file, the line number and the problem.
pub fn read_history(path: impl AsRef<Path>) -> io::Result<(Vec<String>, Vec<Vec<f64>>)> {
    let path = path.as_ref();
    let text = fs::read_to_string(path).map_err(|e| with_path(e, "cannot read", path))?;
    let mut lines = text.split_inclusive('\n').enumerate();
    let header = loop {
        match lines.next() {
            None => return Err(malformed(path, 1, "missing header line")),
            Some((i, line)) => {
                if !line.ends_with('\n') {
                    return Err(malformed(path, i + 1, "incomplete header line"));
                }
                let line = trim_eol(line);
                if line.trim().is_empty() {
                    continue;
                }
                break parse_header(line).map_err(|m| malformed(path, i + 1, &m))?;
            }
        }
    };
    let mut rows = Vec::new();
    for (i, line) in lines {
        if !line.ends_with('\n') {
            break;
        }
        let line = trim_eol(line);
        if line.trim().is_empty() {
            continue;
        }
        let mut row = Vec::with_capacity(header.len());
        for (k, field) in line.split(',').enumerate() {
            let field = field.trim();
            let value = parse_f64(field).ok_or_else(|| {
                let column = header
                    .get(k)
                    .map(|c| format!("column {:?}", c))
                    .unwrap_or_else(|| format!("field {}", k + 1));
                malformed(
                    path,
                    i + 1,
                    &format!("{column}: cannot parse {field:?} as a number"),
                )
            })?;
            row.push(value);
        }
        if row.len() != header.len() {
            return Err(malformed(
                path,
                i + 1,
                &format!(
                    "expected {} values (one per column), found {}",
                    header.len(),
                    row.len()
                ),
            ));
        }
        rows.push(row);
    }
    Ok((header, rows))
}

/// Appends `v` in the file's number format (see the module documentation).
fn push_f64(out: &mut String, v: f64) {
    let a = v.abs();
    if v.is_nan() {
        out.push_str("nan");
    } else if v.is_infinite() {
        out.push_str(if v > 0.0 { "inf" } else { "-inf" });
    } else if a == 0.0 || (1e-4..1e15).contains(&a) {
        let _ = write!(out, "{v}");
    } else {
        let _ = write!(out, "{v:e}");
    }
}

/// Parses a number in the file's format (also accepts any spelling Rust's `f64` parser does).
fn parse_f64(s: &str) -> Option<f64> {
    if s.is_empty() {
        return None;
    }
    s.parse::<f64>().ok()
}

/// Appends a column name, quoted if needed.
fn push_quoted(out: &mut String, name: &str) {
    let needs_quotes = name.contains([',', '"']) || name.trim() != name || name.is_empty();
    if needs_quotes {
        out.push('"');
        out.push_str(&name.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(name);
    }
}

/// Splits a header line into column names, undoing [`push_quoted`].
fn parse_header(line: &str) -> Result<Vec<String>, String> {
    let mut names = Vec::new();
    let mut chars = line.chars().peekable();
    loop {
        while chars.next_if(|c| *c == ' ' || *c == '\t').is_some() {}
        let mut name = String::new();
        if chars.next_if_eq(&'"').is_some() {
            loop {
                match chars.next() {
                    None => return Err("unterminated quoted column name".into()),
                    Some('"') if chars.next_if_eq(&'"').is_some() => name.push('"'),
                    Some('"') => break,
                    Some(c) => name.push(c),
                }
            }
            while chars.next_if(|c| *c == ' ' || *c == '\t').is_some() {}
            match chars.peek() {
                None | Some(',') => {}
                Some(c) => {
                    return Err(format!(
                        "unexpected character {c:?} after quoted column name"
                    ))
                }
            }
        } else {
            while let Some(c) = chars.next_if(|c| *c != ',') {
                if c == '"' {
                    return Err("double quote inside an unquoted column name".into());
                }
                name.push(c);
            }
            name = name.trim().to_owned();
        }
        names.push(name);
        if chars.next().is_none() {
            return Ok(names);
        }
    }
}

fn trim_eol(line: &str) -> &str {
    let line = line.strip_suffix('\n').unwrap_or(line);
    line.strip_suffix('\r').unwrap_or(line)
}

fn invalid(path: &Path, message: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{}: {message}", path.display()),
    )
}

fn malformed(path: &Path, line: usize, message: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}:{line}: {message}", path.display()),
    )
}

#[cfg(test)]
mod tests {
    use super::super::atomic::test_support::TestDir;
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    /// Values that stress the number format: tiny, huge, subnormal, signed zero, awkward
    /// decimal fractions and the extremes of the finite range.
    fn tricky_values() -> Vec<f64> {
        vec![
            0.0,
            -0.0,
            0.1,
            1.0 / 3.0,
            -2.5e-300,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::MIN,
            1e15,
            123_456_789.123_456_78,
            9.999999999999999e-5,
            1e-4,
            std::f64::consts::PI * 1e21,
            -7.0,
        ]
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let dir = TestDir::new("csv-roundtrip");
        let path = dir.path().join("history.csv");
        let values = tricky_values();
        let columns: Vec<String> = (0..values.len()).map(|i| format!("c{i}")).collect();
        let mut w = HistoryWriter::create(&path, &columns).unwrap();
        let mut expected = Vec::new();
        for k in 0..20 {
            let row: Vec<f64> = values
                .iter()
                .map(|v| {
                    if k == 0 {
                        *v
                    } else {
                        v * (1.0 + k as f64 * 0.37)
                    }
                })
                .collect();
            w.append(&row).unwrap();
            expected.push(row);
        }
        assert_eq!(w.rows_written(), 20);
        let (header, rows) = read_history(&path).unwrap();
        assert_eq!(header, columns);
        assert_eq!(rows.len(), expected.len());
        for (r, e) in rows.iter().zip(&expected) {
            let rb: Vec<u64> = r.iter().map(|v| v.to_bits()).collect();
            let eb: Vec<u64> = e.iter().map(|v| v.to_bits()).collect();
            assert_eq!(rb, eb);
        }
    }

    #[test]
    fn non_finite_values_are_spelled_out() {
        let dir = TestDir::new("csv-nonfinite");
        let path = dir.path().join("h.csv");
        let mut w = HistoryWriter::create(&path, &names(&["a", "b", "c"])).unwrap();
        w.append(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY])
            .unwrap();
        let text = fs::read_to_string(&path).unwrap();
        assert_eq!(text, "a,b,c\nnan,inf,-inf\n");
        let (_, rows) = read_history(&path).unwrap();
        assert!(rows[0][0].is_nan());
        assert_eq!(rows[0][1], f64::INFINITY);
        assert_eq!(rows[0][2], f64::NEG_INFINITY);
    }

    #[test]
    fn each_row_is_readable_while_the_writer_is_open() {
        let dir = TestDir::new("csv-flush");
        let path = dir.path().join("live.csv");
        let mut w = HistoryWriter::create(&path, &["t", "energy"]).unwrap();
        let (header, rows) = read_history(&path).unwrap();
        assert_eq!(header, names(&["t", "energy"]));
        assert!(rows.is_empty());
        for k in 0..5 {
            let row = [k as f64 * 0.1, (k as f64).sqrt()];
            w.append(&row).unwrap();
            let (_, rows) = read_history(&path).unwrap();
            assert_eq!(rows.len(), k + 1);
            assert_eq!(rows[k], row.to_vec());
        }
        drop(w);
    }

    #[test]
    fn wrong_row_length_is_an_error_and_writes_nothing() {
        let dir = TestDir::new("csv-wronglen");
        let path = dir.path().join("h.csv");
        let mut w = HistoryWriter::create(&path, &["a", "b"]).unwrap();
        w.append(&[1.0, 2.0]).unwrap();
        for bad in [&[1.0][..], &[1.0, 2.0, 3.0][..], &[][..]] {
            let err = w.append(bad).unwrap_err();
            assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
            assert!(err.to_string().contains("h.csv"), "{err}");
        }
        w.append(&[3.0, 4.0]).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "a,b\n1,2\n3,4\n");
    }

    #[test]
    fn awkward_column_names_round_trip() {
        let dir = TestDir::new("csv-names");
        let path = dir.path().join("h.csv");
        let cols = names(&["time (s)", "F_x, top", "say \"hi\"", " padded ", ""]);
        let mut w = HistoryWriter::create(&path, &cols).unwrap();
        w.append(&[1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
        let (header, rows) = read_history(&path).unwrap();
        assert_eq!(header, cols);
        assert_eq!(rows, vec![vec![1.0, 2.0, 3.0, 4.0, 5.0]]);
        let err = HistoryWriter::create(&path, &["a\nb"]).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        let none: [&str; 0] = [];
        assert!(HistoryWriter::create(&path, &none).is_err());
    }

    #[test]
    fn malformed_input_names_file_and_line() {
        let dir = TestDir::new("csv-malformed");
        let path = dir.path().join("bad.csv");
        fs::write(&path, "a,b\n1,2\n\n3,oops\n").unwrap();
        let msg = read_history(&path).unwrap_err().to_string();
        assert!(msg.contains("bad.csv:4"), "{msg}");
        assert!(msg.contains("\"b\""), "{msg}");
        assert!(msg.contains("oops"), "{msg}");

        fs::write(&path, "a,b\n1,2\n1,2,3\n").unwrap();
        let err = read_history(&path).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidData);
        assert!(err.to_string().contains("bad.csv:3"), "{err}");

        fs::write(&path, "").unwrap();
        assert!(read_history(&path)
            .unwrap_err()
            .to_string()
            .contains("bad.csv:1"));

        let missing = dir.path().join("missing.csv");
        let err = read_history(&missing).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        assert!(err.to_string().contains("missing.csv"), "{err}");
    }

    #[test]
    fn reopen_keeps_the_first_rows_and_appends_after_them() {
        let dir = TestDir::new("csv-reopen");
        let path = dir.path().join("h.csv");
        let mut w = HistoryWriter::create(&path, &["t", "u"]).unwrap();
        for k in 0..5 {
            w.append(&[k as f64, 2.0 * k as f64]).unwrap();
        }
        drop(w);
        // A half-written row left by a killed run.
        let mut text = fs::read_to_string(&path).unwrap();
        text.push_str("5,1");
        fs::write(&path, text).unwrap();
        let mut w = HistoryWriter::reopen(&path, &["t", "u"], 3).unwrap();
        assert_eq!(w.rows_written(), 3);
        w.append(&[7.0, 8.0]).unwrap();
        assert_eq!(
            fs::read_to_string(&path).unwrap(),
            "t,u\n0,0\n1,2\n2,4\n7,8\n"
        );
        drop(w);
        let err = HistoryWriter::reopen(&path, &["t", "v"], 1).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidData);
        assert!(err.to_string().contains("differ"), "{err}");
        let err = HistoryWriter::reopen(&path, &["t", "u"], 9).unwrap_err();
        assert!(err.to_string().contains("4 complete rows"), "{err}");
    }

    #[test]
    fn interrupted_last_row_is_ignored() {
        let dir = TestDir::new("csv-truncated");
        let path = dir.path().join("h.csv");
        fs::write(&path, "t,u\r\n0,1\r\n0.5,2\r\n1,2.2").unwrap();
        let (header, rows) = read_history(&path).unwrap();
        assert_eq!(header, names(&["t", "u"]));
        assert_eq!(rows, vec![vec![0.0, 1.0], vec![0.5, 2.0]]);
    }
}

//! Malformed input must never crash the program: every scenario in `tests/bad_input/` (and
//! the Gmsh files they reference) is rejected by `adhesim check` and `adhesim run` with exit
//! code 2 and one error message that names the file and the offending key, never a panic.
//!
//! Each scenario's first line is a comment `# <what is wrong>; expect: <fragment>`: the
//! fragment must appear in the message. An optional second line `# args: ...` gives extra
//! command-line arguments (e.g. `--variant coarse`).

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_adhesim");

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input")
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("adhesim-bad-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

struct Case {
    path: PathBuf,
    expect: String,
    args: Vec<String>,
}

fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        let first = lines.next().unwrap_or_default();
        let expect = first
            .strip_prefix('#')
            .and_then(|l| l.split_once("expect:"))
            .map(|(_, e)| e.trim().to_string())
            .unwrap_or_else(|| panic!("{}: first line lacks `# ...; expect: ...`", path.display()));
        assert!(!expect.is_empty(), "{}: empty expect", path.display());
        let args = lines
            .next()
            .and_then(|l| l.strip_prefix("# args:"))
            .map(|a| a.split_whitespace().map(String::from).collect())
            .unwrap_or_default();
        out.push(Case { path, expect, args });
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    out
}

/// Runs the binary; returns (exit code, stderr).
fn adhesim(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(BIN).args(args).output().expect("run adhesim");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Exit code 2, one error message (no panic), naming `name` and holding `expect`.
fn check_rejection(
    what: &str,
    code: Option<i32>,
    stderr: &str,
    name: &str,
    expect: &str,
) -> Vec<String> {
    let mut problems = Vec::new();
    if code != Some(2) {
        problems.push(format!(
            "{what}: exit code {code:?}, expected 2; stderr:\n{stderr}"
        ));
    }
    if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") {
        problems.push(format!("{what}: panic:\n{stderr}"));
    }
    if stderr.trim().is_empty() {
        problems.push(format!("{what}: empty stderr"));
    }
    // One error message (a sweep announces itself on the line before).
    if stderr.matches("error: ").count() != 1 {
        problems.push(format!("{what}: not one `error: ` message:\n{stderr}"));
    }
    if stderr.lines().count() > 12 {
        problems.push(format!(
            "{what}: message of {} lines:\n{stderr}",
            stderr.lines().count()
        ));
    }
    if !stderr.contains(name) {
        problems.push(format!("{what}: message does not name {name}:\n{stderr}"));
    }
    if !stderr.contains(expect) {
        problems.push(format!("{what}: message lacks {expect:?}:\n{stderr}"));
    }
    problems
}

#[test]
fn corpus_is_large_and_every_mesh_file_is_used() {
    let cases = cases();
    let files = std::fs::read_dir(corpus_dir()).unwrap().count();
    assert!(files >= 45, "only {files} files in the corpus");
    let scenarios: String = cases
        .iter()
        .map(|c| std::fs::read_to_string(&c.path).unwrap())
        .collect();
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) == Some("msh") {
            let name = path.file_name().unwrap().to_str().unwrap();
            assert!(
                scenarios.contains(name),
                "{name} is used by no scenario of the corpus"
            );
        }
    }
}

#[test]
fn check_rejects_every_bad_scenario() {
    let mut problems = Vec::new();
    for c in cases() {
        let file = c.path.to_str().unwrap();
        let mut args = vec!["check", file];
        args.extend(c.args.iter().map(String::as_str));
        let (code, stderr) = adhesim(&args);
        let name = c.path.file_name().unwrap().to_str().unwrap();
        problems.extend(check_rejection(
            &format!("check {name}"),
            code,
            &stderr,
            name,
            &c.expect,
        ));
    }
    assert!(
        problems.is_empty(),
        "{} problem(s):\n{}",
        problems.len(),
        problems.join("\n\n")
    );
}

#[test]
fn run_rejects_every_bad_scenario_and_writes_nothing() {
    let mut problems = Vec::new();
    let out = scratch("run");
    for c in cases() {
        let file = c.path.to_str().unwrap();
        let mut args = vec!["run", file, "--out", out.to_str().unwrap()];
        args.extend(c.args.iter().map(String::as_str));
        let (code, stderr) = adhesim(&args);
        let name = c.path.file_name().unwrap().to_str().unwrap();
        problems.extend(check_rejection(
            &format!("run {name}"),
            code,
            &stderr,
            name,
            &c.expect,
        ));
        if out.exists() {
            problems.push(format!("run {name}: the output directory was created"));
            let _ = std::fs::remove_dir_all(&out);
        }
    }
    assert!(
        problems.is_empty(),
        "{} problem(s):\n{}",
        problems.len(),
        problems.join("\n\n")
    );
}

#[test]
fn bad_command_line_arguments_are_rejected() {
    let cantilever = root().join("scenarios/cantilever.toml");
    let cantilever = cantilever.to_str().unwrap();
    let plate = root().join("scenarios/paper/plate-on-cylinder.toml");
    let plate = plate.to_str().unwrap();
    let out = scratch("cli");
    let out = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str, &str)> = vec![
        (
            vec!["run", cantilever, "--variant", "nosuch", "--out", out],
            "cantilever.toml",
            "nosuch",
        ),
        (
            vec!["check", plate, "--variant", "nosuch"],
            "plate-on-cylinder.toml",
            "nosuch",
        ),
        (
            vec!["run", cantilever, "--set", "nosuch.key=1", "--out", out],
            "cantilever.toml",
            "nosuch",
        ),
        (
            vec!["check", cantilever, "--set", "time.dt=-1"],
            "cantilever.toml",
            "time.dt",
        ),
        (
            vec!["check", cantilever, "--set", "time.dt=nan"],
            "cantilever.toml",
            "time.dt",
        ),
        (
            vec![
                "check",
                cantilever,
                "--set",
                "body.beam.material.g=\"soft\"",
            ],
            "cantilever.toml",
            "g",
        ),
        (
            vec!["check", cantilever, "--set", "=1"],
            "--set",
            "empty key",
        ),
        (
            vec!["check", cantilever, "--set", "time.dt"],
            "--set",
            "key=value",
        ),
        (
            vec!["sweep", plate, "--set", "k=", "--out", out],
            "--set",
            "`k=`",
        ),
        (
            vec!["sweep", plate, "--set", "mu=0.2,-0.1", "--out", out],
            "plate-on-cylinder.toml",
            "friction",
        ),
        (
            vec!["sweep", plate, "--set", "nosuch=1,2", "--out", out],
            "plate-on-cylinder.toml",
            "nosuch",
        ),
    ];
    let mut problems = Vec::new();
    for (args, name, expect) in &cases {
        let (code, stderr) = adhesim(args);
        problems.extend(check_rejection(
            &args.join(" "),
            code,
            &stderr,
            name,
            expect,
        ));
    }
    let (code, stderr) = adhesim(&["check", "/no/such/scenario.toml"]);
    problems.extend(check_rejection(
        "missing file",
        code,
        &stderr,
        "scenario.toml",
        "cannot read",
    ));
    let _ = std::fs::remove_dir_all(out);
    assert!(
        problems.is_empty(),
        "{} problem(s):\n{}",
        problems.len(),
        problems.join("\n\n")
    );
}

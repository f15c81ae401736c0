//! Output folders that cannot be clobbered, tried through the real `adhesim run`: a second
//! run into a folder that a run is writing is refused (exit 2, naming the first run's
//! process) and leaves the first run's outputs intact; a folder holding an interrupted or a
//! finished run is refused without --resume or --overwrite and left byte for byte as it was.
#![cfg(unix)]

use adhesim_io::output::csv::read_history;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

mod common;
use common::*;

const BIN: &str = env!("CARGO_BIN_EXE_adhesim");

/// The shipped indentation scenario, coarsened and cut to 1 s (50 steps, one to two seconds).
const SCENARIO_ARGS: [&str; 5] = [
    "../../scenarios/indentation.toml",
    "--set",
    "time.t_end=1.0",
    "--set",
    "body.layer.mesh.divisions=[30,3,1]",
];

fn fresh_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("adhesim-test-no-clobber-{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn command(out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(BIN);
    c.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["run", "-q", "--checkpoint-every", "0"])
        .args(SCENARIO_ARGS)
        .arg("--out")
        .arg(out)
        .args(extra);
    c
}

fn spawn(out: &Path) -> Child {
    command(out, &[]).stderr(Stdio::piped()).spawn().unwrap()
}

fn run(out: &Path, extra: &[&str]) -> Output {
    command(out, extra).output().unwrap()
}

/// Every line of history.csv has the header's number of fields and the steps run 0, 1, 2, …
/// without a gap or a repeat. Returns the number of rows.
fn assert_history_intact(out: &Path) -> usize {
    let text = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(text.ends_with('\n'), "history.csv ends with a cut line");
    let mut lines = text.lines();
    let fields = lines.next().unwrap().split(',').count();
    for (i, line) in lines.enumerate() {
        assert_eq!(line.split(',').count(), fields, "row {i}: {line}");
    }
    let (cols, rows) = read_history(out.join("history.csv")).unwrap();
    let k = cols.iter().position(|c| c == "step").unwrap();
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[k], i as f64, "row {i} holds step {}", r[k]);
    }
    rows.len()
}

#[test]
fn a_second_run_into_a_busy_folder_is_refused_and_the_first_is_intact() {
    let out = fresh_dir("concurrent");
    let mut first = spawn(&out);
    wait_for_rows(&mut first, &out, 5);
    let second = run(&out, &["--overwrite"]);
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(&format!("process {}", first.id())),
        "the refusal names the first run's process: {stderr}"
    );
    let status = first.wait().unwrap();
    assert!(status.success(), "the first run: {status}");
    assert_eq!(status_in_run_json(&out), "finished");
    // 50 steps of 0.02 s and the initial row.
    assert_eq!(assert_history_intact(&out), 51);
}

#[test]
fn an_interrupted_run_is_kept_unless_resumed_or_overwritten() {
    let out = fresh_dir("interrupted");
    let mut child = spawn(&out);
    wait_for_rows(&mut child, &out, 5);
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert_eq!(status_in_run_json(&out), "interrupted");
    let checkpoint = std::fs::read(out.join("checkpoint.bin")).unwrap();
    let history = std::fs::read(out.join("history.csv")).unwrap();
    let run_json = std::fs::read(out.join("run.json")).unwrap();

    let again = run(&out, &[]);
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert_eq!(again.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("interrupted run") && stderr.contains("--resume"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(out.join("checkpoint.bin")).unwrap(),
        checkpoint
    );
    assert_eq!(std::fs::read(out.join("history.csv")).unwrap(), history);
    assert_eq!(std::fs::read(out.join("run.json")).unwrap(), run_json);

    // --overwrite replaces it: a complete new run, no checkpoint left behind.
    let replaced = run(&out, &["--overwrite"]);
    assert!(replaced.status.success(), "{replaced:?}");
    assert!(!out.join("checkpoint.bin").exists());
    assert_eq!(assert_history_intact(&out), 51);
}

#[test]
fn a_finished_run_needs_overwrite() {
    let out = fresh_dir("finished");
    assert!(run(&out, &[]).status.success());
    let history = std::fs::read(out.join("history.csv")).unwrap();
    let again = run(&out, &[]);
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert_eq!(again.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("finished run") && stderr.contains("--overwrite"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(out.join("history.csv")).unwrap(), history);
    assert!(run(&out, &["--overwrite"]).status.success());
    assert_eq!(status_in_run_json(&out), "finished");
}

//! A real `adhesim run` killed (SIGKILL) or interrupted (SIGINT, SIGTERM) in the middle of a
//! run leaves readable outputs, and `--resume` finishes it with the result of an
//! uninterrupted run.
#![cfg(unix)]

use adhesim_io::output::csv::read_history;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::OnceLock;

mod common;
use common::*;

const BIN: &str = env!("CARGO_BIN_EXE_adhesim");

fn work_dir() -> PathBuf {
    std::env::temp_dir().join("adhesim-test-kill-resume")
}

/// The shipped indentation scenario, coarsened and cut to 1 s (50 steps, about a second).
fn scenario() -> &'static Path {
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/indentation.toml");
        let text = std::fs::read_to_string(src)
            .unwrap()
            .replace("t_end = 4.0", "t_end = 1.0")
            .replace("divisions = [60, 6, 1]", "divisions = [30, 3, 1]");
        let dir = work_dir();
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("indentation.toml");
        std::fs::write(&file, text).unwrap();
        file
    })
}

/// Output directory of the uninterrupted run.
fn reference() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = work_dir().join("reference");
        let status = Command::new(BIN)
            .args(["run", "-q", "--checkpoint-every", "0", "--out"])
            .arg(&out)
            .arg(scenario())
            .status()
            .unwrap();
        assert!(status.success(), "reference run: {status}");
        out
    })
}

fn spawn(out: &Path, checkpoint_every: usize) -> Child {
    let _ = std::fs::remove_dir_all(out);
    Command::new(BIN)
        .args(["run", "-q", "--checkpoint-every"])
        .arg(checkpoint_every.to_string())
        .arg("--out")
        .arg(out)
        .arg(scenario())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Every history line is complete and every frame the PVD lists exists and is well-formed
/// XML. Returns the number of history rows.
fn check_outputs_readable(out: &Path) -> usize {
    let text = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(
        text.ends_with('\n'),
        "history.csv ends with an incomplete line"
    );
    let (columns, rows) = read_history(out.join("history.csv")).unwrap();
    assert_eq!(rows.len() + 1, text.lines().count());
    assert!(rows.iter().all(|r| r.len() == columns.len()));
    let pvd = std::fs::read_to_string(out.join("indentation.pvd")).unwrap();
    let doc = roxmltree::Document::parse(&pvd).expect("the PVD is well-formed XML");
    let files: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("DataSet"))
        .map(|n| n.attribute("file").unwrap())
        .collect();
    assert!(!files.is_empty());
    for f in files {
        let vtm = std::fs::read_to_string(out.join(f))
            .unwrap_or_else(|e| panic!("frame {f} listed in the PVD: {e}"));
        let doc = roxmltree::Document::parse(&vtm)
            .unwrap_or_else(|e| panic!("frame {f} is not well-formed XML: {e}"));
        assert_eq!(
            doc.root_element().attribute("type"),
            Some("vtkMultiBlockDataSet")
        );
        let dir = out.join(f);
        let dir = dir.parent().unwrap();
        let grids: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("DataSet"))
            .map(|n| n.attribute("file").unwrap())
            .collect();
        assert!(!grids.is_empty(), "frame {f} lists no data set");
        for g in grids {
            let vtu = std::fs::read_to_string(dir.join(g))
                .unwrap_or_else(|e| panic!("data set {g} listed in {f}: {e}"));
            let doc = roxmltree::Document::parse(&vtu)
                .unwrap_or_else(|e| panic!("data set {g} is not well-formed XML: {e}"));
            assert_eq!(
                doc.root_element().attribute("type"),
                Some("UnstructuredGrid")
            );
        }
    }
    rows.len()
}

fn resume(out: &Path) {
    let output = Command::new(BIN)
        .args(["run", "-q", "--resume"])
        .arg(out)
        .arg(scenario())
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "resume: {}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(status_in_run_json(out), "finished");
}

/// The last history row equals the uninterrupted run's bit for bit (wall-clock timing
/// columns excepted), and so does the row count.
fn assert_same_end(out: &Path) {
    let (cols, a) = read_history(reference().join("history.csv")).unwrap();
    let (_, b) = read_history(out.join("history.csv")).unwrap();
    assert_eq!(a.len(), b.len());
    let (ra, rb) = (a.last().unwrap(), b.last().unwrap());
    for (k, name) in cols.iter().enumerate() {
        if !name.starts_with("time_") {
            assert_eq!(ra[k].to_bits(), rb[k].to_bits(), "column {name}");
        }
    }
}

#[test]
fn killed_run_leaves_readable_outputs_and_resumes_to_the_same_end() {
    reference();
    let out = work_dir().join("killed");
    let mut child = spawn(&out, 4);
    wait_for_rows(&mut child, &out, 12);
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    assert_eq!(status_in_run_json(&out), "running");
    let rows = check_outputs_readable(&out);
    assert!((12..51).contains(&rows), "{rows} rows");
    resume(&out);
    check_outputs_readable(&out);
    assert_same_end(&out);
}

fn interrupt_with(signal: &str) {
    reference();
    let out = work_dir().join(format!("sig{signal}"));
    let mut child = spawn(&out, 0);
    wait_for_rows(&mut child, &out, 6);
    let sent = Command::new("sh")
        .arg("-c")
        .arg(format!("kill -{signal} {}", child.id()))
        .status()
        .unwrap();
    assert!(sent.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("--resume"), "{stderr}");
    assert_eq!(status_in_run_json(&out), "interrupted");
    assert!(out.join("checkpoint.bin").exists());
    check_outputs_readable(&out);
    resume(&out);
    assert_same_end(&out);
}

#[test]
fn ctrl_c_stops_after_the_step_with_a_checkpoint() {
    interrupt_with("INT");
}

#[test]
fn sigterm_stops_after_the_step_with_a_checkpoint() {
    interrupt_with("TERM");
}

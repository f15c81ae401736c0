//! A local sweep killed outright (SIGKILL) during its third case, or stopped with Ctrl-C, and
//! resumed with `--resume` ends with the sweep.csv of an uninterrupted sweep (wall-time
//! column aside): finished cases are kept, the stopped case resumes from its checkpoint and
//! the rest run.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

mod common;
use common::*;

const BIN: &str = env!("CARGO_BIN_EXE_adhesim");

fn work_dir() -> PathBuf {
    std::env::temp_dir().join("adhesim-test-sweep-resume")
}

/// A 4-case sweep (adhesion energy × friction) of the shipped indentation scenario,
/// coarsened and cut to 1 s (50 steps per case), one case at a time, a checkpoint every 5
/// steps.
fn sweep(out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(BIN);
    c.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["sweep", "-q", "-j", "1", "--checkpoint-every", "5"])
        .arg("../../scenarios/indentation.toml")
        .args(["--fix", "time.t_end=1.0"])
        .args(["--fix", "body.layer.mesh.divisions=[30,3,1]"])
        .args(["--set", "contact.indentor.adhesion.w=10,20"])
        .args(["--set", "contact.indentor.friction=0,0.3"])
        .arg("--out")
        .arg(out)
        .args(extra);
    c
}

/// The uninterrupted sweep's folder.
fn reference() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = work_dir().join("reference");
        let _ = std::fs::remove_dir_all(&out);
        let output = sweep(&out, &[]).output().unwrap();
        assert!(output.status.success(), "reference sweep: {output:?}");
        out
    })
}

fn status(dir: &Path) -> Option<String> {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("run.json")).ok()?).ok()?;
    json["outcome"]["status"].as_str().map(String::from)
}

/// The folder of case `n` (1-based) in the sweep folder `out`.
fn case_dir(out: &Path, n: usize) -> PathBuf {
    let prefix = format!("case{n:02}_");
    std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .is_some_and(|f| f.to_string_lossy().starts_with(&prefix))
        })
        .unwrap_or_else(|| panic!("no folder for case {n} in {}", out.display()))
}

/// Waits until case `n` has written `rows` history rows; panics if the sweep ends first.
fn wait_for_case_rows(child: &mut Child, out: &Path, n: usize, rows: usize) {
    let start = Instant::now();
    let prefix = format!("case{n:02}_");
    loop {
        let found = std::fs::read_dir(out).ok().and_then(|entries| {
            entries
                .map_while(Result::ok)
                .find(|e| e.file_name().to_string_lossy().starts_with(&prefix))
        });
        if let Some(e) = found {
            let text = std::fs::read_to_string(e.path().join("history.csv")).unwrap_or_default();
            if text.matches('\n').count() > rows {
                return;
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the sweep ended ({status}) before case {n} wrote {rows} rows");
        }
        assert!(start.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn resume_and_compare(out: &Path) {
    let output = sweep(out, &["--resume"]).output().unwrap();
    assert!(output.status.success(), "resumed sweep: {output:?}");
    assert_eq!(
        table_without_wall_time(out),
        table_without_wall_time(reference())
    );
}

#[test]
fn a_sweep_killed_in_its_third_case_resumes_to_the_same_table() {
    reference();
    let out = work_dir().join("killed");
    let _ = std::fs::remove_dir_all(&out);
    let mut child = sweep(&out, &[]).stderr(Stdio::null()).spawn().unwrap();
    wait_for_case_rows(&mut child, &out, 3, 12);
    child.kill().unwrap(); // SIGKILL: no handler runs
    child.wait().unwrap();
    assert_eq!(status(&case_dir(&out, 1)).as_deref(), Some("finished"));
    assert_eq!(status(&case_dir(&out, 2)).as_deref(), Some("finished"));
    let third = case_dir(&out, 3);
    assert_eq!(status(&third).as_deref(), Some("running"));
    assert!(
        third.join("checkpoint.bin").exists(),
        "a checkpoint every 5 steps"
    );
    assert!(!out.join("sweep.csv").exists());

    // Without --resume the folder is refused and nothing in it changes.
    let before = std::fs::read(third.join("checkpoint.bin")).unwrap();
    let refused = sweep(&out, &[]).output().unwrap();
    assert_eq!(refused.status.code(), Some(2), "{refused:?}");
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--resume"));
    assert_eq!(std::fs::read(third.join("checkpoint.bin")).unwrap(), before);

    resume_and_compare(&out);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(third.join("run.json")).unwrap()).unwrap();
    assert!(
        json["resumed_from"]["step"]
            .as_u64()
            .is_some_and(|s| s >= 5),
        "the third case resumed from its checkpoint: {json}"
    );
}

#[test]
fn ctrl_c_stops_every_case_with_a_checkpoint_and_the_sweep_resumes() {
    reference();
    let out = work_dir().join("ctrl-c");
    let _ = std::fs::remove_dir_all(&out);
    let mut child = sweep(&out, &[]).stderr(Stdio::piped()).spawn().unwrap();
    wait_for_case_rows(&mut child, &out, 2, 8);
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("--resume"), "{stderr}");
    let second = case_dir(&out, 2);
    assert_eq!(status(&second).as_deref(), Some("interrupted"));
    assert!(second.join("checkpoint.bin").exists());
    assert!(
        !out.join("case03_w=20_friction=0").exists(),
        "no case starts after Ctrl-C"
    );
    resume_and_compare(&out);
}

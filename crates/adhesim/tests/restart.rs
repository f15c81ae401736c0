//! Restartable runs: a run stopped after some steps and resumed from its checkpoint gives
//! the outputs of an uninterrupted run bit for bit (history rows, frames, the final β), the
//! wall-clock timing columns of history.csv excepted.

use adhesim::contact::RccHistory;
use adhesim_io::checkpoint::{Checkpoint, CheckpointError};
use adhesim_io::output::csv::read_history;
use adhesim_io::output::{HistoryObserver, HISTORY_KEY};
use adhesim_io::run::{run_with, Outcome, RunControl, RunError, Silent};
use adhesim_io::scenario::Scenario;
use std::path::{Path, PathBuf};

/// The shipped indentation scenario, coarsened and cut to its loading phase (1 s, 50 steps):
/// contact from the first step, bonds forming (β → 1) at the centre and growing outwards;
/// with contact maps at three times, one of them before the checkpoints of the tests.
fn problem(w: f64) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/indentation.toml");
    let maps = "\n[[map]]\ncontact = \"indentor\"\nfields = [\"beta\", \"pn\"]\n\
                times = [0.05, 0.5, 0.9]\n";
    let text = (std::fs::read_to_string(&path).unwrap() + maps)
        .replace("t_end = 4.0", "t_end = 1.0")
        .replace("divisions = [60, 6, 1]", "divisions = [30, 3, 1]")
        .replace("w = 20.0", &format!("w = {w:?}"));
    adhesim_io::scenario::parse(&text, &path).unwrap()
}

fn fresh_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("adhesim-test-restart-{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn go(dir: &Path, control: RunControl) -> Result<adhesim_io::run::RunSummary, RunError> {
    run_with(problem(20.0), None, dir, &mut Silent, &control)
}

/// Asserts that two history files agree bit for bit outside the timing columns.
fn assert_same_history(a: &Path, b: &Path) {
    let (ca, ra) = read_history(a.join("history.csv")).unwrap();
    let (cb, rb) = read_history(b.join("history.csv")).unwrap();
    assert_eq!(ca, cb);
    assert_eq!(ra.len(), rb.len(), "row counts differ");
    for (i, (x, y)) in ra.iter().zip(&rb).enumerate() {
        for (k, name) in ca.iter().enumerate() {
            if name.starts_with("time_") {
                continue;
            }
            assert!(
                x[k].to_bits() == y[k].to_bits(),
                "row {i}, column {name}: {} vs {}",
                x[k],
                y[k]
            );
        }
    }
}

/// Asserts that the frame collections, every frame file and every contact map agree byte
/// for byte; returns the number of frames (multiblock files).
fn assert_same_frames(a: &Path, b: &Path) -> usize {
    let maps = |d: &Path| {
        let mut v: Vec<_> = std::fs::read_dir(d.join("maps"))
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                (e.file_name(), std::fs::read(e.path()).unwrap())
            })
            .collect();
        v.sort();
        v
    };
    let written = maps(a);
    // The faces and one file per requested time.
    assert_eq!(
        written.len(),
        4,
        "{:?}",
        written.iter().map(|m| &m.0).collect::<Vec<_>>()
    );
    assert!(written == maps(b), "the contact maps differ");
    let pvd = "indentation.pvd";
    assert_eq!(
        std::fs::read_to_string(a.join(pvd)).unwrap(),
        std::fs::read_to_string(b.join(pvd)).unwrap()
    );
    let list = |d: &Path| {
        let mut v: Vec<_> = std::fs::read_dir(d.join("vtu"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        v.sort();
        v
    };
    let files = list(a);
    assert_eq!(files, list(b), "different frame files");
    for f in &files {
        let (x, y) = (
            std::fs::read(a.join("vtu").join(f)).unwrap(),
            std::fs::read(b.join("vtu").join(f)).unwrap(),
        );
        assert!(x == y, "frame {f:?} differs");
    }
    files
        .iter()
        .filter(|f| f.to_str().is_some_and(|f| f.ends_with(".vtm")))
        .count()
}

#[test]
fn stopped_and_resumed_run_equals_the_uninterrupted_one() {
    let full = fresh_dir("full");
    let s = go(&full, RunControl::default()).unwrap();
    assert_eq!(s.outcome, Outcome::Finished);
    assert_eq!(s.steps, 50);
    assert!(
        !Checkpoint::path(&full).exists(),
        "no checkpoint unless asked"
    );

    // Stop after step 7 (checkpoints every 4 steps: at 4, then at 7 on the stop).
    let part = fresh_dir("part");
    let s = go(
        &part,
        RunControl {
            checkpoint_every: 4,
            stop_after_steps: Some(7),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.outcome, Outcome::Interrupted);
    assert_eq!(s.steps, 7);
    let c = Checkpoint::read(&part).unwrap();
    assert_eq!(c.snapshot.step, 7);
    let history = c.observer_state(HISTORY_KEY).unwrap();
    assert_eq!(HistoryObserver::rows_in_state(history), Ok(8));
    let json = std::fs::read_to_string(part.join("run.json")).unwrap();
    assert!(json.contains("\"interrupted\""), "{json}");
    // The centre is already bonded: the restart carries real adhesion state.
    assert!(c.snapshot.contact[0]
        .iter()
        .any(|n| RccHistory::from(&n.history).beta == 1.0));

    let s = go(
        &part,
        RunControl {
            resume: true,
            checkpoint_every: 4,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.outcome, Outcome::Finished);
    assert_eq!(s.steps, 50);
    assert_eq!(s.resumed_from.map(|r| r.step), Some(7));
    assert_same_history(&full, &part);
    let frames = assert_same_frames(&full, &part);
    assert_eq!(frames, 11);
}

/// A run killed some steps after its last checkpoint left rows and frames beyond it: the
/// resumed run drops them and computes them again.
#[test]
fn rows_and_frames_after_the_checkpoint_are_recomputed() {
    let full = fresh_dir("full2");
    go(&full, RunControl::default()).unwrap();
    let dir = fresh_dir("killed");
    go(
        &dir,
        RunControl {
            checkpoint_every: 5,
            stop_after_steps: Some(5),
            ..Default::default()
        },
    )
    .unwrap();
    let at_5 = std::fs::read(Checkpoint::path(&dir)).unwrap();
    // Go on to step 13, then put the step-5 checkpoint back: as if killed at step 13.
    let s = go(
        &dir,
        RunControl {
            resume: true,
            stop_after_steps: Some(13),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((s.outcome, s.steps), (Outcome::Interrupted, 13));
    std::fs::write(Checkpoint::path(&dir), &at_5).unwrap();
    // A half-written row, as a kill in the middle of a write could leave.
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .open(dir.join("history.csv"))
        .unwrap();
    std::io::Write::write_all(&mut f, b"0.28,14,0.0").unwrap();
    drop(f);
    let s = go(
        &dir,
        RunControl {
            resume: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((s.outcome, s.steps), (Outcome::Finished, 50));
    assert_same_history(&full, &dir);
    assert_same_frames(&full, &dir);
}

#[test]
fn resuming_with_a_changed_scenario_is_refused() {
    let dir = fresh_dir("changed");
    go(
        &dir,
        RunControl {
            stop_after_steps: Some(2),
            ..Default::default()
        },
    )
    .unwrap();
    let history = std::fs::read(dir.join("history.csv")).unwrap();
    let err = run_with(
        problem(25.0),
        None,
        &dir,
        &mut Silent,
        &RunControl {
            resume: true,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, RunError::Checkpoint(CheckpointError::Mismatch { .. })),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("checkpoint.bin") && msg.contains("scenario differs"),
        "{msg}"
    );
    // Nothing was touched.
    assert_eq!(std::fs::read(dir.join("history.csv")).unwrap(), history);

    let empty = fresh_dir("no-checkpoint");
    std::fs::create_dir_all(&empty).unwrap();
    let err = go(
        &empty,
        RunControl {
            resume: true,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("checkpoint.bin"), "{err}");
}

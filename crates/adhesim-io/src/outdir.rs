//! Output folders that cannot be clobbered.
//!
//! A run holds an exclusive advisory lock on `DIR/run.lock` (a `flock`, released by the
//! operating system when the process ends, however it ends) for as long as it writes to
//! `DIR`; the file holds the process id and host name of the run that holds it. A second run
//! into the same folder finds the lock taken and is refused, naming the other run.
//!
//! A folder that already holds a run (its `run.json` or `checkpoint.bin`) is only written
//! over on request: resuming continues it, an explicit overwrite first removes the previous
//! run's outputs, and otherwise the run is refused, so that an interrupted or finished run
//! cannot be lost by a mistyped command.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// Name of the lock file in an output folder.
pub const LOCK_FILE: &str = "run.lock";

/// Why an output folder cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum OutDirError {
    /// Another process holds the folder's lock.
    #[error(
        "{dir} is in use by another run ({holder}); wait for it to end, stop it, or choose another --out"
    )]
    Locked {
        /// The folder.
        dir: PathBuf,
        /// Who holds the lock, e.g. `process 1234 on node7`.
        holder: String,
    },
    /// The folder holds a previous run that would be lost.
    #[error("{dir} holds {what}; {hint}")]
    HoldsRun {
        /// The folder.
        dir: PathBuf,
        /// What it holds, e.g. `an interrupted run (checkpoint at step 40)`.
        what: String,
        /// What to do instead.
        hint: String,
    },
    /// The lock file cannot be created or locked.
    #[error("cannot lock {path}: {source}")]
    Io {
        /// The lock file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The exclusive lock on an output folder; released when dropped (or when the process ends).
#[derive(Debug)]
pub struct DirLock {
    _file: File,
}

/// The process id of the lock holder as recorded in a lock file's text (`pid HOST`).
pub fn holder_pid(text: &str) -> Option<u32> {
    text.split_whitespace().next()?.parse().ok()
}

/// Takes the exclusive lock on `dir/run.lock`, creating `dir` if needed; refuses if another
/// process (or another run in this process) holds it.
pub fn lock(dir: &Path) -> Result<DirLock, OutDirError> {
    let path = dir.join(LOCK_FILE);
    let io = |source| OutDirError::Io {
        path: path.clone(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(io)?;
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(io)?;
    match file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            let mut text = String::new();
            let _ = file.read_to_string(&mut text);
            let holder = match (holder_pid(&text), text.split_whitespace().nth(1)) {
                (Some(pid), Some(host)) => format!("process {pid} on {host}"),
                (Some(pid), None) => format!("process {pid}"),
                _ => "a process that has not yet written its id".to_string(),
            };
            return Err(OutDirError::Locked {
                dir: dir.to_path_buf(),
                holder,
            });
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
    }
    let me = format!("{} {}\n", std::process::id(), host_name());
    file.set_len(0)
        .and_then(|()| file.write_all(me.as_bytes()))
        .and_then(|()| file.flush())
        .map_err(io)?;
    Ok(DirLock { _file: file })
}

/// Whether a live process holds the lock on `dir` (a run is writing there). Takes and at
/// once releases the lock when it is free; a folder without a lock file is not locked.
pub fn is_locked(dir: &Path) -> bool {
    let Ok(file) = File::open(dir.join(LOCK_FILE)) else {
        return false;
    };
    match file.try_lock() {
        Ok(()) => {
            let _ = file.unlock();
            false
        }
        Err(std::fs::TryLockError::WouldBlock) => true,
        Err(std::fs::TryLockError::Error(_)) => false,
    }
}

/// The machine's host name (for lock files on shared file systems), or `?`.
fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "?".into())
}

/// The status recorded in `dir/run.json` (`running`, `finished`, `interrupted`, `failed`)
/// and the checkpoint step it names, if the file is there and readable.
fn recorded_status(dir: &Path) -> Option<(String, Option<u64>)> {
    let text = std::fs::read(dir.join("run.json")).ok()?;
    let json: serde_json::Value = serde_json::from_slice(&text).ok()?;
    let status = json["outcome"]["status"].as_str()?.to_string();
    Some((status, json["checkpoint"]["step"].as_u64()))
}

/// Describes the run whose outputs are in `dir`, or `None` when it holds none (no run.json,
/// no checkpoint.bin).
pub fn existing_run(dir: &Path) -> Option<String> {
    let has_checkpoint = crate::checkpoint::Checkpoint::path(dir).exists();
    let recorded = recorded_status(dir);
    if !has_checkpoint && recorded.is_none() && !dir.join("run.json").exists() {
        return None;
    }
    let at = |step: Option<u64>| match step {
        Some(s) => format!(" (checkpoint at step {s})"),
        None => String::new(),
    };
    Some(match (recorded, has_checkpoint) {
        (Some((s, step)), true) if s == "interrupted" => format!("an interrupted run{}", at(step)),
        (Some((s, step)), true) if s == "running" => {
            format!("a run that was killed{}", at(step))
        }
        (Some((s, _)), false) if s == "running" => {
            "a run that was killed before its first checkpoint".into()
        }
        (Some((s, _)), _) if s == "finished" => "a finished run".into(),
        (Some((s, _)), _) if s == "failed" => "a run that stopped on an error".into(),
        (_, true) => "a run's checkpoint".into(),
        _ => "a previous run's run.json".into(),
    })
}

/// Checks that a new run (not a resumed one) may write into `dir`: refuses when `dir` holds
/// a previous run unless `overwrite`; with `overwrite`, removes that run's outputs (the
/// files and folders adhesim writes, nothing else) so that none of them is mixed with the
/// new run's. Call with the folder's lock held.
pub fn prepare_fresh(dir: &Path, overwrite: bool) -> Result<(), OutDirError> {
    let Some(what) = existing_run(dir) else {
        return Ok(());
    };
    if !overwrite {
        let hint = if crate::checkpoint::Checkpoint::path(dir).exists() {
            "continue it with --resume DIR, or replace it with --overwrite"
        } else {
            "replace it with --overwrite, or choose another --out"
        };
        return Err(OutDirError::HoldsRun {
            dir: dir.to_path_buf(),
            what,
            hint: hint.into(),
        });
    }
    remove_outputs(dir).map_err(|source| OutDirError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

/// Removes the outputs of a run from `dir`: checkpoint.bin, run.json, history.csv, the PVD
/// collections, and the vtu/, maps/ and figures/ folders.
fn remove_outputs(dir: &Path) -> std::io::Result<()> {
    let ignore_missing = |r: std::io::Result<()>| match r {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        other => other,
    };
    for f in ["checkpoint.bin", "run.json", "history.csv"] {
        ignore_missing(std::fs::remove_file(dir.join(f)))?;
    }
    for d in ["vtu", "maps", "figures"] {
        ignore_missing(std::fs::remove_dir_all(dir.join(d)))?;
    }
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "pvd") && path.is_file() {
            std::fs::remove_file(path)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fresh(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("adhesim-outdir-{tag}"));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_second_lock_on_the_same_folder_is_refused_with_the_holder_pid() {
        let dir = fresh("lock");
        let held = lock(&dir).unwrap();
        let text = std::fs::read_to_string(dir.join(LOCK_FILE)).unwrap();
        assert_eq!(holder_pid(&text), Some(std::process::id()));
        match lock(&dir) {
            Err(OutDirError::Locked { holder, .. }) => {
                assert!(holder.contains(&std::process::id().to_string()), "{holder}")
            }
            other => panic!("expected a refusal, got {other:?}"),
        }
        assert!(is_locked(&dir));
        drop(held);
        assert!(!is_locked(&dir));
        lock(&dir).expect("the lock is free again once dropped");
    }

    #[test]
    fn a_folder_with_a_run_is_kept_unless_overwritten() {
        let dir = fresh("existing");
        std::fs::create_dir_all(dir.join("vtu")).unwrap();
        prepare_fresh(&dir, false).expect("an empty folder is fine");
        let json = r#"{"outcome":{"status":"interrupted"},"checkpoint":{"step":40,"t":0.8}}"#;
        std::fs::write(dir.join("run.json"), json).unwrap();
        std::fs::write(dir.join("checkpoint.bin"), b"x").unwrap();
        std::fs::write(dir.join("notes.txt"), b"mine").unwrap();
        let err = prepare_fresh(&dir, false).unwrap_err().to_string();
        assert!(
            err.contains("interrupted run (checkpoint at step 40)"),
            "{err}"
        );
        assert!(err.contains("--resume"), "{err}");
        assert!(dir.join("checkpoint.bin").exists());
        prepare_fresh(&dir, true).unwrap();
        assert!(!dir.join("checkpoint.bin").exists() && !dir.join("vtu").exists());
        assert!(
            dir.join("notes.txt").exists(),
            "files adhesim did not write stay"
        );
    }
}

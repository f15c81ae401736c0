//! Helpers shared by the command-line tests: watching a run's outputs as it goes and reading
//! what it left.
#![allow(dead_code)]

use std::path::Path;
use std::process::Child;
use std::time::{Duration, Instant};

/// Waits until history.csv holds `rows` complete rows; panics if the run ends first.
pub fn wait_for_rows(child: &mut Child, out: &Path, rows: usize) {
    let start = Instant::now();
    loop {
        let text = std::fs::read_to_string(out.join("history.csv")).unwrap_or_default();
        if text.matches('\n').count() > rows {
            return;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the run ended ({status}) before writing {rows} rows");
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no progress");
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// The outcome status that run.json records.
pub fn status_in_run_json(out: &Path) -> String {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    json["outcome"]["status"].as_str().unwrap().to_string()
}

/// sweep.csv without its wall_time column.
pub fn table_without_wall_time(dir: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == "wall_time").unwrap();
    text.lines()
        .map(|l| {
            let mut f: Vec<String> = l.split(',').map(String::from).collect();
            f.remove(k);
            f
        })
        .collect()
}

//! No partial output, even when killed: `trum map` writes to a hidden temporary file in
//! the target's directory and renames it over the target only at the end. A SIGKILL in
//! the middle of a large map must leave no target file, and must leave an existing
//! target untouched. A leftover hidden temporary file (`.NAME.XXXXXX.csv`) is expected
//! (nothing runs after SIGKILL to remove it) and is tolerated; docs/RELIABILITY.md says so.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Starts a map of 4 million points (minutes of work) writing to `out`.
fn start_big_map(out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_trum"))
        .args([
            "map",
            "--motor",
            "trum60a",
            "--preload-n",
            "1:5000:2000",
            "--torque-nm",
            "0:3:2000",
            "--quiet",
            "--chunk-points",
            "256",
            "-o",
        ])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start trum map")
}

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir).expect("dir").map(|e| e.expect("entry").path()).collect();
    v.sort();
    v
}

/// Waits until the temporary file holds data (the map is mid-write), then another
/// `extra`, then kills. Returns the temporary files seen and their size at the kill.
fn kill_mid_write(child: &mut Child, dir: &Path, target: &Path, extra: Duration) -> u64 {
    let t0 = Instant::now();
    let tmp_size = |dir: &Path| -> u64 {
        files_in(dir)
            .iter()
            .filter(|p| p.as_path() != target)
            .map(|p| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0))
            .sum()
    };
    while tmp_size(dir) == 0 {
        assert!(t0.elapsed() < Duration::from_secs(60), "trum map never started writing");
        assert!(child.try_wait().expect("try_wait").is_none(), "trum map ended early");
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(extra);
    assert!(child.try_wait().expect("try_wait").is_none(), "the map finished before the kill; make it larger");
    let size = tmp_size(dir);
    child.kill().expect("SIGKILL");
    child.wait().expect("wait");
    size
}

#[test]
fn killed_map_leaves_no_target_and_an_existing_target_untouched() {
    let dir = tempfile::tempdir().expect("tempdir");
    let target = dir.path().join("big.csv");

    // 1. no target before: none after the kill
    let mut child = start_big_map(&target);
    let written = kill_mid_write(&mut child, dir.path(), &target, Duration::from_millis(300));
    assert!(written > 0);
    assert!(!target.exists(), "a killed map left a (partial) target file");
    let left = files_in(dir.path());
    for p in &left {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        assert!(name.starts_with(".big.csv.") && name.ends_with(".csv"), "unexpected file {}", p.display());
    }
    eprintln!("after SIGKILL: {} hidden temporary file(s) left: {left:?} ({written} bytes written)", left.len());
    for p in left {
        std::fs::remove_file(p).expect("rm temp");
    }

    // 2. an existing target keeps its exact content
    let old = b"preload_n,torque_nm\nold,content\n";
    std::fs::write(&target, old).expect("write old target");
    let mut child = start_big_map(&target);
    kill_mid_write(&mut child, dir.path(), &target, Duration::from_millis(300));
    assert_eq!(std::fs::read(&target).expect("read target"), old, "a killed map changed the existing target");

    // 3. control: the same command on a small grid completes and replaces the target atomically
    let o = Command::new(env!("CARGO_BIN_EXE_trum"))
        .args(["map", "--motor", "trum60a", "--preload-n", "1:5000:20", "--torque-nm", "0:3:20", "--quiet", "-o"])
        .arg(&target)
        .output()
        .expect("run trum map");
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&target).expect("read");
    assert_eq!(text.lines().count(), 1 + 400, "header + 400 rows");
    assert!(text.ends_with('\n'));
}

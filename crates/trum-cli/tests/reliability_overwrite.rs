//! Overwriting and interrupting, as `cp`, `sort -o` and careful editors behave: an output
//! that is an input (the same file, also through a symbolic or hard link) is refused
//! before any work; `-o link` writes through the link; a replaced file keeps its mode; a
//! write-protected file is not replaced; SIGINT, SIGTERM and SIGHUP remove the temporary
//! output file, leave an existing target as it was, and end the process by that signal.

use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn trum(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trum")).current_dir(dir).args(args).output().expect("run trum")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const SMALL_MAP: [&str; 6] = ["--preload-n", "100:200:3", "--torque-nm", "0", "--voltage-v", "150"];

fn map_args<'a>(motor: &'a str, out: &'a str) -> Vec<&'a str> {
    let mut v = vec!["map", "--motor", motor];
    v.extend(SMALL_MAP);
    v.extend(["--quiet", "-o", out]);
    v
}

fn motor_file(dir: &Path) -> String {
    let text = "preset = \"trum60a\"\n";
    std::fs::write(dir.join("m.toml"), text).expect("write motor");
    text.to_string()
}

/// Eight rows of the ring motor's bench (speed vs preload and torque), enough to calibrate.
fn data_file(dir: &Path) -> String {
    let mut t = String::from("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n");
    for (p, tq, s) in [
        (150, 0.0, 120),
        (200, 0.0, 140),
        (250, 0.0, 142),
        (300, 0.0, 131),
        (150, 0.1, 90),
        (200, 0.1, 112),
        (250, 0.1, 118),
        (300, 0.1, 110),
    ] {
        t += &format!("{p},150,42000,{tq},{s}\n");
    }
    std::fs::write(dir.join("d.csv"), &t).expect("write data");
    t
}

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let motor = motor_file(d);
    std::os::unix::fs::symlink("m.toml", d.join("sym.toml")).expect("symlink");
    std::fs::hard_link(d.join("m.toml"), d.join("hard.toml")).expect("hard link");
    // the same file named three ways as input, and as output directly and through the links
    for (input, output) in
        [("m.toml", "m.toml"), ("sym.toml", "m.toml"), ("m.toml", "sym.toml"), ("hard.toml", "m.toml")]
    {
        let o = trum(d, &map_args(input, output));
        assert_eq!(o.status.code(), Some(1), "map --motor {input} -o {output}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("is the input file --motor") && e.contains(input), "{e}");
        assert_eq!(std::fs::read_to_string(d.join("m.toml")).expect("read"), motor, "the input was changed");
        assert!(std::fs::symlink_metadata(d.join("sym.toml")).expect("link").file_type().is_symlink());
    }
    let data = data_file(d);
    for args in [
        vec!["calibrate", "--motor", "trum60a", "--data", "d.csv", "-o", "d.csv"],
        vec!["calibrate", "--motor", "trum60a", "--data", "d.csv", "--json", "d.csv"],
        vec!["diagnose", "--motor", "trum60a", "--data", "d.csv", "--json", "d.csv"],
        vec!["diagnose", "--motor", "trum60a", "--data", "d.csv", "--report", "d.csv"],
        vec!["synth", "--motor", "m.toml", "--campaign", "stability", "--noise", "0", "--seed", "1", "-o", "m.toml"],
    ] {
        let t0 = Instant::now();
        let o = trum(d, &args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("is the input file"), "{args:?}: {}", stderr(&o));
        // refused before the work starts
        assert!(t0.elapsed() < Duration::from_secs(20), "{args:?} took {:?}", t0.elapsed());
    }
    assert_eq!(std::fs::read_to_string(d.join("d.csv")).expect("read"), data);
    assert_eq!(std::fs::read_to_string(d.join("m.toml")).expect("read"), motor);
    assert_eq!(std::fs::read_dir(d).expect("dir").count(), 4, "a temporary file was left behind");
}

#[test]
fn a_symbolic_link_is_written_through_and_the_mode_kept() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::create_dir(d.join("sub")).expect("mkdir");
    std::fs::write(d.join("sub/real.csv"), "old\n").expect("write");
    std::fs::set_permissions(d.join("sub/real.csv"), std::fs::Permissions::from_mode(0o664)).expect("chmod");
    std::os::unix::fs::symlink("sub/real.csv", d.join("link.csv")).expect("symlink");
    let o = trum(d, &map_args("trum60a", "link.csv"));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let link = std::fs::symlink_metadata(d.join("link.csv")).expect("link");
    assert!(link.file_type().is_symlink(), "the link was replaced by a plain file");
    let text = std::fs::read_to_string(d.join("sub/real.csv")).expect("read target");
    assert!(text.starts_with("preload_n,"), "the link's target was not written: {text}");
    assert_eq!(text.lines().count(), 4);
    let mode = std::fs::metadata(d.join("sub/real.csv")).expect("meta").permissions().mode() & 0o7777;
    assert_eq!(mode, 0o664, "the replaced file's mode changed");
    // no temporary file left in either directory
    assert_eq!(std::fs::read_dir(d).expect("dir").count(), 2);
    assert_eq!(std::fs::read_dir(d.join("sub")).expect("dir").count(), 1);
    // an unusual mode is kept too, and a new file gets 0666 less the umask (at most 0666)
    std::fs::set_permissions(d.join("sub/real.csv"), std::fs::Permissions::from_mode(0o640)).expect("chmod");
    assert_eq!(trum(d, &map_args("trum60a", "sub/real.csv")).status.code(), Some(0));
    assert_eq!(std::fs::metadata(d.join("sub/real.csv")).expect("meta").permissions().mode() & 0o7777, 0o640);
    assert_eq!(trum(d, &map_args("trum60a", "new.csv")).status.code(), Some(0));
    let new_mode = std::fs::metadata(d.join("new.csv")).expect("meta").permissions().mode() & 0o7777;
    assert_eq!(new_mode & !0o666, 0, "{new_mode:o}");
    assert_ne!(new_mode & 0o600, 0, "{new_mode:o}");
}

#[test]
fn a_write_protected_file_is_not_replaced() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("ro.csv"), "keep me\n").expect("write");
    std::fs::set_permissions(d.join("ro.csv"), std::fs::Permissions::from_mode(0o444)).expect("chmod");
    let o = trum(d, &map_args("trum60a", "ro.csv"));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("'ro.csv' is write-protected"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(d.join("ro.csv")).expect("read"), "keep me\n");
    assert_eq!(std::fs::read_dir(d).expect("dir").count(), 1);
}

/// Starts a map of 4 million points (minutes of work) writing to `out`.
fn start_big_map(out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_trum"))
        .args(["map", "--motor", "trum60a", "--preload-n", "1:5000:2000", "--torque-nm", "0:3:2000"])
        .args(["--quiet", "--chunk-points", "256", "-o"])
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

#[test]
fn sigint_sigterm_and_sighup_remove_the_temporary_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let target = dir.path().join("big.csv");
    let old = b"preload_n,torque_nm\nold,content\n";
    for (name, signo) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        std::fs::write(&target, old).expect("write old target");
        let mut child = start_big_map(&target);
        let t0 = Instant::now();
        // wait until the temporary file holds data: the map is mid-write
        loop {
            let written: u64 = files_in(dir.path())
                .iter()
                .filter(|p| **p != target)
                .map(|p| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0))
                .sum();
            if written > 0 {
                break;
            }
            assert!(t0.elapsed() < Duration::from_secs(60), "trum map never started writing");
            assert!(child.try_wait().expect("try_wait").is_none(), "trum map ended early");
            std::thread::sleep(Duration::from_millis(10));
        }
        let k = Command::new("kill").args(["-s", name, &child.id().to_string()]).status().expect("kill");
        assert!(k.success());
        let status = child.wait().expect("wait");
        assert_eq!(status.signal(), Some(signo), "SIG{name}: ended with {status:?}");
        assert_eq!(files_in(dir.path()), vec![target.clone()], "SIG{name} left a temporary file");
        assert_eq!(std::fs::read(&target).expect("read"), old, "SIG{name} changed the existing target");
    }
}

//! Shared argument handling: motor lookup (file or preset), effects, grid axes, output
//! files written atomically, and the progress bar.

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use trum_core::params::SweepTable;
use trum_core::presets;
use trum_core::sweep::{Axis, Grid};
use trum_core::Motor;

/// `--motor` and `--effect`, shared by every command that solves.
#[derive(Args, Debug, Clone)]
pub struct MotorArgs {
    /// Motor: a TOML motor file, or a preset name (see `trum presets`). A file wins if it exists.
    #[arg(long, value_name = "FILE|PRESET")]
    pub motor: String,
    /// Switch an unmodelled effect on: NAME=STRENGTH or NAME:param=value,... (repeatable; see `trum effects`).
    #[arg(long = "effect", value_name = "NAME=STRENGTH")]
    pub effects: Vec<String>,
}

impl MotorArgs {
    /// The motor with the command-line effects applied, and its `[sweep]` table.
    pub fn load(&self) -> Result<(Motor, SweepTable)> {
        let (mut motor, sweep) = load_motor(&self.motor)?;
        for spec in &self.effects {
            motor.effects.parse_assignment(spec).map_err(|m| anyhow!("--effect '{spec}': {m}"))?;
        }
        Ok((motor, sweep))
    }
}

/// Reads `--motor`: an existing file is read as a motor file, anything else must be a
/// preset name. The error says which of the two was tried.
pub fn load_motor(spec: &str) -> Result<(Motor, SweepTable)> {
    let path = Path::new(spec);
    if path.is_file() {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read motor file '{spec}'"))?;
        // ParamError's message names the file, line and key; show it unchanged.
        return Motor::from_toml_str_with_sweep(&text, spec).map_err(|e| anyhow!("{e}"));
    }
    if path.is_dir() {
        bail!("--motor '{spec}' is a directory, not a motor file");
    }
    match presets::find(spec) {
        Ok(p) => Ok((p.motor(), SweepTable::default())),
        Err(_) => {
            let names = presets::PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ");
            let looks_like_file = spec.ends_with(".toml") || spec.contains('/') || spec.contains('\\');
            if looks_like_file {
                bail!("motor file '{spec}' does not exist (nor is it a preset name; valid presets are: {names})")
            }
            bail!("unknown preset '{spec}' (and no file of that name exists); valid presets are: {names}")
        }
    }
}

/// Parses an axis: `VALUE` or `START:STOP:N` (N ≥ 1 evenly spaced values, both ends included).
pub fn parse_axis(s: &str) -> Result<Axis, String> {
    let num = |t: &str| -> Result<f64, String> {
        let v: f64 = t.trim().parse().map_err(|_| format!("'{}' is not a number", t.trim()))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("'{}' is not a finite number", t.trim()))
        }
    };
    let parts: Vec<&str> = s.split(':').collect();
    match parts.as_slice() {
        [v] => Ok(Axis::fixed(num(v)?)),
        [a, b, n] => {
            let n: usize = n
                .trim()
                .parse()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| format!("the point count '{}' must be a whole number >= 1", n.trim()))?;
            Ok(Axis::linspace(num(a)?, num(b)?, n))
        }
        _ => Err(format!("expected VALUE or START:STOP:N (for example 150:400:11), got '{s}'")),
    }
}

/// The four grid axes on the command line.
#[derive(Args, Debug, Clone, Default)]
pub struct GridArgs {
    /// Axial preload [N]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    pub preload_n: Option<Axis>,
    /// Load torque [N m]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    pub torque_nm: Option<Axis>,
    /// Drive voltage amplitude per phase, zero-to-peak [V]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    pub voltage_v: Option<Axis>,
    /// Drive frequency [Hz]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    pub frequency_hz: Option<Axis>,
}

/// Defaults for axes set neither on the command line nor in the motor file's `[sweep]`.
pub const DEFAULT_PRELOAD_N: f64 = 250.0;
/// Default load torque [N·m].
pub const DEFAULT_TORQUE_NM: f64 = 0.0;
/// Default voltage [V].
pub const DEFAULT_VOLTAGE_V: f64 = 200.0;
/// Default frequency [Hz].
pub const DEFAULT_FREQUENCY_HZ: f64 = 43_000.0;

impl GridArgs {
    /// Command line first, then the `[sweep]` table, then `fallback` (per axis).
    pub fn resolve(&self, sweep: &SweepTable, fallback: &Grid) -> Grid {
        Grid {
            preload_n: self.preload_n.or(sweep.preload_n).unwrap_or(fallback.preload_n),
            torque_nm: self.torque_nm.or(sweep.torque_nm).unwrap_or(fallback.torque_nm),
            voltage_v: self.voltage_v.or(sweep.voltage_v).unwrap_or(fallback.voltage_v),
            frequency_hz: self.frequency_hz.or(sweep.frequency_hz).unwrap_or(fallback.frequency_hz),
        }
    }
}

/// The fixed default grid (one point: 250 N, 0 N·m, 200 V, 43 kHz).
pub fn default_grid() -> Grid {
    Grid {
        preload_n: Axis::fixed(DEFAULT_PRELOAD_N),
        torque_nm: Axis::fixed(DEFAULT_TORQUE_NM),
        voltage_v: Axis::fixed(DEFAULT_VOLTAGE_V),
        frequency_hz: Axis::fixed(DEFAULT_FREQUENCY_HZ),
    }
}

/// Checks what a map can hold: finite values and at least one point per axis. Values
/// outside the model's domain (preload ≤ 0, torque < 0) are allowed: those rows come out
/// with status `invalid_input` and empty numbers, like any other invalid point.
pub fn check_grid(g: &Grid) -> Result<()> {
    let axes = [
        ("preload_n", g.preload_n),
        ("torque_nm", g.torque_nm),
        ("voltage_v", g.voltage_v),
        ("frequency_hz", g.frequency_hz),
    ];
    for (name, ax) in axes {
        if ax.n == 0 {
            bail!("{name}: an axis needs at least one point");
        }
        for v in [ax.start, ax.stop] {
            if !v.is_finite() {
                bail!("{name}: {v} is not a finite number");
            }
        }
    }
    let total = axes.iter().try_fold(1u64, |acc, (_, a)| acc.checked_mul(a.n as u64));
    if total.is_none() {
        bail!("the grid has more points than fit in 64 bits");
    }
    Ok(())
}

/// The unit of an input column or output quantity, if known.
pub fn unit_of(name: &str) -> Option<&'static str> {
    match name {
        "preload_n" => Some("N"),
        "torque_nm" => Some("N m"),
        "voltage_v" => Some("V"),
        "frequency_hz" => Some("Hz"),
        "elapsed_s" | "time_s" => Some("s"),
        "position_m" => Some("m"),
        "tangential_force_n_per_m" => Some("N/m"),
        "score" => Some("-"),
        "max_efficiency" => Some("-"),
        "torque_at_max_efficiency_nm" => Some("N m"),
        "no_load_speed_rpm" => Some("rpm"),
        _ => trum_core::quantities::QUANTITIES.iter().find(|q| q.name == name).map(|q| q.unit),
    }
}

/// Where a command writes a file: `-` is stdout, anything else a temporary file in the
/// same directory that is renamed over the target only when the run succeeded, so a
/// failed run leaves no partial file behind. An existing target that is not a regular
/// file (`/dev/null`, a FIFO, a terminal) is written in place: renaming over it would
/// replace the device with a regular file.
pub enum OutputTarget {
    /// Standard output.
    Stdout,
    /// A temporary file and the final path.
    File(tempfile::NamedTempFile, PathBuf),
    /// An existing special file, written directly.
    Device(PathBuf),
}

impl OutputTarget {
    /// Opens the target; `suffix` keeps the extension on the temporary file (plotters uses it).
    pub fn create(path: &Path, suffix: &str) -> Result<OutputTarget> {
        if path.as_os_str() == "-" {
            return Ok(OutputTarget::Stdout);
        }
        if let Ok(meta) = std::fs::metadata(path) {
            if meta.is_dir() {
                bail!("output '{}' is a directory", path.display());
            }
            if !meta.is_file() {
                return Ok(OutputTarget::Device(path.to_path_buf()));
            }
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            bail!("cannot write '{}': directory '{}' does not exist", path.display(), dir.display());
        }
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let prefix = format!(".{name}.");
        let mut b = tempfile::Builder::new();
        b.prefix(&prefix).suffix(suffix);
        // tempfile creates 0600 files; an output file should have ordinary permissions.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            b.permissions(std::fs::Permissions::from_mode(0o644));
        }
        let tmp =
            b.tempfile_in(&dir).with_context(|| format!("cannot create a temporary file in '{}'", dir.display()))?;
        Ok(OutputTarget::File(tmp, path.to_path_buf()))
    }

    /// The file to write into (`None`: standard output).
    pub fn open(&self) -> Result<Option<std::fs::File>> {
        match self {
            OutputTarget::Stdout => Ok(None),
            OutputTarget::File(tmp, path) => {
                tmp.reopen().map(Some).with_context(|| format!("cannot write '{}'", path.display()))
            }
            OutputTarget::Device(path) => std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map(Some)
                .with_context(|| format!("cannot write '{}'", path.display())),
        }
    }

    /// The path a drawing backend writes to (`None`: standard output).
    pub fn draw_path(&self) -> Option<&Path> {
        match self {
            OutputTarget::Stdout => None,
            OutputTarget::File(tmp, _) => Some(tmp.path()),
            OutputTarget::Device(path) => Some(path),
        }
    }

    /// Moves the finished temporary file to its final name.
    pub fn finish(self) -> Result<()> {
        if let OutputTarget::File(tmp, path) = self {
            // An fsync that fails can mean data that never reached the disk: no rename then
            // (the temporary file is removed). A filesystem without fsync is no failure.
            if let Err(e) = tmp.as_file().sync_all() {
                if !matches!(e.kind(), std::io::ErrorKind::InvalidInput | std::io::ErrorKind::Unsupported) {
                    bail!("cannot write '{}': {e}", path.display());
                }
            }
            tmp.persist(&path).map_err(|e| anyhow!("cannot write '{}': {}", path.display(), e.error))?;
        }
        Ok(())
    }
}

/// A file writer for large outputs that hands the disk writeback to a helper thread as
/// it goes: every `step` bytes the helper flushes what has been written so far
/// (`sync_data`), while the caller keeps writing. The `fsync` in [`OutputTarget::finish`]
/// then finds little left to write, instead of the whole file at the end (a 504 MB map
/// spent ~0.2 s there). A flush still running when the next step comes is not queued
/// twice. Errors of these early flushes are ignored: the final `sync_all` reports nothing
/// either, and a failed write is caught by `write` itself.
pub struct WritebackFile {
    file: std::fs::File,
    step: u64,
    since: u64,
    /// Flushes handed to the helper (the test checks the helper is used).
    kicks: u64,
    kick: Option<std::sync::mpsc::SyncSender<()>>,
    helper: Option<std::thread::JoinHandle<()>>,
}

impl WritebackFile {
    /// Wraps `file`; flushes start every `step` bytes (no helper when the file cannot be
    /// cloned or no thread started: then it is a plain file writer).
    pub fn new(file: std::fs::File, step: u64) -> WritebackFile {
        let (kick, helper) = match file.try_clone() {
            Ok(clone) => {
                let (tx, rx) = std::sync::mpsc::sync_channel::<()>(1);
                let spawned = std::thread::Builder::new().name("trum-writeback".into()).spawn(move || {
                    for () in rx {
                        clone.sync_data().ok();
                    }
                });
                match spawned {
                    Ok(h) => (Some(tx), Some(h)),
                    // no thread to spare: a plain writer
                    Err(_) => (None, None),
                }
            }
            Err(_) => (None, None),
        };
        WritebackFile { file, step, since: 0, kicks: 0, kick, helper }
    }
}

impl std::io::Write for WritebackFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.since += n as u64;
        if self.since >= self.step {
            self.since = 0;
            if let Some(k) = &self.kick {
                // Full means a flush is queued already; it will include these bytes.
                if k.try_send(()).is_ok() {
                    self.kicks += 1;
                }
            }
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Drop for WritebackFile {
    fn drop(&mut self) {
        self.kick = None;
        if let Some(h) = self.helper.take() {
            h.join().ok();
        }
    }
}

/// A progress bar on stderr that appears only once a run has taken more than a second,
/// and never when stderr is not a terminal or with `--quiet`.
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
    enabled: bool,
    shown: bool,
}

impl Progress {
    /// A bar for `total` steps (`unit` names them in the message).
    pub fn new(total: u64, unit: &str, quiet: bool) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        let template =
            format!("{{elapsed_precise}} [{{bar:40}}] {{human_pos}}/{{human_len}} {unit} ({{per_sec}}, eta {{eta}})");
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Progress { bar, start: Instant::now(), enabled: !quiet && std::io::stderr().is_terminal(), shown: false }
    }

    /// Sets the position; shows the bar once the run is older than a second.
    pub fn set(&mut self, pos: u64) {
        if self.enabled && !self.shown && self.start.elapsed() > Duration::from_secs(1) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        self.bar.set_position(pos);
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A CSV/JSON-friendly number: Rust's shortest round-trip form, empty when not finite.
pub fn csv_number(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// A readable number with `sig` significant digits (fixed notation for magnitudes in
/// [1e-3, 1e6), exponent form otherwise); `-` when not finite.
pub fn fmt_sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if (-3..6).contains(&mag) {
        let decimals = (sig as i32 - 1 - mag).max(0) as usize;
        let s = format!("{v:.decimals$}");
        // rounding can carry into a new digit (999.9995 → 1000.000); that is harmless here
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{v:.prec$e}", prec = sig.saturating_sub(1));
        // trim trailing zeros of the mantissa: 1.50000e-9 → 1.5e-9
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            _ => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_syntax() {
        assert_eq!(parse_axis("250").expect("valid"), Axis::fixed(250.0));
        assert_eq!(parse_axis("100:300:5").expect("valid"), Axis::linspace(100.0, 300.0, 5));
        assert!(parse_axis("100:300").expect_err("invalid").contains("START:STOP:N"));
        assert!(parse_axis("100:300:0").expect_err("invalid").contains("whole number"));
        assert!(parse_axis("100:300:2.5").expect_err("invalid").contains("whole number"));
        assert!(parse_axis("nan").expect_err("invalid").contains("finite"));
        assert!(parse_axis("abc").expect_err("invalid").contains("not a number"));
    }

    #[test]
    fn significant_digits() {
        assert_eq!(fmt_sig(95.123456, 6), "95.1235");
        assert_eq!(fmt_sig(43000.0, 6), "43000");
        assert_eq!(fmt_sig(5.41e-9, 6), "5.41e-9");
        assert_eq!(fmt_sig(-0.25, 6), "-0.25");
        assert_eq!(fmt_sig(f64::NAN, 6), "-");
        assert_eq!(csv_number(f64::NAN), "");
        assert_eq!(csv_number(0.1), "0.1");
    }

    #[test]
    fn writeback_file_writes_everything_and_flushes_on_the_way() {
        use std::io::Write;
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("w.bin");
        let data: Vec<u8> = (0..3_000_000u32).map(|i| (i % 251) as u8).collect();
        let mut w = WritebackFile::new(std::fs::File::create(&path).expect("create"), 64 << 10);
        for piece in data.chunks(10_007) {
            w.write_all(piece).expect("write");
        }
        w.flush().expect("flush");
        assert!(w.kicks >= 1, "no early flush was started");
        drop(w); // joins the helper
        assert_eq!(std::fs::read(&path).expect("read back"), data);
    }
}

//! Output files written atomically, large files flushed to disk as they grow, and the
//! progress bar.

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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

#[cfg(test)]
mod tests {
    use super::*;

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

//! Output files written atomically, large files flushed to disk as they grow, and the
//! progress bar.

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Where a command writes a file: `-` is stdout, anything else a temporary file in the
/// target's directory that is renamed over the target only when the run succeeded, so a
/// failed or interrupted run leaves no partial file behind. An existing target that is not
/// a regular file (`/dev/null`, a FIFO, a terminal) is written in place: renaming over it
/// would replace the device with a regular file.
///
/// Overwriting behaves as `cp` and `sort -o` do: a symbolic link is written through (its
/// target is replaced, the link stays), an existing file keeps its permission bits (and,
/// where the user may set them, its owner and group), a write-protected file is not
/// replaced, and an output that is one of the run's input files (same device and inode,
/// so through links too) is refused before any work starts.
pub enum OutputTarget {
    /// Standard output.
    Stdout,
    /// A temporary file, the final path, and the temporary file's entry in the list the
    /// signal handler cleans up.
    File(tempfile::NamedTempFile, PathBuf, signals::Registered),
    /// An existing special file, written directly.
    Device(PathBuf),
}

impl OutputTarget {
    /// Opens the target; `suffix` keeps the extension on the temporary file (plotters uses it).
    pub fn create(path: &Path, suffix: &str) -> Result<OutputTarget> {
        if path.as_os_str() == "-" {
            return Ok(OutputTarget::Stdout);
        }
        let target = follow_links(path)?;
        check_not_an_input(path, &target)?;
        let existing = std::fs::metadata(&target).ok();
        if let Some(meta) = &existing {
            if meta.is_dir() {
                bail!("output '{}' is a directory", path.display());
            }
            if !meta.is_file() {
                return Ok(OutputTarget::Device(target));
            }
            check_writable(path, meta)?;
        }
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            bail!("cannot write '{}': directory '{}' does not exist", path.display(), dir.display());
        }
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let prefix = format!(".{name}.");
        let mut b = tempfile::Builder::new();
        b.prefix(&prefix).suffix(suffix);
        // tempfile creates 0600 files; a new output file gets 0666 less the umask, as
        // `cp` and `sort -o` create theirs.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            b.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp =
            b.tempfile_in(&dir).with_context(|| format!("cannot create a temporary file in '{}'", dir.display()))?;
        let reg = signals::register(tmp.path());
        if let Some(meta) = &existing {
            keep_mode_and_owner(tmp.as_file(), meta);
        }
        Ok(OutputTarget::File(tmp, target, reg))
    }

    /// The file to write into (`None`: standard output).
    pub fn open(&self) -> Result<Option<std::fs::File>> {
        match self {
            OutputTarget::Stdout => Ok(None),
            OutputTarget::File(tmp, path, _) => {
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
            OutputTarget::File(tmp, _, _) => Some(tmp.path()),
            OutputTarget::Device(path) => Some(path),
        }
    }

    /// Moves the finished temporary file to its final name.
    pub fn finish(self) -> Result<()> {
        if let OutputTarget::File(tmp, path, _reg) = self {
            // An fsync that fails can mean data that never reached the disk: no rename then
            // (the temporary file is removed). A filesystem without fsync is no failure.
            if let Err(e) = tmp.as_file().sync_all() {
                if !matches!(e.kind(), std::io::ErrorKind::InvalidInput | std::io::ErrorKind::Unsupported) {
                    bail!("cannot write '{}': {e}", path.display());
                }
            }
            // Held across the rename: a signal arriving now waits, and then finds the
            // temporary file gone (renamed) rather than removing half of a rename.
            let guard = signals::lock();
            let result = tmp.persist(&path).map_err(|e| anyhow!("cannot write '{}': {}", path.display(), e.error));
            drop(guard);
            result?;
        }
        Ok(())
    }
}

/// The file a path finally names: symbolic links followed (relative ones against their
/// own directory), so that the link is written through instead of being replaced by a
/// regular file. A dangling link names the file it would create.
fn follow_links(path: &Path) -> Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&p).with_context(|| format!("cannot read link '{}'", p.display()))?;
                p = if link.is_absolute() { link } else { p.parent().map(|d| d.join(&link)).unwrap_or(link) };
            }
            _ => return Ok(p),
        }
    }
    bail!("cannot write '{}': too many levels of symbolic links", path.display())
}

/// Refuses to replace a file the user may not write (its permission bits, judged for the
/// effective user and groups; the superuser only when no write bit is set at all, as
/// `rm` asks before removing a write-protected file). Renaming over it would need only
/// the directory's permission and would silently defeat the protection.
fn check_writable(path: &Path, meta: &std::fs::Metadata) -> Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let mode = meta.mode();
        let uid = rustix::process::geteuid();
        let writable = if uid.is_root() {
            mode & 0o222 != 0
        } else if uid.as_raw() == meta.uid() {
            mode & 0o200 != 0
        } else if rustix::process::getegid().as_raw() == meta.gid()
            || rustix::process::getgroups().is_ok_and(|g| g.iter().any(|g| g.as_raw() == meta.gid()))
        {
            mode & 0o020 != 0
        } else {
            mode & 0o002 != 0
        };
        if !writable {
            bail!(
                "output '{}' is write-protected (mode {:04o}); not replacing it (make it writable or remove it first)",
                path.display(),
                mode & 0o7777
            );
        }
    }
    #[cfg(not(unix))]
    if meta.permissions().readonly() {
        bail!("output '{}' is read-only; not replacing it", path.display());
    }
    Ok(())
}

/// Gives the new file the replaced file's permission bits and, where allowed, its owner
/// and group (a failed change of owner is not an error: `cp` does not preserve it either).
fn keep_mode_and_owner(file: &std::fs::File, meta: &std::fs::Metadata) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = std::os::unix::fs::fchown(file, Some(meta.uid()), Some(meta.gid()));
    }
    let _ = file.set_permissions(meta.permissions());
}

thread_local! {
    /// The input files the current run has read (device, inode and how they were named),
    /// checked by [`OutputTarget::create`]. Per thread: a run's reading and its output
    /// targets happen on the thread that runs the command, and in-process tests run
    /// several commands at once on different threads.
    static INPUTS: std::cell::RefCell<Vec<(u64, u64, String)>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Forgets the inputs of an earlier run on this thread.
pub fn reset_inputs() {
    INPUTS.with(|i| i.borrow_mut().clear());
}

/// Records that the run reads `path` (`what` names it in an error, e.g. "--data 'd.csv'").
pub fn note_input(path: &Path, what: &str) {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        if m.is_file() {
            INPUTS.with(|i| i.borrow_mut().push((m.dev(), m.ino(), what.to_string())));
        }
    }
    #[cfg(not(unix))]
    let _ = (path, what);
}

fn check_not_an_input(shown: &Path, target: &Path) -> Result<()> {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(target) {
        use std::os::unix::fs::MetadataExt;
        let hit = INPUTS.with(|i| i.borrow().iter().find(|(d, n, _)| *d == m.dev() && *n == m.ino()).cloned());
        if let Some((_, _, what)) = hit {
            bail!(
                "output '{}' is the input file {what} (the same file); refusing to overwrite an input, write elsewhere",
                shown.display()
            );
        }
    }
    #[cfg(not(unix))]
    let _ = (shown, target);
    Ok(())
}

/// Cleanup on SIGINT, SIGTERM and SIGHUP: the temporary output files that exist at that
/// moment are removed, then the process dies of the same signal (so a shell sees it
/// interrupted, exit status 128 + signal). `signal-hook`'s iterator receives the signal on
/// a thread of its own, where removing files and taking a lock are safe (a plain signal
/// handler may do neither), and it needs no unsafe code here; `ctrlc` would hide which
/// signal came and so could not end the process with it. SIGKILL cannot be caught: it may
/// leave a temporary `.NAME.XXXXXX` file beside the target (never a partial target).
pub mod signals {
    use std::path::{Path, PathBuf};
    use std::sync::{Mutex, MutexGuard};

    static TEMPS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

    pub(super) fn lock() -> MutexGuard<'static, Vec<PathBuf>> {
        TEMPS.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// A temporary file in the cleanup list; dropping it takes the name off the list
    /// (the file itself is removed by `NamedTempFile`, or was renamed).
    pub struct Registered(PathBuf);

    impl Drop for Registered {
        fn drop(&mut self) {
            let mut g = lock();
            if let Some(i) = g.iter().position(|q| *q == self.0) {
                g.swap_remove(i);
            }
        }
    }

    pub(super) fn register(p: &Path) -> Registered {
        lock().push(p.to_path_buf());
        Registered(p.to_path_buf())
    }

    /// Installs the handler (once; later calls do nothing). Without it (a library user
    /// running commands in-process) a signal ends the process as it would anyway.
    pub fn install() {
        #[cfg(unix)]
        {
            static ONCE: std::sync::Once = std::sync::Once::new();
            ONCE.call_once(|| {
                use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
                let Ok(mut sigs) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else { return };
                let _ = std::thread::Builder::new().name("trum-signals".into()).spawn(move || {
                    if let Some(sig) = sigs.forever().next() {
                        // Keep the lock: no new temporary file appears, no rename starts.
                        let g = lock();
                        for p in g.iter() {
                            let _ = std::fs::remove_file(p);
                        }
                        let _ = signal_hook::low_level::emulate_default_handler(sig);
                        std::process::exit(128 + sig);
                    }
                });
            });
        }
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

/// The number of worker threads for `requested` (`None` or 0: RAYON_NUM_THREADS, else
/// every core), never more than the machine's cores: more threads than cores only add
/// switching and memory (100 000 threads drove the load above 600). A flag above the
/// cores is capped with a note on `err` (`flag` names the option); the environment
/// variable is capped silently.
pub fn worker_threads(requested: Option<usize>, flag: &str, err: &mut dyn std::io::Write) -> Result<usize> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    match requested {
        Some(n) if n > cores => {
            writeln!(err, "note: {flag} {n} capped at {cores}, the number of cores of this machine")?;
            Ok(cores)
        }
        Some(n) if n > 0 => Ok(n),
        _ => Ok(std::env::var("RAYON_NUM_THREADS")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .filter(|&n| n > 0)
            .map_or(cores, |n| n.min(cores))),
    }
}

/// `3.1 GB`, `310 GB`, `12 MB` (decimal units).
pub fn human_bytes(b: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut i = 0;
    while v >= 1000.0 && i + 1 < units.len() {
        v /= 1000.0;
        i += 1;
    }
    if v < 10.0 && i > 0 {
        format!("{v:.1} {}", units[i])
    } else {
        format!("{v:.0} {}", units[i])
    }
}

/// `45 s`, `17 min`, `3.2 h`, `41 days`.
pub fn human_seconds(s: f64) -> String {
    if s < 90.0 {
        format!("{s:.0} s")
    } else if s < 5400.0 {
        format!("{:.0} min", s / 60.0)
    } else if s < 3.0 * 86400.0 {
        format!("{:.1} h", s / 3600.0)
    } else {
        format!("{:.0} days", s / 86400.0)
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

//! `trum map`: a grid of operating points to CSV, streamed in constant memory.
//!
//! The grid is cut into the core's fixed chunks ([`trum_core::sweep::CHUNK_POINTS`]). Each
//! chunk is solved serially with warm starts ([`trum_core::sweep::solve_range`]), exactly
//! as Python's `trum.map` solves it, and formatted into a byte buffer;
//! a wave of chunks is solved in parallel with rayon while the previous wave is being
//! written. Chunk boundaries do not depend on the thread count, so the output is
//! byte-identical whatever the parallelism. At most three waves exist at once (one being
//! solved, one queued, one being written): memory is constant for any grid size.

use crate::args::{GridArgs, MotorArgs};
use crate::format::csv_number;
use crate::grid::{check_grid, default_grid};
use crate::output::{OutputTarget, Progress, WritebackFile};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use rayon::prelude::*;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use trum_core::quantities::{Quantity, QUANTITIES};
use trum_core::solve::Prepared;
use trum_core::sweep::{
    axis_values, chunk_count, chunk_range, solve_range, Axis, Grid, LineStall, AXES, CHUNK_POINTS, LOADED_STALL_COLUMN,
};
use trum_core::Motor;

/// Bytes between the early disk flushes of a map written to a file (4-32 MB measured the
/// same; docs/PERFORMANCE.md "CSV maps").
const WRITEBACK_STEP: u64 = 32 << 20;

/// Input columns, in the order they are written: the core's grid axes.
pub const INPUT_COLUMNS: [&str; 4] = AXES;

#[derive(Args, Debug)]
pub struct MapArgs {
    #[command(flatten)]
    motor: MotorArgs,
    #[command(flatten)]
    grid: GridArgs,
    /// Quantity columns to write, comma-separated (default: all, `loaded_stall_torque_nm`
    /// last; see `trum point` for the list).
    #[arg(long, value_name = "a,b,c")]
    columns: Option<String>,
    /// Output CSV file (`-` for stdout). Written to a temporary file and renamed at the end.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
    /// Worker threads (default: RAYON_NUM_THREADS or the number of cores; never more than
    /// the machine's cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Largest grid to solve, in points (docs/CLI.md, "Limits"): a bigger grid is refused
    /// before any work with its estimated size and time; raise this to run it anyway.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_POINTS)]
    max_points: u64,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    /// Points per chunk (advanced; changes warm-start boundaries, so the last digits may differ).
    #[arg(long, default_value_t = CHUNK_POINTS, hide = true)]
    chunk_points: u64,
}

/// The map of a motor when nothing sets the axes: preload 100-500 N in 9 steps, load
/// torque from 0 to 5 % above the largest loaded stall torque over those preloads
/// ([`crate::grid::running_torque_top`], rounded up to two significant digits) in 25
/// steps, at the motor's drive (its `[drive]`, else 200 V, 43 kHz).
fn motor_default_grid(motor: &Motor, drive: Option<trum_core::params::Drive>) -> Result<Grid> {
    let (v, f) = drive
        .map_or((crate::grid::DEFAULT_VOLTAGE_V, crate::grid::DEFAULT_FREQUENCY_HZ), |d| (d.voltage_v, d.frequency_hz));
    let preload = Axis::linspace(100.0, 500.0, 9);
    let Some(stall) = crate::grid::running_torque_top(motor, &preload, v, f) else {
        bail!(
            "the motor does not run at {}-{} N, {} V, {} Hz, so it has no default map: give the axes (e.g. --preload-n 100:500:9 --torque-nm 0:1:25)",
            preload.start,
            preload.stop,
            v,
            f
        );
    };
    let step = 10f64.powf(stall.log10().floor() - 1.0);
    let top = (stall / step).ceil() * step;
    Ok(Grid {
        preload_n: preload,
        torque_nm: Axis::linspace(0.0, crate::format::round_sig(top, 2), 25),
        voltage_v: Axis::fixed(v),
        frequency_hz: Axis::fixed(f),
    })
}

/// An axis as the command line writes it.
fn axis_text(a: &Axis) -> String {
    if a.n == 1 {
        csv_number(a.start)
    } else {
        format!("{}:{}:{}", csv_number(a.start), csv_number(a.stop), a.n)
    }
}

/// A column of a map after the inputs, `status` and `warnings`.
#[derive(Clone, Copy, Debug)]
pub enum MapColumn {
    /// A quantity of the point's own solution.
    Quantity(&'static Quantity),
    /// The load torque at which the loaded motor stops on the point's torque line
    /// ([`LOADED_STALL_COLUMN`], [`LineStall`]): one bisection per line, shared by its points.
    LoadedStall,
}

impl MapColumn {
    /// The column's name in the header.
    pub fn name(&self) -> &'static str {
        match self {
            MapColumn::Quantity(q) => q.name,
            MapColumn::LoadedStall => LOADED_STALL_COLUMN.0,
        }
    }
}

/// The default columns: every quantity, then the loaded stall torque.
pub fn default_columns() -> Vec<MapColumn> {
    QUANTITIES.iter().map(MapColumn::Quantity).chain([MapColumn::LoadedStall]).collect()
}

/// Parses `--columns`: names of [`default_columns`], no duplicates. The accepted names and
/// the list an unknown name's error prints are both that list, so they always agree.
pub fn parse_columns(spec: Option<&str>) -> Result<Vec<MapColumn>> {
    let Some(spec) = spec else { return Ok(default_columns()) };
    let known = default_columns();
    let mut cols: Vec<MapColumn> = Vec::new();
    for name in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        if INPUT_COLUMNS.contains(&name) || name == "status" || name == "warnings" {
            bail!(
                "--columns: '{name}' is always written (inputs, status and warnings come first); list only quantities"
            );
        }
        let c = *known.iter().find(|k| k.name() == name).ok_or_else(|| {
            let names: Vec<&str> = known.iter().map(MapColumn::name).collect();
            let hint = crate::suggest::hint(name, crate::suggest::names(names.iter().copied()));
            anyhow!("--columns: unknown quantity '{name}'; valid quantities are: {}{hint}", names.join(", "))
        })?;
        if cols.iter().any(|k| k.name() == c.name()) {
            bail!("--columns: '{name}' is listed twice");
        }
        cols.push(c);
    }
    if cols.is_empty() {
        bail!("--columns: no column given");
    }
    Ok(cols)
}

pub fn run(a: &MapArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let (motor, sweep) = a.motor.load()?;
    let given = [a.grid.preload_n, a.grid.torque_nm, a.grid.voltage_v, a.grid.frequency_hz];
    let in_file = [sweep.preload_n, sweep.torque_nm, sweep.voltage_v, sweep.frequency_hz];
    let grid = if given.iter().chain(&in_file).all(Option::is_none) {
        // Nothing says what to map: the motor's own map, not a single point.
        let drive = crate::optimize::motor_drive(&a.motor.motor)?;
        let g = motor_default_grid(&motor, drive)?;
        if !a.quiet {
            writeln!(
                err,
                "note: no axes given (command line or the motor file's [sweep]): mapping the motor's default grid \
                 --preload-n {} --torque-nm {} --voltage-v {} --frequency-hz {}",
                axis_text(&g.preload_n),
                axis_text(&g.torque_nm),
                axis_text(&g.voltage_v),
                axis_text(&g.frequency_hz)
            )?;
        }
        g
    } else {
        // an axis set nowhere is fixed; its drive is the motor's own ([drive]), as for
        // `trum point`, `trum optimize` and `trum plot`
        let mut fallback = default_grid();
        if let Some(d) = crate::optimize::motor_drive(&a.motor.motor)? {
            fallback.voltage_v = Axis::fixed(d.voltage_v);
            fallback.frequency_hz = Axis::fixed(d.frequency_hz);
        }
        a.grid.resolve(&sweep, &fallback)
    };
    check_grid(&grid)?;
    let cols = parse_columns(a.columns.as_deref())?;
    if a.chunk_points == 0 {
        bail!("--chunk-points must be >= 1");
    }
    let threads = crate::output::worker_threads(a.threads, "--threads", err)?;
    check_size(&motor, &grid, &cols, threads, a.max_points)?;
    let target = OutputTarget::create(&a.output, ".csv")?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start worker threads")?;
    let mut progress = Progress::new(grid.len(), "points", a.quiet);
    let result = match target.open()? {
        None => write_map(&motor, &grid, &cols, a.chunk_points, &pool, out, &mut progress),
        Some(file) => {
            let mut w = BufWriter::with_capacity(1 << 20, WritebackFile::new(file, WRITEBACK_STEP));
            write_map(&motor, &grid, &cols, a.chunk_points, &pool, &mut w, &mut progress)
                .and_then(|()| w.flush().map_err(Into::into))
                .with_context(|| format!("writing '{}'", a.output.display()))
        }
    };
    progress.finish();
    result?;
    target.finish()?;
    Ok(0)
}

/// Default of `--max-points`: 2·10^8 points, tens of GB of CSV and some minutes on two
/// cores (10^8-point maps are run and measured in docs/PERFORMANCE.md).
pub const DEFAULT_MAX_POINTS: u64 = 200_000_000;

/// Bytes of a CSV cell, on average: a shortest round-trip double in positional notation
/// (12-20 digits) and its comma, measured 17-19 on maps of the presets.
const BYTES_PER_CELL: f64 = 19.0;

/// Solver time a point [s] on one core, in a warm-started sweep with its formatting:
/// 1 µs for the baseline (0.3 µs solving, the rest formatting and writing;
/// docs/PERFORMANCE.md), 13 µs with the slowest effects on (numerical interface,
/// voltage sag).
fn seconds_per_point(motor: &Motor) -> f64 {
    if motor.effects.is_none() {
        1e-6
    } else {
        13e-6
    }
}

/// Cold solves of one torque line's loaded stall torque: the no-load point, the bracket
/// and the bisection to a relative 1e-9 (about 30).
const SOLVES_PER_LINE: f64 = 34.0;

/// The time of one cold solve in warm-started map points ([`seconds_per_point`]): 0.7-3
/// measured, effect-free and with the shipped `trum60a`'s effects (docs/PERFORMANCE.md,
/// the cost of `loaded_stall_torque_nm`).
const COLD_SOLVE_POINTS: f64 = 3.0;

/// The size model of `trum map`: (points, estimated CSV bytes, estimated seconds). The
/// loaded stall torque adds its bisection once per torque line.
pub fn size_estimate(motor: &Motor, grid: &Grid, cols: &[MapColumn], threads: usize) -> (u64, f64, f64) {
    let n = grid.len();
    let bytes = n as f64 * (INPUT_COLUMNS.len() + 1 + cols.len()) as f64 * BYTES_PER_CELL;
    let lines = if cols.iter().any(|c| matches!(c, MapColumn::LoadedStall)) {
        n as f64 / grid.torque_nm.n.max(1) as f64
    } else {
        0.0
    };
    let point_equivalents = n as f64 + lines * SOLVES_PER_LINE * COLD_SOLVE_POINTS;
    let secs = point_equivalents * seconds_per_point(motor) / threads.max(1) as f64;
    (n, bytes, secs)
}

/// Refuses a grid above `max_points` before any work, with its size and the flag.
fn check_size(motor: &Motor, grid: &Grid, cols: &[MapColumn], threads: usize, max_points: u64) -> Result<()> {
    let (n, bytes, secs) = size_estimate(motor, grid, cols, threads);
    if n > max_points {
        bail!(
            "the grid has {} points ({}): an estimated {} of CSV and {} on {threads} thread{}; that is more than \
             --max-points {max_points} (docs/CLI.md, \"Limits\"); give --max-points {} to run it anyway, or a coarser grid",
            if n == u64::MAX { "more than 1.8e19".to_string() } else { n.to_string() },
            grid.axes().iter().map(|a| a.n.to_string()).collect::<Vec<_>>().join(" × "),
            crate::output::human_bytes(bytes),
            crate::output::human_seconds(secs),
            if threads == 1 { "" } else { "s" },
            n
        );
    }
    Ok(())
}

/// The CSV header line: inputs, `status`, `warnings` (the motor's `[limits]` keys the
/// point exceeds, `;`-separated, empty when none), then the quantities.
pub fn header(cols: &[MapColumn]) -> String {
    let mut h: Vec<&str> = INPUT_COLUMNS.to_vec();
    h.push("status");
    h.push("warnings");
    h.extend(cols.iter().map(MapColumn::name));
    h.join(",") + "\n"
}

/// Solves and formats one chunk.
fn chunk_csv(motor: &Motor, prep: &Prepared, grid: &Grid, cols: &[MapColumn], range: std::ops::Range<u64>) -> Vec<u8> {
    let mut buf = Vec::with_capacity((range.end - range.start) as usize * (24 * cols.len() + 64));
    let mut fmt = NumberFormatter::new();
    let mut last = ColumnMemo::new(INPUT_COLUMNS.len() + cols.len());
    let mut line = LineStall::new();
    solve_range(motor, prep, grid, range, |_, op, s| {
        for (c, v) in axis_values(op).into_iter().enumerate() {
            last.push(&mut fmt, &mut buf, c, v);
            buf.push(b',');
        }
        buf.extend_from_slice(s.status.as_str().as_bytes());
        buf.push(b',');
        if !s.warnings.is_empty() {
            buf.extend_from_slice(s.warnings.to_string().as_bytes());
        }
        let valid = s.status.is_valid();
        for (c, col) in cols.iter().enumerate() {
            buf.push(b',');
            match col {
                // Invalid points: empty cells (never "NaN"); the status column says why.
                MapColumn::Quantity(q) => {
                    if valid {
                        last.push(&mut fmt, &mut buf, INPUT_COLUMNS.len() + c, (q.get)(s));
                    }
                }
                // A property of the line, not of the point: written whatever the point's
                // status (empty where the rotor does not run at no load).
                MapColumn::LoadedStall => {
                    last.push(&mut fmt, &mut buf, INPUT_COLUMNS.len() + c, line.get(prep, motor, op));
                }
            }
        }
        buf.push(b'\n');
    });
    buf
}

/// Where each column's latest number was written, reused while the column repeats it: in
/// a map the drive voltage and frequency, the preload along a torque line, and quantities
/// that are constant or zero for a motor (the electrode voltage without sag, the modal
/// stiffness, an effect's zero loss) repeat row after row, and copying their bytes from
/// the row above is several times cheaper than formatting them again. The text stays in
/// the chunk's own buffer (`out` only grows), so a new value is written once.
struct ColumnMemo {
    /// Per column: the value's bits (NaN's, never produced by a finite value, when empty)
    /// and the range of `out` holding its text.
    last: Vec<(u64, std::ops::Range<usize>)>,
}

impl ColumnMemo {
    fn new(columns: usize) -> Self {
        ColumnMemo { last: vec![(f64::NAN.to_bits(), 0..0); columns] }
    }

    /// Appends `v` to `out` as `fmt.push` does, for column `c`; `out` must be the buffer
    /// of every earlier call.
    fn push(&mut self, fmt: &mut NumberFormatter, out: &mut Vec<u8>, c: usize, v: f64) {
        let (bits, text) = &mut self.last[c];
        if *bits == v.to_bits() {
            out.extend_from_within(text.clone());
        } else {
            let start = out.len();
            fmt.push(out, v);
            (*bits, *text) = (v.to_bits(), start..out.len());
        }
    }
}

/// Writes numbers as [`crate::format::csv_number`] does — shortest round-trip digits,
/// plain decimals for magnitudes in [1e-5, 1e16), exponent form (`1e23`) outside — but
/// through `zmij`, without allocating: number formatting cost more than solving in large
/// maps (zmij takes 11 ns a number where ryu takes 19, for the same digits).
pub struct NumberFormatter {
    digits: zmij::Buffer,
}

impl Default for NumberFormatter {
    fn default() -> Self {
        Self::new()
    }
}

impl NumberFormatter {
    /// A formatter with its own scratch buffer.
    pub fn new() -> Self {
        NumberFormatter { digits: zmij::Buffer::new() }
    }

    /// Appends `v` to `out`; nothing for a non-finite value (an empty CSV cell).
    pub fn push(&mut self, out: &mut Vec<u8>, v: f64) {
        if !v.is_finite() {
            return;
        }
        let a = v.abs();
        let s = self.digits.format_finite(v).as_bytes();
        if (crate::format::PLAIN_MIN..crate::format::PLAIN_MAX).contains(&a) {
            // zmij writes these magnitudes in decimal form (decimal exponent -5..=15: the
            // shortest digits of a double below 1e16, or at or above the double nearest
            // 1e-5, stay on the same side of the bound), an integer as "N.0", which
            // Display writes without ".0". Deciding by magnitude instead of reading the
            // text back (looking for `e`, then for ".0") was ~17 % of a map's CPU.
            let n = if v.fract() == 0.0 { s.len() - 2 } else { s.len() };
            out.extend_from_slice(&s[..n]);
            return;
        }
        let Some(e) = s.iter().position(|&b| b == b'e') else {
            out.extend_from_slice(s.strip_suffix(b".0").unwrap_or(s));
            return;
        };
        // Exponent form `[-]d[.ddd]e[+-]EXP`: as `{:e}` writes it (no ".0", no "+").
        let mant = &s[..e];
        out.extend_from_slice(mant.strip_suffix(b".0").unwrap_or(mant));
        out.push(b'e');
        let exp = &s[e + 1..];
        out.extend_from_slice(exp.strip_prefix(b"+").unwrap_or(exp));
    }
}

fn write_map(
    motor: &Motor,
    grid: &Grid,
    cols: &[MapColumn],
    chunk: u64,
    pool: &rayon::ThreadPool,
    w: &mut dyn Write,
    progress: &mut Progress,
) -> Result<()> {
    w.write_all(header(cols).as_bytes())?;
    let total = grid.len();
    let nchunks = chunk_count(total, chunk);
    // Two chunks per thread keep both busy; at most three waves (solving, queued, being
    // written) of ~2 MB chunks bound the memory (4 per thread reached 51 MB at 10^7 points).
    let wave = (2 * pool.current_num_threads() as u64).max(2);
    let prep = Prepared::new(motor);
    // A bounded channel of one wave is the reorder buffer: the solver thread runs at most
    // one wave ahead of the writer.
    let (tx, rx) = std::sync::mpsc::sync_channel::<(u64, Vec<Vec<u8>>)>(1);
    std::thread::scope(|scope| -> Result<()> {
        let prep = &prep;
        scope.spawn(move || {
            let mut first = 0;
            while first < nchunks {
                let last = (first + wave).min(nchunks);
                let bufs: Vec<Vec<u8>> = pool.install(|| {
                    (first..last)
                        .into_par_iter()
                        .map(|c| chunk_csv(motor, prep, grid, cols, chunk_range(total, chunk, c)))
                        .collect()
                });
                let done = (last * chunk).min(total);
                if tx.send((done, bufs)).is_err() {
                    return; // the writer failed and hung up; stop solving
                }
                first = last;
            }
        });
        // Fault injection for the test that checks a failed run leaves no file behind.
        let fail_after: Option<u64> = std::env::var("TRUM_TEST_FAIL_AFTER_POINTS").ok().and_then(|v| v.parse().ok());
        for (done, bufs) in rx {
            for b in &bufs {
                w.write_all(b)?;
            }
            progress.set(done);
            if fail_after.is_some_and(|n| done >= n) {
                bail!("injected failure after {done} points (TRUM_TEST_FAIL_AFTER_POINTS)");
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_formatter_writes_what_display_writes() {
        let mut f = NumberFormatter::new();
        let (mut exact, mut total) = (0usize, 0usize);
        let mut check = |v: f64| {
            let mut out = Vec::new();
            f.push(&mut out, v);
            let got = String::from_utf8(out).expect("ascii");
            let want = crate::format::csv_number(v);
            // Same shortest round trip in the same notation. (Where two 17-digit strings
            // are equally short, zmij and std may pick different last digits: 1658206780088562.2
            // vs .3 for 1.6582067800885623e15; both parse back to v.)
            assert_eq!(got.parse::<f64>().map(f64::to_bits), Ok(v.to_bits()), "{v:e}: {got}");
            assert_eq!(got.len(), want.len(), "{v:e}: {got} vs {want}");
            assert_eq!(got.contains('e'), want.contains('e'), "{v:e}: {got} vs {want}");
            exact += usize::from(got == want);
            total += 1;
        };
        for v in [0.0, -0.0, 1.0, -1.0, 0.1, 1e-7, 1.5e20, 1e21, 123.456, 5e-324, f64::MAX, f64::MIN_POSITIVE, 43000.0]
        {
            check(v);
        }
        // Both sides of the magnitudes where the notation changes, and integers near them.
        for b in [1e-5f64, 1e16, 1e15, 1e-4] {
            for k in -3i64..=3 {
                let v = f64::from_bits(b.to_bits().wrapping_add_signed(k));
                check(v);
                check(-v);
            }
        }
        for v in [9_999_999_999_999_998.0, 999_999_999_999_999.9, 4_503_599_627_370_496.5, 0.5, 2.0f64.powi(52)] {
            check(v);
            check(-v);
        }
        // Random bit patterns over the whole finite range, and values of map magnitudes.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                check(v);
                check(v.abs().log2().fract() * 1e3);
            }
        }
        assert!(exact as f64 >= 0.999 * total as f64, "{exact} of {total} identical to Display");
        let mut out = Vec::new();
        f.push(&mut out, f64::NAN);
        f.push(&mut out, f64::INFINITY);
        assert!(out.is_empty());
    }

    /// The list an unknown `--columns` name prints is exactly the set of names
    /// `--columns` accepts: every listed name parses on its own, and every accepted
    /// column (the defaults, `loaded_stall_torque_nm` among them) is listed.
    #[test]
    fn unknown_column_error_lists_exactly_the_accepted_columns() {
        let msg = format!("{:#}", parse_columns(Some("speed_rmp")).expect_err("an unknown name is an error"));
        let list = msg.split("valid quantities are: ").nth(1).expect("the message lists the names");
        let list = list.split("; did you mean").next().unwrap_or(list);
        let listed: Vec<&str> = list.split(", ").collect();
        let accepted: Vec<&str> = default_columns().iter().map(MapColumn::name).collect();
        assert_eq!(listed, accepted, "{msg}");
        assert!(listed.contains(&LOADED_STALL_COLUMN.0), "{msg}");
        for name in listed {
            let cols = parse_columns(Some(name)).unwrap_or_else(|e| panic!("listed '{name}' is refused: {e}"));
            assert_eq!(cols.iter().map(MapColumn::name).collect::<Vec<_>>(), [name]);
        }
        // the hint still points at the near miss
        assert!(msg.ends_with("; did you mean 'speed_rpm'?"), "{msg}");
    }

    #[test]
    fn column_memo_writes_what_the_formatter_writes() {
        // Two columns, values repeated, changed, signed zeros (equal as f64, not as text),
        // non-finite values (no text) and a repeat right after one.
        let seq = [1.5, 1.5, 2.0, 0.0, -0.0, -0.0, f64::NAN, f64::NAN, 3.25, 3.25, f64::INFINITY, 7e-9];
        let (mut memo, mut f) = (ColumnMemo::new(2), NumberFormatter::new());
        let (mut got, mut want) = (Vec::new(), Vec::new());
        for (i, &v) in seq.iter().enumerate() {
            let w = if i % 3 == 0 { 4.0 } else { v };
            for (c, x) in [v, w].into_iter().enumerate() {
                memo.push(&mut f, &mut got, c, x);
                f.push(&mut want, x);
                got.push(b',');
                want.push(b',');
            }
        }
        assert_eq!(String::from_utf8(got).expect("ascii"), String::from_utf8(want).expect("ascii"));
    }
}

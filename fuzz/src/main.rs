//! A stable-Rust fuzz driver for trum-core (no nightly, no sanitizers: cargo-fuzz needs
//! nightly; see docs/RELIABILITY.md).
//!
//! Three targets, each fed mutations of a committed seed corpus (`fuzz/corpus/<target>/`)
//! by a seeded ChaCha8 generator, so a run is reproducible from `--seed`:
//!
//! * `toml`: `Motor::from_toml_str` and `Motor::from_toml_str_with_sweep` on arbitrary
//!   bytes (lossily decoded to UTF-8, as a caller holding bytes would). Properties: no
//!   panic; an error's Display starts with the source name; both readers agree; an
//!   accepted motor validates and reads back identically from its own `to_toml()`.
//! * `csv`: `measurements::parse_measurements` on arbitrary bytes. Properties: no panic;
//!   an error's Display starts with the source name; accepted data re-reads identically
//!   from its own `to_csv_string()`.
//! * `solver`: a motor (preset plus arbitrary overrides of any dotted key with any f64,
//!   NaN and infinities included, plus effects with in- and out-of-range parameters) and
//!   an operating point (any f64). `Motor::validate` first, then a solve bounded at
//!   [`FUZZ_WORK_BOUND`] work units (the default solve, bit for bit, wherever it needs
//!   less; at most about 0.2 s of work, so one input cannot take a run's time). Properties:
//!   no panic; an invalid operating point gives `invalid_input`; for a motor that
//!   validates, a solution whose status is valid has no NaN or infinity in any quantity; a
//!   solve that spends its bound says so and is `no_convergence`.
//!
//! Every input runs under `catch_unwind` and is timed: an input slower than `--slow-ms`
//! (checked twice, to ignore scheduler noise) is a failure, one slower than `--hang-s`
//! aborts the run after writing the input to `fuzz/artifacts/`. Mutators: bit flips,
//! byte insert/delete/overwrite, splices from other corpus entries, numeric tokens
//! replaced by extremes (0, -1, 1e308, 1e400, nan, inf, 9.5, huge integers, ...),
//! dictionary tokens (keys, sections, effect names, CSV column names), line
//! duplication/deletion/swap and truncation. Inputs that reach a new outcome (error kind,
//! status, effect set) join the in-memory corpus: cheap feedback without coverage.
//!
//! ```text
//! cargo run --profile test --example trum-fuzz -- --seconds 20 --target all
//! cargo run --profile test --example trum-fuzz -- --target toml --replay fuzz/artifacts/toml-panic-0.bin
//! ```
//! Exit code 0 when no property failed, 1 when one did, 2 on a usage error, 3 on a hang.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::{BTreeMap, HashSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};
use trum_core::effects::{Effect, ALL as ALL_EFFECTS, MAX_PARAMS};
use trum_core::measurements::{parse_measurements, Measurements, COLUMNS};
use trum_core::quantities::QUANTITIES;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::{presets, Motor, OperatingPoint, Status};

const SRC_TOML: &str = "fuzz.toml";
const SRC_CSV: &str = "fuzz.csv";
/// The in-memory corpus stops growing here.
const MAX_POOL: usize = 20_000;

#[derive(Clone, Copy, PartialEq, Eq, Debug, PartialOrd, Ord)]
enum Target {
    Toml,
    Csv,
    Solver,
}

impl Target {
    const ALL: [Target; 3] = [Target::Toml, Target::Csv, Target::Solver];
    fn name(self) -> &'static str {
        match self {
            Target::Toml => "toml",
            Target::Csv => "csv",
            Target::Solver => "solver",
        }
    }
}

struct Opts {
    seconds: f64,
    targets: Vec<Target>,
    seed: u64,
    corpus: PathBuf,
    artifacts: PathBuf,
    slow_ms: f64,
    hang_s: f64,
    max_len: usize,
    replay: Option<PathBuf>,
}

fn usage() -> ! {
    eprintln!(
        "usage: trum-fuzz [--seconds S] [--target toml|csv|solver|all] [--seed N] [--corpus DIR] \
         [--artifacts DIR] [--slow-ms MS] [--hang-s S] [--max-len BYTES] [--replay FILE]"
    );
    std::process::exit(2)
}

fn parse_opts() -> Opts {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut o = Opts {
        seconds: 20.0,
        targets: Target::ALL.to_vec(),
        seed: 1,
        corpus: root.join("corpus"),
        artifacts: root.join("artifacts"),
        slow_ms: 200.0,
        hang_s: 10.0,
        max_len: 8192,
        replay: None,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let val = |i: usize| args.get(i + 1).cloned().unwrap_or_else(|| usage());
        let num =
            |i: usize| val(i).parse::<f64>().ok().filter(|v| v.is_finite() && *v >= 0.0).unwrap_or_else(|| usage());
        match args[i].as_str() {
            "--seconds" => o.seconds = num(i),
            "--seed" => o.seed = val(i).parse().unwrap_or_else(|_| usage()),
            "--corpus" => o.corpus = PathBuf::from(val(i)),
            "--artifacts" => o.artifacts = PathBuf::from(val(i)),
            "--slow-ms" => o.slow_ms = num(i),
            "--hang-s" => o.hang_s = num(i),
            "--max-len" => o.max_len = num(i) as usize,
            "--replay" => o.replay = Some(PathBuf::from(val(i))),
            "--target" => {
                o.targets = match val(i).as_str() {
                    "all" => Target::ALL.to_vec(),
                    t => vec![*Target::ALL.iter().find(|x| x.name() == t).unwrap_or_else(|| usage())],
                }
            }
            "-h" | "--help" => usage(),
            _ => usage(),
        }
        i += 2;
    }
    o
}

// ------------------------------------------------------------------ panic capture, watchdog

static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);
static EPOCH: OnceLock<Instant> = OnceLock::new();
/// Microseconds since EPOCH at which the running input started; 0 when idle.
static BUSY_SINCE_US: AtomicU64 = AtomicU64::new(0);
static CURRENT: Mutex<(String, Vec<u8>)> = Mutex::new((String::new(), Vec::new()));
static QUIET_PANICS: AtomicBool = AtomicBool::new(true);

fn now_us() -> u64 {
    EPOCH.get_or_init(Instant::now).elapsed().as_micros() as u64 + 1
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        *lock(&LAST_PANIC) = Some(info.to_string());
        if !QUIET_PANICS.load(Ordering::Relaxed) {
            eprintln!("{info}");
        }
    }));
}

fn start_watchdog(hang_s: f64, artifacts: PathBuf) {
    std::thread::spawn(move || loop {
        std::thread::sleep(Duration::from_millis(200));
        let since = BUSY_SINCE_US.load(Ordering::Relaxed);
        if since != 0 && (now_us().saturating_sub(since)) as f64 > hang_s * 1e6 {
            let cur = lock(&CURRENT);
            let path = save_artifact(&artifacts, &cur.0, "hang", &cur.1);
            eprintln!(
                "HANG: {} input running for more than {hang_s} s; saved to {}\n{}",
                cur.0,
                path.display(),
                show(&cur.1)
            );
            std::process::exit(3);
        }
    });
}

fn save_artifact(dir: &Path, target: &str, kind: &str, input: &[u8]) -> PathBuf {
    let _ = std::fs::create_dir_all(dir);
    let mut n = 0;
    loop {
        let p = dir.join(format!("{target}-{kind}-{n}.bin"));
        if !p.exists() {
            let _ = std::fs::write(&p, input);
            return p;
        }
        n += 1;
    }
}

/// An input as an escaped string, shortened for the terminal.
fn show(input: &[u8]) -> String {
    let s = format!("{:?}", String::from_utf8_lossy(input));
    if s.len() > 600 {
        let cut = (0..=600).rev().find(|&i| s.is_char_boundary(i)).unwrap_or(0);
        format!("{}… ({} bytes)", &s[..cut], input.len())
    } else {
        s
    }
}

/// Digits replaced by `#`, cut to `n` characters: one bucket per message shape.
fn shape(s: &str, n: usize) -> String {
    s.chars().map(|c| if c.is_ascii_digit() { '#' } else { c }).take(n).collect()
}

/// A coarse outcome class for corpus feedback: quoted text and numbers dropped, so
/// that a fuzzed token inside a message does not make every input "new".
fn outcome(s: &str, n: usize) -> String {
    let mut out = String::new();
    let mut quote: Option<char> = None;
    for c in s.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if matches!(c, '`' | '\'' | '"') => {
                quote = Some(c);
                out.push('_');
            }
            None if c.is_ascii_digit() || c == '.' || c == '-' => {}
            None => out.push(c),
        }
    }
    out.chars().take(n).collect()
}

/// A key as a signature: known dotted keys and sections stay, anything else is "other".
fn key_class(key: &str) -> String {
    let known = Motor::all_keys().iter().any(|k| key == format!("{}.{}", k.section, k.key) || key == k.section)
        || key.starts_with("effects.")
        || key.starts_with("sweep.")
        || key.is_empty()
        || key == "preset";
    if known && key.len() < 64 {
        key.to_string()
    } else {
        "other".into()
    }
}

// ------------------------------------------------------------------ targets

enum Verdict {
    /// Fine; the string is the outcome's signature (new signatures grow the corpus).
    Fine(String),
    /// A property failed.
    Violation(String),
}

fn check(target: Target, input: &[u8]) -> Verdict {
    match target {
        Target::Toml => check_toml(input),
        Target::Csv => check_csv(input),
        Target::Solver => check_solver(&Case::parse(input)),
    }
}

fn check_toml(input: &[u8]) -> Verdict {
    let text = String::from_utf8_lossy(input);
    let a = Motor::from_toml_str(&text, SRC_TOML);
    let b = Motor::from_toml_str_with_sweep(&text, SRC_TOML);
    // the [plausible] reader: an error names the source, like the motor reader's
    if let Err(e) = trum_core::params::plausible_from_toml_str(&text, SRC_TOML) {
        if !e.to_string().starts_with(SRC_TOML) {
            return Verdict::Violation(format!("[plausible] error does not name the source: {e}"));
        }
    }
    match (a, b) {
        (Err(e), b) => {
            let msg = e.to_string();
            if !msg.starts_with(SRC_TOML) {
                return Verdict::Violation(format!("error does not name the source: {msg}"));
            }
            match b {
                Ok(_) => return Verdict::Violation(format!("from_toml_str fails ({msg}) but with_sweep accepts")),
                Err(e2) if e2 != e => {
                    return Verdict::Violation(format!("the two readers disagree: '{msg}' vs '{e2}'"));
                }
                Err(_) => {}
            }
            Verdict::Fine(format!("err {} line={} {}", key_class(&e.key), e.line.is_some(), outcome(&e.reason, 40)))
        }
        (Ok(m), b) => {
            if let Err(e) = m.validate(SRC_TOML, None) {
                return Verdict::Violation(format!("accepted motor does not validate: {e}"));
            }
            let sweep_sig = match b {
                Ok((m2, _)) if m2 != m => return Verdict::Violation("with_sweep reads a different motor".into()),
                Ok((_, sw)) => format!(
                    "sweep {}{}{}{}",
                    sw.preload_n.is_some() as u8,
                    sw.voltage_v.is_some() as u8,
                    sw.frequency_hz.is_some() as u8,
                    sw.torque_nm.is_some() as u8
                ),
                Err(e) => {
                    let msg = e.to_string();
                    if !msg.starts_with(SRC_TOML) {
                        return Verdict::Violation(format!("sweep error does not name the source: {msg}"));
                    }
                    format!("sweep-err {} {}", key_class(&e.key), outcome(&e.reason, 30))
                }
            };
            let back = m.to_toml();
            match Motor::from_toml_str(&back, "roundtrip.toml") {
                Ok(m2) if m2 == m => {}
                Ok(m2) => {
                    return Verdict::Violation(format!(
                        "to_toml does not read back identically:\n{m:?}\nvs\n{m2:?}\ntext:\n{back}"
                    ))
                }
                Err(e) => return Verdict::Violation(format!("to_toml output does not read back: {e}\ntext:\n{back}")),
            }
            let fx: String = ALL_EFFECTS.iter().map(|e| if m.effects.is_on(*e) { '1' } else { '0' }).collect();
            Verdict::Fine(format!(
                "ok preset={:?} effects={fx} truth={} {sweep_sig}",
                m.preset,
                m.effects.truth_forms()
            ))
        }
    }
}

/// The parts of `Measurements` that `to_csv_string` writes.
fn comparable(m: &Measurements) -> Measurements {
    let mut c = m.clone();
    c.lines.clear();
    c.extra_columns.clear();
    c.warnings.clear();
    c
}

fn check_csv(input: &[u8]) -> Verdict {
    match parse_measurements(input, SRC_CSV) {
        Err(e) => {
            let msg = e.to_string();
            if !msg.starts_with(SRC_CSV) {
                return Verdict::Violation(format!("error does not name the source: {msg}"));
            }
            let kind = format!("{:?}", e.kind);
            let variant: String = kind.chars().take_while(|c| c.is_alphanumeric()).collect();
            let col = e.column.as_deref().filter(|c| COLUMNS.iter().any(|k| k.name == *c)).unwrap_or("other");
            Verdict::Fine(format!("err {variant} {col} line={}", e.line.is_some()))
        }
        Ok(m) => {
            let text = m.to_csv_string();
            match parse_measurements(text.as_bytes(), "roundtrip.csv") {
                Ok(m2) if comparable(&m2) == comparable(&m) => {}
                Ok(m2) => {
                    return Verdict::Violation(format!(
                        "to_csv_string does not read back identically:\n{m:?}\nvs\n{m2:?}\ntext:\n{text}"
                    ))
                }
                Err(e) => return Verdict::Violation(format!("to_csv_string output does not read back: {e}\n{text}")),
            }
            let cols: Vec<&str> = m.columns().iter().map(|c| c.name()).collect();
            Verdict::Fine(format!("ok {} rows>1={}", cols.join(","), m.len() > 1))
        }
    }
}

/// One solver input: preset, overrides, effects, operating point. Text form, one item a line:
/// `preset NAME`, `op PRELOAD TORQUE VOLTAGE FREQUENCY ELAPSED`, `param DOTTED VALUE`,
/// `effect NAME P0 P1`, `truth`. Values use Rust's float syntax (`NaN`, `inf`, `-inf`).
#[derive(Clone, Debug, PartialEq)]
struct Case {
    preset: String,
    op: [f64; 5],
    params: Vec<(String, f64)>,
    effects: Vec<(Effect, [f64; MAX_PARAMS])>,
    truth: bool,
}

impl Case {
    fn parse(input: &[u8]) -> Case {
        let text = String::from_utf8_lossy(input);
        let mut c = Case {
            preset: "trum60a".into(),
            op: [250.0, 0.0, 200.0, 43_000.0, 0.0],
            params: vec![],
            effects: vec![],
            truth: false,
        };
        for line in text.lines() {
            let w: Vec<&str> = line.split_whitespace().collect();
            let f = |i: usize| w.get(i).and_then(|t| t.parse::<f64>().ok()).unwrap_or(0.0);
            match w.first().copied() {
                Some("preset") if w.len() > 1 => c.preset = w[1].to_string(),
                Some("op") => {
                    for (i, slot) in c.op.iter_mut().enumerate() {
                        *slot = f(i + 1);
                    }
                }
                Some("param") if w.len() > 2 => c.params.push((w[1].to_string(), f(2))),
                Some("effect") if w.len() > 1 => {
                    if let Ok(e) = Effect::from_name(w[1]) {
                        c.effects.push((e, std::array::from_fn(|i| f(i + 2))));
                    }
                }
                Some("truth") => c.truth = true,
                _ => {}
            }
        }
        c
    }

    fn to_text(&self) -> String {
        let mut s = format!(
            "preset {}\nop {:?} {:?} {:?} {:?} {:?}\n",
            self.preset, self.op[0], self.op[1], self.op[2], self.op[3], self.op[4]
        );
        for (k, v) in &self.params {
            s.push_str(&format!("param {k} {v:?}\n"));
        }
        for (e, v) in &self.effects {
            let vals: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
            s.push_str(&format!("effect {} {}\n", e.name(), vals.join(" ")));
        }
        if self.truth {
            s.push_str("truth\n");
        }
        s
    }

    fn motor(&self) -> Motor {
        let mut m = presets::preset(&self.preset).unwrap_or_else(|_| presets::PRESETS[0].motor());
        for (k, v) in &self.params {
            if let Some(slot) = m.param_mut(k) {
                *slot = *v;
            }
        }
        for (e, v) in &self.effects {
            m.effects.set(*e, &v[..e.info().params.len()]);
        }
        m.effects.set_truth_forms(self.truth);
        m
    }
}

/// The work bound of each solve [interface-integrand evaluations; trum_core's
/// `solve::WORK_BOUND` is 10⁹], as in the coverage-guided solver target.
const FUZZ_WORK_BOUND: u64 = 2_000_000;

fn check_solver(c: &Case) -> Verdict {
    let m = c.motor();
    let motor_ok = m.validate("fuzz", None).is_ok();
    let op = OperatingPoint {
        preload_n: c.op[0],
        torque_nm: c.op[1],
        voltage_v: c.op[2],
        frequency_hz: c.op[3],
        elapsed_s: c.op[4],
    };
    let op_ok = op.invalid_reason().is_none();
    let s = solve_prepared(&Prepared::new(&m).with_work_bound(FUZZ_WORK_BOUND), &m, &op, None);
    if s.work_bound_reached && s.status != Status::NoConvergence {
        return Verdict::Violation(format!("a solve that spent its work bound has status {} at {op:?}", s.status));
    }
    if !op_ok && s.status != Status::InvalidInput {
        return Verdict::Violation(format!("invalid operating point {op:?} gives status {}", s.status));
    }
    let bad: Vec<String> = QUANTITIES
        .iter()
        .map(|q| (q.name, (q.get)(&s)))
        .chain([("torque_nm", s.torque_nm), ("axial_force_n", s.axial_force_n)])
        .filter(|(_, v)| !v.is_finite())
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    if motor_ok && s.status.is_valid() && !bad.is_empty() {
        return Verdict::Violation(format!("status {} with non-finite quantities: {}", s.status, bad.join(", ")));
    }
    let fx: String = ALL_EFFECTS.iter().map(|e| if m.effects.is_on(*e) { '1' } else { '0' }).collect();
    let nonfinite = if !motor_ok && s.status.is_valid() && !bad.is_empty() { " unvalidated-nonfinite" } else { "" };
    Verdict::Fine(format!("motor_ok={motor_ok} op_ok={op_ok} {} fx={fx} truth={}{nonfinite}", s.status, c.truth))
}

// ------------------------------------------------------------------ mutation

/// Replacements for numeric tokens and values: zero, signs, extremes, non-finite, not
/// an integer, not representable, and spellings that are not plain decimals.
const EXTREME_TOKENS: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "-1",
    "1",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e400",
    "-1e400",
    "nan",
    "-nan",
    "+nan",
    "inf",
    "-inf",
    "+inf",
    "NaN",
    "Infinity",
    "9.5",
    "0.5",
    "1e-320",
    "5e-324",
    "2.2250738585072014e-308",
    "18446744073709551616",
    "9223372036854775807",
    "-9223372036854775808",
    "99999999999999999999999999",
    "1_000",
    "0x1F",
    "0o17",
    "0b11",
    "1e",
    "1.",
    ".5",
    "-.5",
    "1,5",
    "1e6",
    "1e12",
    "1000000",
    "1000001",
    "3.0e-5",
    "2000-01-01",
    "true",
    "\"12\"",
    "[1, 2, 3]",
    "[1, 2]",
    "[0, 1e12, 1e12]",
    "{ a = 1 }",
];

const EXTREME_VALUES: &[f64] = &[
    0.0,
    -0.0,
    -1.0,
    1.0,
    1e308,
    -1e308,
    f64::MAX,
    f64::MIN_POSITIVE,
    5e-324,
    1e-300,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    9.5,
    0.5,
    1e6,
    1e12,
    1e-12,
    9.223372036854776e18,
    1.8446744073709552e19,
];

fn dictionary(target: Target) -> Vec<Vec<u8>> {
    let mut d: Vec<String> = Vec::new();
    match target {
        Target::Toml => {
            for k in Motor::all_keys() {
                d.push(format!("[{}]\n", k.section));
                d.push(format!("{} = 1\n", k.key));
                d.push(format!("{}.{} = 2.5\n", k.section, k.key));
            }
            for e in ALL_EFFECTS {
                d.push(format!("{} = 1\n", e.name()));
                d.push(format!("[effects.{}]\n", e.name()));
                for p in e.info().params {
                    d.push(format!("{} = {}\n", p.name, p.typical));
                }
            }
            for s in [
                "[effects]\n",
                "[sweep]\n",
                "[nonsense]\n",
                "preset = \"trum60a\"\n",
                "preset = \"generic60\"\n",
                "preset = \"nope\"\n",
                "name = \"x\"\n",
                "form = \"truth\"\n",
                "form = \"candidate\"\n",
                "preload_n = [100, 500, 9]\n",
                "torque_nm = [0, 1, 1e12]\n",
                "voltage_v = 200\n",
                "frequency_hz = [1, 2, 0.5]\n",
                "radial_friction = { radial_velocity_ratio = 1 }\n",
                "hertz_softening = { beta_n_per_m3 = 1e18, preload_gain_per_n = 0.004 }\n",
                "\"",
                "'",
                "'''",
                "\"\"\"",
                "[[",
                "]]",
                "[",
                "]",
                "{",
                "}",
                "=",
                ",",
                ".",
                "#",
                "\\u0000",
                "\\",
                "\u{7f}",
                "\u{feff}",
                "\r\n",
                "\r",
                "\t",
                "\u{0}",
                "\u{2028}",
                "é",
                "\u{10ffff}",
            ] {
                d.push(s.into());
            }
        }
        Target::Csv => {
            for c in COLUMNS.iter() {
                d.push(c.name.into());
                d.push(format!(",{}", c.name));
                d.push(format!("{}\n", c.name));
            }
            for s in [
                ",",
                "\"",
                "\"\"",
                "\r",
                "\r\n",
                "\n",
                "\n\n",
                "\u{feff}",
                ";",
                "\t",
                " ",
                "run_id",
                "Preload_N",
                "torque_mnm",
                "speed_rad_s",
                "efficiency_percent",
                "nan",
                "inf",
                "1e400",
                "-0",
                "0x10",
                "1,5",
                "é",
                "\u{0}",
                "\u{7f}",
                "\u{2028}",
                "a\"b",
                "\"a,b\"",
                "\"  x  \"",
            ] {
                d.push(s.into());
            }
        }
        Target::Solver => {}
    }
    d.into_iter().map(String::into_bytes).collect()
}

fn is_num_byte(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'+' | b'-' | b'_')
}

/// Byte ranges of numeric-looking tokens (runs of digits, signs, dots, exponents that
/// contain a digit).
fn numeric_tokens(data: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if is_num_byte(data[i]) {
            let j = (i..data.len()).find(|&j| !is_num_byte(data[j])).unwrap_or(data.len());
            if data[i..j].iter().any(u8::is_ascii_digit) {
                out.push((i, j));
            }
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn line_starts(data: &[u8]) -> Vec<usize> {
    std::iter::once(0).chain(data.iter().enumerate().filter(|(_, &b)| b == b'\n').map(|(i, _)| i + 1)).collect()
}

fn mutate_bytes(data: &mut Vec<u8>, rng: &mut ChaCha8Rng, pool: &[Vec<u8>], dict: &[Vec<u8>], max_len: usize) {
    let rounds = 1 + (rng.random_range(0..16u32)).trailing_zeros().min(6) as usize + rng.random_range(0..2usize);
    for _ in 0..rounds {
        let len = data.len();
        match rng.random_range(0..12u32) {
            0 if len > 0 => {
                let i = rng.random_range(0..len);
                data[i] ^= 1 << rng.random_range(0..8u32);
            }
            1 => {
                let i = rng.random_range(0..=len);
                let b = if rng.random_bool(0.5) {
                    rng.random::<u8>()
                } else {
                    *pick(rng, b"[]=\"',.#{}\n\r\t \\0123456789-+eE\x7f\xff\xc3\xa9")
                };
                data.insert(i, b);
            }
            2 if len > 0 => {
                let i = rng.random_range(0..len);
                let n = rng.random_range(1..=16usize).min(len - i);
                data.drain(i..i + n);
            }
            3 => {
                let other = pick(rng, pool);
                if !other.is_empty() {
                    let a = rng.random_range(0..other.len());
                    let b = rng.random_range(a..=other.len().min(a + 256));
                    let at = rng.random_range(0..=len);
                    if rng.random_bool(0.5) {
                        data.splice(at..at, other[a..b].iter().copied());
                    } else {
                        let end = (at + (b - a)).min(len);
                        data.splice(at..end, other[a..b].iter().copied());
                    }
                }
            }
            4..=6 => {
                let toks = numeric_tokens(data);
                if let Some(&(a, b)) = (!toks.is_empty()).then(|| pick(rng, &toks)) {
                    let rep: Vec<u8> = if rng.random_bool(0.8) {
                        pick(rng, EXTREME_TOKENS).as_bytes().to_vec()
                    } else {
                        let v: f64 = std::str::from_utf8(&data[a..b]).ok().and_then(|t| t.parse().ok()).unwrap_or(1.0);
                        format!("{:?}", v * 10f64.powf(rng.random_range(-3.0..3.0))).into_bytes()
                    };
                    data.splice(a..b, rep);
                }
            }
            7 | 8 if !dict.is_empty() => {
                let tok = pick(rng, dict).clone();
                let at = if rng.random_bool(0.5) { *pick(rng, &line_starts(data)) } else { rng.random_range(0..=len) };
                data.splice(at..at, tok);
            }
            9 => {
                let ls = line_starts(data);
                let k = rng.random_range(0..ls.len());
                let (a, b) = (ls[k], ls.get(k + 1).copied().unwrap_or(len));
                match rng.random_range(0..3u32) {
                    0 => {
                        let line = data[a..b].to_vec();
                        data.splice(b..b, line);
                    }
                    1 => {
                        data.drain(a..b);
                    }
                    _ => {
                        let j = rng.random_range(0..ls.len());
                        let (c, d) = (ls[j], ls.get(j + 1).copied().unwrap_or(len));
                        if d <= a {
                            let (x, y) = (data[c..d].to_vec(), data[a..b].to_vec());
                            data.splice(a..b, x);
                            data.splice(c..d, y);
                        }
                    }
                }
            }
            10 if len > 0 => data.truncate(rng.random_range(0..len)),
            11 if len > 0 => {
                let i = rng.random_range(0..len);
                data[i] = *pick(rng, b"\x00\x7f\x80\xbf\xc0\xff\xfe\"'=[]\n\r,");
            }
            _ => {}
        }
    }
    data.truncate(max_len);
}

fn pick<'a, T>(rng: &mut ChaCha8Rng, v: &'a [T]) -> &'a T {
    &v[rng.random_range(0..v.len())]
}

fn new_value(rng: &mut ChaCha8Rng, cur: f64) -> f64 {
    let cur = if cur.is_finite() && cur != 0.0 { cur } else { 1.0 };
    match rng.random_range(0..7u32) {
        0 => *pick(rng, EXTREME_VALUES),
        1 | 2 => cur * rng.random_range(0.5..2.0),
        3 => cur * 10f64.powf(rng.random_range(-6.0..6.0)),
        4 => -cur,
        5 => cur * (1.0 + f64::EPSILON * rng.random_range(-4.0..4.0)),
        _ => 10f64.powf(rng.random_range(-12.0..12.0)),
    }
}

fn mutate_case(c: &mut Case, rng: &mut ChaCha8Rng) {
    let rounds = rng.random_range(1..=3u32);
    for _ in 0..rounds {
        match rng.random_range(0..11u32) {
            0..=2 => {
                let i = rng.random_range(0..5usize);
                c.op[i] = if i == 1 && rng.random_bool(0.2) { 0.0 } else { new_value(rng, c.op[i]) };
            }
            3..=5 => {
                let keys = Motor::all_keys();
                let k = pick(rng, &keys);
                let dotted = format!("{}.{}", k.section, k.key);
                let base = c.motor().param(&dotted).unwrap_or(1.0);
                let v = if dotted == "geometry.wave_number" && rng.random_bool(0.5) {
                    *pick(rng, &[0.0, 1.0, 2.0, 9.0, 9.5, 40.0, 1e6, 1e7])
                } else {
                    new_value(rng, base)
                };
                c.params.retain(|(d, _)| *d != dotted);
                c.params.push((dotted, v));
            }
            6 | 7 => {
                let e = *pick(rng, &ALL_EFFECTS);
                let mut v = [0.0; MAX_PARAMS];
                for (slot, p) in v.iter_mut().zip(e.info().params) {
                    *slot = if rng.random_bool(0.8) {
                        if rng.random_bool(0.2) {
                            *pick(rng, &[p.min, p.max, p.typical])
                        } else {
                            rng.random_range(p.min..=p.max)
                        }
                    } else {
                        new_value(rng, p.typical)
                    };
                }
                c.effects.retain(|(x, _)| *x != e);
                c.effects.push((e, v));
            }
            8 => {
                if !c.params.is_empty() && rng.random_bool(0.5) {
                    let i = rng.random_range(0..c.params.len());
                    c.params.remove(i);
                } else if !c.effects.is_empty() {
                    let i = rng.random_range(0..c.effects.len());
                    c.effects.remove(i);
                }
            }
            9 => c.truth = !c.truth,
            _ => c.preset = pick(rng, presets::PRESETS).name.to_string(),
        }
    }
}

// ------------------------------------------------------------------ the loop

#[derive(Default)]
struct Stats {
    execs: u64,
    seeds: usize,
    signatures: HashSet<String>,
    slowest: Duration,
    slowest_input: Vec<u8>,
    /// failure bucket -> (count, first input, message)
    failures: BTreeMap<String, (u64, Vec<u8>, String)>,
    counters: BTreeMap<String, u64>,
}

fn run_input(target: Target, input: &[u8]) -> (Result<Verdict, String>, Duration) {
    {
        let mut cur = lock(&CURRENT);
        cur.0.clear();
        cur.0.push_str(target.name());
        cur.1.clear();
        cur.1.extend_from_slice(input);
    }
    BUSY_SINCE_US.store(now_us(), Ordering::Relaxed);
    let t0 = Instant::now();
    let r = catch_unwind(AssertUnwindSafe(|| check(target, input)));
    let dt = t0.elapsed();
    BUSY_SINCE_US.store(0, Ordering::Relaxed);
    let r = r.map_err(|_| lock(&LAST_PANIC).take().unwrap_or_else(|| "panic (no message)".into()));
    (r, dt)
}

fn execute(target: Target, input: &[u8], o: &Opts, st: &mut Stats, pool: &mut Vec<Vec<u8>>) {
    let (r, mut dt) = run_input(target, input);
    st.execs += 1;
    let limit = Duration::from_secs_f64(o.slow_ms / 1e3);
    if dt > limit {
        // once more: a slow run on a busy machine is not a slow input
        let (_, dt2) = run_input(target, input);
        st.execs += 1;
        dt = dt.min(dt2);
        if dt > limit {
            fail(
                st,
                target,
                o,
                format!("slow: over {} ms", o.slow_ms),
                format!("took {:.1} ms", dt.as_secs_f64() * 1e3),
                input,
            );
        }
    }
    if dt > st.slowest {
        st.slowest = dt;
        st.slowest_input = input.to_vec();
    }
    match r {
        Ok(Verdict::Fine(sig)) => {
            if sig.contains("unvalidated-nonfinite") {
                *st.counters.entry("valid status with non-finite numbers for a motor that fails validate (not a failure: solve() is documented for validated motors)".into()).or_default() += 1;
            }
            if !st.signatures.contains(&sig) {
                st.signatures.insert(sig);
                // slow inputs are not bred from: they would eat the time budget
                if pool.len() < MAX_POOL && dt < limit / 4 {
                    pool.push(input.to_vec());
                }
            }
        }
        Ok(Verdict::Violation(msg)) => fail(st, target, o, format!("property: {}", shape(&msg, 70)), msg, input),
        Err(msg) => {
            let loc = msg.lines().next().unwrap_or("").to_string();
            fail(st, target, o, format!("panic: {}", shape(&loc, 120)), msg, input)
        }
    }
}

fn fail(st: &mut Stats, target: Target, o: &Opts, bucket: String, msg: String, input: &[u8]) {
    let e = st.failures.entry(bucket).or_insert_with(|| (0, Vec::new(), String::new()));
    if e.0 == 0 {
        e.1 = input.to_vec();
        e.2 = msg;
        let kind = if e.2.starts_with("took") { "slow" } else { "fail" };
        let p = save_artifact(&o.artifacts, target.name(), kind, input);
        eprintln!("[{}] failure saved to {}: {}", target.name(), p.display(), e.2.lines().next().unwrap_or(""));
    }
    e.0 += 1;
}

fn load_corpus(dir: &Path) -> Vec<Vec<u8>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.flatten().map(|e| e.path()).filter(|p| p.is_file()).collect())
        .unwrap_or_default();
    files.sort();
    files.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

fn fuzz_target(target: Target, o: &Opts) -> Stats {
    let mut rng = ChaCha8Rng::seed_from_u64(o.seed ^ ((target as u64 + 1) << 32));
    let mut pool = load_corpus(&o.corpus.join(target.name()));
    let mut st = Stats { seeds: pool.len(), ..Stats::default() };
    if pool.is_empty() {
        pool.push(Vec::new());
    }
    let dict = dictionary(target);
    let deadline = Instant::now() + Duration::from_secs_f64(o.seconds);
    // every seed once as it is
    for i in 0..pool.len() {
        let input = pool[i].clone();
        execute(target, &input, o, &mut st, &mut pool);
    }
    while Instant::now() < deadline {
        let mut input = pick(&mut rng, &pool).clone();
        if target == Target::Solver {
            let mut c = Case::parse(&input);
            mutate_case(&mut c, &mut rng);
            input = c.to_text().into_bytes();
        } else {
            mutate_bytes(&mut input, &mut rng, &pool, &dict, o.max_len);
        }
        execute(target, &input, o, &mut st, &mut pool);
    }
    let grown = pool.len();
    println!(
        "{:<6} {:>9} execs in {:>5.1} s ({:>7.0}/s)  corpus {} seeds -> {} entries, {} outcomes  slowest {:.2} ms  failures {}",
        target.name(),
        st.execs,
        o.seconds,
        st.execs as f64 / o.seconds.max(1e-9),
        st.seeds,
        grown,
        st.signatures.len(),
        st.slowest.as_secs_f64() * 1e3,
        st.failures.values().map(|f| f.0).sum::<u64>(),
    );
    st
}

fn main() {
    let o = parse_opts();
    EPOCH.get_or_init(Instant::now);
    install_panic_hook();
    start_watchdog(o.hang_s, o.artifacts.clone());
    if let Some(path) = &o.replay {
        let input = std::fs::read(path).unwrap_or_else(|e| {
            eprintln!("cannot read {}: {e}", path.display());
            std::process::exit(2)
        });
        let mut code = 0;
        for &t in &o.targets {
            let (r, dt) = run_input(t, &input);
            let what = match r {
                Ok(Verdict::Fine(sig)) => format!("fine ({sig})"),
                Ok(Verdict::Violation(m)) => {
                    code = 1;
                    format!("PROPERTY FAILED: {m}")
                }
                Err(m) => {
                    code = 1;
                    format!("PANIC: {m}")
                }
            };
            println!("{}: {:.3} ms: {what}", t.name(), dt.as_secs_f64() * 1e3);
        }
        std::process::exit(code);
    }
    println!("trum-fuzz: seed {}, {} s per target, slow limit {} ms", o.seed, o.seconds, o.slow_ms);
    let mut failed = false;
    for &t in &o.targets {
        let st = fuzz_target(t, &o);
        println!("       slowest input ({:.2} ms): {}", st.slowest.as_secs_f64() * 1e3, show(&st.slowest_input));
        for (what, n) in &st.counters {
            println!("       note: {n} x {what}");
        }
        for (bucket, (n, input, msg)) in &st.failures {
            failed = true;
            println!(
                "  FAIL [{}] {n} x {bucket}\n       {}\n       input: {}",
                t.name(),
                msg.replace('\n', "\n       "),
                show(input)
            );
        }
    }
    std::process::exit(if failed { 1 } else { 0 });
}

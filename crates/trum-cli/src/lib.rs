//! The `trum` command-line tool as a library, so tests can run it in-process.
//!
//! Errors use `anyhow` in this layer only; messages from trum-core (which already name
//! the file, line and key) are shown unchanged. Exit codes: 0 success, 1 bad input or a
//! failed run, 2 usage errors (clap), 101 an internal error (a panic, which is a bug).

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::Write;

mod args;
mod calib;
mod data;
mod diagnose;
mod estimate;
mod fleet;
mod format;
mod grid;
mod info;
mod map;
mod motor;
mod optimize;
mod output;
mod plot;
mod point;
mod report;
mod resonance;
mod step;
mod suggest;
mod svg;
mod synth;
mod table;
mod verdict;

pub use grid::parse_axis;

/// Simulate, map and optimise traveling-wave rotary ultrasonic motors (SI units throughout).
#[derive(Parser, Debug)]
#[command(name = "trum", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Solve one operating point and print every quantity with its unit.
    #[command(allow_negative_numbers = true)]
    Point(point::PointArgs),
    /// Solve a grid of operating points and write a CSV map (streamed, parallel).
    #[command(allow_negative_numbers = true)]
    Map(map::MapArgs),
    /// Evaluate the preload optimisation criterion (Chen et al. 2020, section 5).
    #[command(allow_negative_numbers = true)]
    Optimize(optimize::OptimizeArgs),
    /// List the built-in motor presets, or print one as a motor file.
    Presets(info::PresetsArgs),
    /// List the switchable unmodelled effects and their parameters.
    Effects(info::EffectsArgs),
    /// Plot curves or heat maps from a motor or from a map CSV (.png or .svg).
    #[command(allow_negative_numbers = true)]
    Plot(plot::PlotArgs),
    /// Simulate a bench measurement campaign (with known effects) and write it as a measurement CSV.
    #[command(allow_negative_numbers = true)]
    Synth(synth::SynthArgs),
    /// Calibrate the uncertain motor parameters to a measurement CSV; write the calibrated motor file.
    Calibrate(calib::CalibrateArgs),
    /// Estimate contact state, losses and efficiency per measurement row from the measured preload and feedback voltage (Sun et al. 2021).
    Estimate(estimate::EstimateArgs),
    /// Diagnose the sim-to-real gap: where the model misses, which effect causes it, how far it shrinks.
    Diagnose(diagnose::DiagnoseArgs),
    /// Nonlinear (Hertzian) resonance curves: every branch, backbone and jump frequencies vs voltage and preload ([Hertz2022]: docs/REFERENCES.md).
    #[command(allow_negative_numbers = true)]
    Resonance(resonance::ResonanceArgs),
    /// Identify the cubic coefficient beta from a sampled waveform by harmonic balance ([Hertz2022] eq. 5-9).
    #[command(name = "identify-hertz", allow_negative_numbers = true)]
    IdentifyHertz(resonance::IdentifyArgs),
    /// Step response of the rotor speed with stick-slip contact ([BarTransient]: docs/REFERENCES.md); metrics vs the steady solver.
    #[command(allow_negative_numbers = true)]
    Step(step::StepArgs),
    /// Print a shell completion script (`trum completions bash > ~/.local/share/bash-completion/completions/trum`).
    Completions {
        /// The shell: bash, zsh, fish, elvish or powershell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
}

/// Runs the CLI with the given arguments (the first is the program name) and returns
/// the process exit code. Output goes to the process's stdout and stderr.
pub fn main_with_args<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    output::signals::install();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    // Not stderr's lock for the whole run: a worker thread that writes to stderr (the panic
    // hook of a bug in a rayon task) would wait for it forever while this thread waits for
    // the worker, and the run would hang instead of ending with exit code 101. Stderr is
    // unbuffered; each write takes the lock.
    let mut err = std::io::stderr();
    run_with_io(args, &mut out, &mut err)
}

/// Like [`main_with_args`], writing to the given streams (tests capture them this way).
/// Progress bars, when shown, still go to the terminal's stderr.
pub fn run_with_io<I, T>(args: I, out: &mut dyn Write, err: &mut dyn Write) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // --help and --version are "errors" with exit code 0 that belong on stdout.
            let text = e.render().to_string();
            let _ = if e.use_stderr() { write!(err, "{text}") } else { write!(out, "{text}") };
            return e.exit_code();
        }
    };
    output::reset_inputs();
    // Last resort: nothing should panic, but a bug must not print a backtrace at the user.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(cli, out, err)));
    match result {
        Ok(Ok(code)) => {
            let _ = out.flush();
            code
        }
        Ok(Err(e)) => {
            if is_broken_pipe(&e) {
                // `trum map -o - | head`: the reader went away; that is not an error.
                return 0;
            }
            let _ = out.flush();
            let _ = writeln!(err, "error: {e:#}");
            1
        }
        Err(_) => {
            let _ = writeln!(err, "error: internal error (a bug in trum; please report it with the command line)");
            101
        }
    }
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe))
}

fn run(cli: Cli, out: &mut dyn Write, err: &mut dyn Write) -> anyhow::Result<i32> {
    match cli.command {
        Command::Point(a) => point::run(&a, out, err),
        Command::Map(a) => map::run(&a, out, err),
        Command::Optimize(a) => optimize::run(&a, out, err),
        Command::Presets(a) => info::presets(&a, out),
        Command::Effects(a) => info::effects(&a, out),
        Command::Plot(a) => plot::run(&a, err),
        Command::Synth(a) => synth::run(&a, out, err),
        Command::Calibrate(a) => calib::run(&a, out, err),
        Command::Diagnose(a) => diagnose::run(&a, out, err),
        Command::Estimate(a) => estimate::run(&a, out, err),
        Command::Resonance(a) => resonance::run(&a, out, err),
        Command::IdentifyHertz(a) => resonance::identify(&a, out),
        Command::Step(a) => step::run(&a, out, err),
        Command::Completions { shell } => {
            use clap::CommandFactory;
            let mut buf = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "trum", &mut buf);
            out.write_all(&buf)?;
            Ok(0)
        }
    }
}

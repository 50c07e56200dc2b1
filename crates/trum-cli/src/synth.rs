//! `trum synth`: a synthetic bench campaign with known effects, written as a measurement
//! file (layout: docs/MEASUREMENTS.md) for `trum calibrate` and `trum diagnose`.

use crate::args::MotorArgs;
use crate::data::write_atomic;
use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};
use std::io::Write;
use std::path::PathBuf;
use trum_core::bench::to_measurements;
use trum_core::calibrate::Observable;
use trum_core::synth::{synthesize, Artefacts, Campaign, SynthConfig};

/// Campaign kinds (the names of `trum_core::synth::Campaign::NAMES`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CampaignArg {
    /// Preloads 100-400 N in 50 N steps × load torque from zero to 90 % of stall (56 rows).
    PreloadTorque,
    /// No-load frequency sweeps ±1.5 kHz at 0.75, 1 and 1.25 × the voltage, 250 N (45 rows).
    FrequencySweep,
    /// A 10 min warm-up time series at 250 N, 0.3 N·m, 20 s samples, with temperatures (31 rows).
    WarmUp,
    /// Speed stability (speed_std_rpm) at no load, preloads 150-500 N (8 rows).
    Stability,
    /// All four together.
    Combined,
}

impl CampaignArg {
    fn campaign(self) -> Result<Campaign> {
        let name = self.to_possible_value().map(|v| v.get_name().to_string()).unwrap_or_default();
        Campaign::from_name(&name).map_err(|e| anyhow!("{e}"))
    }
}

#[derive(Args, Debug)]
pub struct SynthArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Measurement campaign to simulate.
    #[arg(long, value_enum)]
    campaign: CampaignArg,
    /// Noise level: 0 = exact readings, 1 = the nominal bench noise (docs/SYNTH.md).
    #[arg(long, value_name = "LEVEL")]
    noise: f64,
    /// Random seed (the same seed gives the same file, byte for byte).
    #[arg(long, value_name = "N")]
    seed: u64,
    /// Seed of the true motor's parameter perturbation (default: `--seed`). Give several
    /// campaigns the same motor seed and different seeds to simulate one motor measured
    /// in several runs; different motor seeds are different motors of one design.
    #[arg(long, value_name = "N")]
    motor_seed: Option<u64>,
    /// Relative standard deviation of the perturbation of the uncertain motor parameters
    /// (what calibration must absorb).
    #[arg(long, default_value_t = 0.03, value_name = "REL")]
    perturbation: f64,
    /// Drive voltage amplitude of the fixed-drive runs, zero-to-peak per phase [V]
    /// (default: the motor's [drive], else 200).
    #[arg(long, allow_hyphen_values = true)]
    voltage_v: Option<f64>,
    /// Drive frequency of the fixed-drive runs [Hz] (default: the motor's [drive], else 43000).
    #[arg(long, allow_hyphen_values = true)]
    frequency_hz: Option<f64>,
    /// Simulate the effects in their candidate forms (the forms the diagnosis fits). By
    /// default effects use their truth forms, which differ in form from the candidates, as
    /// a real motor would.
    #[arg(long)]
    candidate_forms: bool,
    /// Simulate the effects in their second family of truth forms (docs/EFFECTS.md), which
    /// differ from the first and from every candidate.
    #[arg(long, conflicts_with = "candidate_forms")]
    truth_forms_b: bool,
    /// Optional columns to leave out, comma-separated (to mimic a poorer bench), e.g. feedback_v,current_a.
    #[arg(long, value_name = "col1,col2")]
    omit: Option<String>,
    /// Bench artefacts besides the reading noise, as `name=value,...` (docs/SYNTH.md):
    /// readback_rel (voltage read back around its set point), speed_std_floor_rpm,
    /// torque_offset_nm, speed_quantum_rpm, outlier_fraction, temperature_offset_k,
    /// temperature_lag_s, preload_offset_n, current_gain_rel, power_phase_rad.
    #[arg(long, value_name = "name=value,...")]
    artefacts: Option<String>,
    /// Output CSV file (`-` for stdout). Written to a temporary file and renamed at the end.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
}

/// Parses `--omit`: optional measured columns only.
pub fn parse_omit(spec: Option<&str>) -> Result<Vec<Observable>> {
    let Some(spec) = spec else { return Ok(Vec::new()) };
    let optional: Vec<&str> =
        Observable::ALL.iter().filter(|o| **o != Observable::SpeedRpm).map(|o| o.column()).collect();
    let mut v = Vec::new();
    for name in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        if name == "speed_rpm" {
            bail!("--omit: speed_rpm is a required column and cannot be left out");
        }
        let o = Observable::ALL.into_iter().find(|o| o.column() == name).ok_or_else(|| {
            anyhow!("--omit: '{name}' is not an optional measured column; valid columns are: {}", optional.join(", "))
        })?;
        if !v.contains(&o) {
            v.push(o);
        }
    }
    Ok(v)
}

/// The fixed drive of the campaign, voltage [V] and frequency [Hz]: each given option,
/// else the motor's `[drive]` (as `trum point`, `trum map` and `trum step` take it), else
/// the core's [`SynthConfig`] default (200 V, 43 kHz), so that a motor without a `[drive]`
/// gives the same file as the core's own synthesis.
fn drive(a: &SynthArgs) -> Result<(f64, f64)> {
    let own = crate::optimize::motor_drive(&a.motor.motor)?;
    let core = SynthConfig::default();
    Ok((
        a.voltage_v.or(own.map(|d| d.voltage_v)).unwrap_or(core.voltage_v),
        a.frequency_hz.or(own.map(|d| d.frequency_hz)).unwrap_or(core.frequency_hz),
    ))
}

pub fn run(a: &SynthArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let (motor, _) = a.motor.load()?;
    // The motor file's (or preset's) own effects are part of the nominal model a diagnosis
    // of these data starts from: they keep their candidate forms; only what --effect adds
    // or changes takes a truth form.
    let own = crate::motor::load_motor(&a.motor.motor)?.0.effects;
    let (voltage_v, frequency_hz) = drive(a)?;
    for (flag, v) in [("--voltage-v", voltage_v), ("--frequency-hz", frequency_hz)] {
        if !(v.is_finite() && v > 0.0) {
            bail!("{flag} {v} must be a finite number > 0");
        }
    }
    let cfg = SynthConfig {
        campaign: a.campaign.campaign()?,
        noise: a.noise,
        seed: a.seed,
        motor_seed: a.motor_seed,
        perturbation: a.perturbation,
        voltage_v,
        frequency_hz,
        truth_forms: !a.candidate_forms,
        truth_form_b: a.truth_forms_b,
        nominal_effects: own,
        omit: parse_omit(a.omit.as_deref())?,
        artefacts: Artefacts::parse(a.artefacts.as_deref().unwrap_or("")).map_err(|e| anyhow!("--artefacts: {e}"))?,
    };
    let rows = synthesize(&motor, &cfg).map_err(|e| anyhow!("{e}"))?;
    if rows.is_empty() {
        bail!("the motor has no valid steady state at any point of this campaign; nothing to write");
    }
    let m = to_measurements(&rows).map_err(|e| anyhow!("{e}"))?;
    write_atomic(&a.output, ".csv", &m.to_csv_string(), out)?;
    if a.output.as_os_str() != "-" {
        let truth = trum_core::synth::true_motor(&motor, &cfg).effects;
        let forms = |truth_form: bool| {
            let names: Vec<&str> = motor
                .effects
                .active()
                .into_iter()
                .filter(|&e| truth.is_truth_form(e) == truth_form)
                .map(|e| e.name())
                .collect();
            names.join(", ")
        };
        let forms = match (forms(true), forms(false)) {
            (t, c) if t.is_empty() && c.is_empty() => String::new(),
            (t, c) if t.is_empty() => format!(" (candidate forms: {c})"),
            (t, c) if c.is_empty() => format!(" ({} forms: {t})", if a.truth_forms_b { "truth-b" } else { "truth" }),
            (t, c) => {
                format!(" ({} forms: {t}; candidate forms: {c})", if a.truth_forms_b { "truth-b" } else { "truth" })
            }
        };
        writeln!(
            err,
            "wrote {} rows to '{}': campaign {} at {} V, {} Hz, noise {}, seed {}{}, effects {}{forms}",
            rows.len(),
            a.output.display(),
            a.campaign.to_possible_value().map(|v| v.get_name().to_string()).unwrap_or_default(),
            crate::format::fmt_sig(voltage_v, 6),
            crate::format::fmt_sig(frequency_hz, 6),
            a.noise,
            a.seed,
            a.motor_seed.filter(|&m| m != a.seed).map(|m| format!(" (motor seed {m})")).unwrap_or_default(),
            motor.effects,
        )?;
    }
    Ok(0)
}

//! `trum synth`: bench data with known effects. Generates measurement campaigns like a
//! real test bench (seed 000 section 3-4, seed 001 section 3): the "true" motor is the
//! nominal one with its uncertain parameters perturbed (so calibration has something to
//! absorb) and the chosen effects switched on — by default in their **truth forms**,
//! which differ in form from the candidates the diagnosis fits — and every reading gets
//! realistic noise. Reproducible from the seed.

use crate::calibrate::{Observable, ObservedRow};
use crate::error::TrumError;
use crate::params::Motor;
use crate::solve::{solve_prepared, OperatingPoint, Prepared, Status};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Kinds of measurement campaign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Campaign {
    /// Preload grid (100-400 N, 50 N steps) × load torque from zero to near stall, fixed drive.
    PreloadTorque,
    /// No-load frequency sweeps at three voltages, fixed preload.
    FrequencySweep,
    /// Warm-up time series at constant drive (10 min, 20 s samples) with temperatures.
    WarmUp,
    /// Speed stability (speed standard deviation) at no load over a preload grid.
    Stability,
    /// All of the above.
    Combined,
}

impl Campaign {
    /// Names accepted on the command line.
    pub const NAMES: [&'static str; 5] = ["preload-torque", "frequency-sweep", "warm-up", "stability", "combined"];

    /// Parses a campaign name; the error lists the valid names.
    pub fn from_name(s: &str) -> Result<Campaign, TrumError> {
        Ok(match s {
            "preload-torque" => Campaign::PreloadTorque,
            "frequency-sweep" => Campaign::FrequencySweep,
            "warm-up" => Campaign::WarmUp,
            "stability" => Campaign::Stability,
            "combined" => Campaign::Combined,
            _ => {
                return Err(TrumError::input(format!(
                    "unknown campaign '{s}'; valid campaigns are: {}",
                    Campaign::NAMES.join(", ")
                )))
            }
        })
    }
}

/// Settings of a synthetic campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthConfig {
    /// Campaign kind.
    pub campaign: Campaign,
    /// Noise level: 0 = exact, 1 = the nominal bench noise of docs/SYNTH.md.
    pub noise: f64,
    /// Random seed of the readings' noise (and of the true motor unless `motor_seed`).
    pub seed: u64,
    /// Seed of the true motor's perturbation; `None`: `seed`. Campaigns of one motor (a
    /// bench's several runs) share it while their noise seeds differ.
    pub motor_seed: Option<u64>,
    /// Relative standard deviation of the perturbation of the uncertain parameters.
    pub perturbation: f64,
    /// Drive voltage amplitude of the fixed-drive campaigns [V].
    pub voltage_v: f64,
    /// Drive frequency of the fixed-drive campaigns [Hz].
    pub frequency_hz: f64,
    /// Use the truth forms of the effects (default) rather than the candidate forms.
    pub truth_forms: bool,
    /// Optional columns to leave out (to mimic a poorer bench).
    pub omit: Vec<Observable>,
}

impl Default for SynthConfig {
    fn default() -> Self {
        SynthConfig {
            campaign: Campaign::PreloadTorque,
            noise: 1.0,
            seed: 1,
            motor_seed: None,
            perturbation: 0.03,
            voltage_v: 200.0,
            frequency_hz: 43_000.0,
            truth_forms: true,
            omit: Vec::new(),
        }
    }
}

/// One synthetic reading row.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthRow {
    /// Measured operating point (preload, torque and voltage carry sensor noise).
    pub op: OperatingPoint,
    /// True when the row is a sample of a time series.
    pub time_series: bool,
    /// Readings (noisy), one per observable present.
    pub readings: Vec<(Observable, f64)>,
    /// Ambient temperature [°C].
    pub ambient_c: f64,
    /// Run identifier.
    pub run_id: String,
}

impl SynthRow {
    /// As an observed row for calibration, with the default noise levels.
    pub fn observed(&self) -> ObservedRow {
        ObservedRow {
            op: self.op,
            readings: self.readings.iter().map(|&(o, v)| (o, v, o.default_sigma(v))).collect(),
            ambient_c: self.ambient_c,
            speed_std_clipped: false,
        }
    }
}

/// The uncertain parameters perturbed in the true motor (relative std: `perturbation`,
/// a tenth of it for the resonance frequency, whose absolute scale is much larger).
pub const PERTURBED: [&str; 5] = [
    "friction_layer.friction_coefficient",
    "friction_layer.youngs_modulus_pa",
    "stator.modal_damping_ns_per_m",
    "stator.force_factor_n_per_v",
    "stator.resonance_frequency_hz",
];

/// The true motor: `motor` with its uncertain parameters perturbed.
pub fn true_motor(motor: &Motor, cfg: &SynthConfig) -> Motor {
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.motor_seed.unwrap_or(cfg.seed) ^ 0x5eed_0f_7e57);
    let mut m = motor.clone();
    for key in PERTURBED {
        let rel = if key.ends_with("resonance_frequency_hz") { 0.1 * cfg.perturbation } else { cfg.perturbation };
        let z: f64 = Normal::new(0.0, 1.0).map(|n| n.sample(&mut rng)).unwrap_or(0.0);
        if let Some(v) = m.param_mut(key) {
            *v *= (rel * z.clamp(-3.0, 3.0)).exp();
        }
    }
    m.effects.set_truth_forms(cfg.truth_forms);
    m
}

struct Noise {
    rng: ChaCha8Rng,
    level: f64,
}

impl Noise {
    fn gauss(&mut self, sd: f64) -> f64 {
        if self.level == 0.0 || sd == 0.0 {
            return 0.0;
        }
        let z: f64 = Normal::new(0.0, 1.0).map(|n| n.sample(&mut self.rng)).unwrap_or(0.0);
        z * sd * self.level
    }
}

/// Bench noise per column: standard deviation of a reading of value `v` at noise level 1
/// (docs/SYNTH.md).
pub fn reading_noise(o: Observable, v: f64) -> f64 {
    match o {
        Observable::SpeedRpm => 0.3 + 0.005 * v.abs(),
        Observable::InputPowerW => 0.02 + 0.01 * v.abs(),
        Observable::CurrentA => 0.001 + 0.008 * v.abs(),
        Observable::Efficiency => 0.003 + 0.015 * v.abs(),
        Observable::FeedbackV => 0.1 + 0.005 * v.abs(),
        Observable::TemperatureC => 0.1,
        Observable::SpeedStdRpm => 0.02 + 0.05 * v.abs(),
    }
}

/// Generates a campaign. `motor` carries the injected effects (may be none).
pub fn synthesize(motor: &Motor, cfg: &SynthConfig) -> Result<Vec<SynthRow>, TrumError> {
    if !(cfg.noise.is_finite() && cfg.noise >= 0.0) {
        return Err(TrumError::input(format!("noise level {} must be a finite number >= 0", cfg.noise)));
    }
    if !(cfg.perturbation.is_finite() && (0.0..0.5).contains(&cfg.perturbation)) {
        return Err(TrumError::input(format!("perturbation {} must be in [0, 0.5)", cfg.perturbation)));
    }
    let truth = true_motor(motor, cfg);
    let p = Prepared::new(&truth);
    let mut noise = Noise { rng: ChaCha8Rng::seed_from_u64(cfg.seed), level: cfg.noise };
    let mut rows = Vec::new();
    let kinds: Vec<Campaign> = match cfg.campaign {
        Campaign::Combined => {
            vec![Campaign::PreloadTorque, Campaign::FrequencySweep, Campaign::WarmUp, Campaign::Stability]
        }
        c => vec![c],
    };
    let ambient = truth.thermal.ambient_c;
    for kind in kinds {
        // (operating point, observables, time series?, run id)
        let mut plan: Vec<(OperatingPoint, bool, String)> = Vec::new();
        match kind {
            Campaign::PreloadTorque => {
                for i in 0..7 {
                    let f = 100.0 + 50.0 * i as f64;
                    let s0 =
                        solve_prepared(&p, &truth, &OperatingPoint::new(f, 0.0, cfg.voltage_v, cfg.frequency_hz), None);
                    let tmax = if s0.status == Status::Ok { 0.9 * s0.stall_torque_nm } else { 0.0 };
                    for j in 0..8 {
                        let t = tmax * j as f64 / 7.0;
                        plan.push((
                            OperatingPoint::new(f, t, cfg.voltage_v, cfg.frequency_hz),
                            false,
                            format!("pt-{f:.0}N"),
                        ));
                    }
                }
            }
            Campaign::FrequencySweep => {
                for v in [0.75 * cfg.voltage_v, cfg.voltage_v, 1.25 * cfg.voltage_v] {
                    for k in 0..15 {
                        let hz = cfg.frequency_hz - 1500.0 + 250.0 * k as f64;
                        plan.push((OperatingPoint::new(250.0, 0.0, v, hz), false, format!("fs-{v:.0}V")));
                    }
                }
            }
            Campaign::WarmUp => {
                for k in 0..31 {
                    let mut op = OperatingPoint::new(250.0, 0.3, cfg.voltage_v, cfg.frequency_hz);
                    op.elapsed_s = 20.0 * k as f64;
                    plan.push((op, true, "warm-up".into()));
                }
            }
            Campaign::Stability => {
                for i in 0..8 {
                    let f = 150.0 + 50.0 * i as f64;
                    plan.push((
                        OperatingPoint::new(f, 0.0, cfg.voltage_v, cfg.frequency_hz),
                        false,
                        "stability".into(),
                    ));
                }
            }
            Campaign::Combined => {}
        }
        for (op, ts, run) in plan {
            let s = solve_prepared(&p, &truth, &op, None);
            if !s.status.is_valid() {
                continue;
            }
            let mut obs =
                vec![Observable::SpeedRpm, Observable::InputPowerW, Observable::CurrentA, Observable::FeedbackV];
            if op.torque_nm > 0.0 {
                obs.push(Observable::Efficiency);
            }
            if ts {
                obs.push(Observable::TemperatureC);
            }
            if kind == Campaign::Stability {
                obs.push(Observable::SpeedStdRpm);
            }
            obs.retain(|o| *o == Observable::SpeedRpm || !cfg.omit.contains(o));
            let readings = obs
                .iter()
                .map(|&o| {
                    let v = o.predict(&s, ambient);
                    let mut x = v + noise.gauss(reading_noise(o, v));
                    if o != Observable::TemperatureC {
                        x = x.max(0.0);
                    }
                    if o == Observable::Efficiency {
                        x = x.min(1.0);
                    }
                    (o, x)
                })
                .collect();
            // the bench records its setpoints with sensor noise: preload ±1 N, torque ±2 mN·m, voltage ±0.3 V
            let mut m_op = op;
            m_op.preload_n = (op.preload_n + noise.gauss(1.0)).max(1.0);
            m_op.torque_nm = (op.torque_nm + noise.gauss(0.002)).max(0.0);
            m_op.voltage_v = (op.voltage_v + noise.gauss(0.3)).max(1.0);
            rows.push(SynthRow { op: m_op, time_series: ts, readings, ambient_c: ambient, run_id: run });
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::frozen as preset;

    #[test]
    fn same_seed_same_data_and_zero_noise_is_exact() {
        let m = preset("trum60a").unwrap();
        let cfg = SynthConfig { campaign: Campaign::Combined, ..SynthConfig::default() };
        let a = synthesize(&m, &cfg).unwrap();
        let b = synthesize(&m, &cfg).unwrap();
        assert_eq!(a, b);
        let c = synthesize(&m, &SynthConfig { seed: 2, ..cfg.clone() }).unwrap();
        assert_ne!(a, c);
        let exact = synthesize(&m, &SynthConfig { noise: 0.0, perturbation: 0.0, ..cfg }).unwrap();
        let r = crate::calibrate::residuals(&m, &exact.iter().map(|r| r.observed()).collect::<Vec<_>>());
        assert!(r.iter().all(|x| x.abs() < 1e-9), "max {:?}", r.iter().fold(0.0f64, |a, b| a.max(b.abs())));
    }

    #[test]
    fn campaigns_have_the_expected_shape() {
        let m = preset("trum60a").unwrap();
        let rows =
            synthesize(&m, &SynthConfig { campaign: Campaign::PreloadTorque, ..SynthConfig::default() }).unwrap();
        assert_eq!(rows.len(), 56);
        let ws = synthesize(&m, &SynthConfig { campaign: Campaign::WarmUp, ..SynthConfig::default() }).unwrap();
        assert!(ws.iter().all(|r| r.time_series && r.readings.iter().any(|x| x.0 == Observable::TemperatureC)));
        assert!(Campaign::from_name("bogus").unwrap_err().to_string().contains("valid campaigns are"));
    }
}

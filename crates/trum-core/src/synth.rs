//! `trum synth`: bench data with known effects. Generates measurement campaigns like a
//! real test bench (Chen et al. 2020 section 3-4, Sun et al. 2021 section 3): the "true" motor is the
//! nominal one with its uncertain parameters perturbed (so calibration has something to
//! absorb) and the chosen effects switched on — by default in their **truth forms**,
//! which differ in form from the candidates the diagnosis fits — and every reading gets
//! realistic noise. Reproducible from the seed.

use crate::effects::Effects;
use crate::error::TrumError;
use crate::observable::{Observable, ObservedRow};
use crate::params::Motor;
use crate::solve::{solve_prepared, OperatingPoint, Prepared, Status};
use rand::{RngExt, SeedableRng};
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

    /// The campaign's name, as `trum synth --campaign` takes it (one of [`Campaign::NAMES`]).
    pub fn name(self) -> &'static str {
        match self {
            Campaign::PreloadTorque => Campaign::NAMES[0],
            Campaign::FrequencySweep => Campaign::NAMES[1],
            Campaign::WarmUp => Campaign::NAMES[2],
            Campaign::Stability => Campaign::NAMES[3],
            Campaign::Combined => Campaign::NAMES[4],
        }
    }

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
    /// Use the truth forms of the effects (default) rather than the candidate forms, for
    /// every effect but those of `nominal_effects`.
    pub truth_forms: bool,
    /// With `truth_forms`: the second family of truth forms (docs/EFFECTS.md).
    pub truth_form_b: bool,
    /// The effects of the nominal model the data are to be diagnosed against (a motor
    /// file's or preset's own). An effect the simulated motor has switched on with the
    /// same parameters as here is part of that model, not unknown physics, and is
    /// simulated in its candidate form, the form the model has; every other effect (one
    /// added to the motor, or given other parameters) is the bench's unknown physics and
    /// takes its truth form (with `truth_forms`). None by default: every effect in truth form.
    pub nominal_effects: Effects,
    /// Optional columns to leave out (to mimic a poorer bench).
    pub omit: Vec<Observable>,
    /// What the bench adds to its readings besides their noise (none by default).
    pub artefacts: Artefacts,
}

/// Bench artefacts: the ways a real test bench's readings differ from the motor's state
/// besides random reading noise (docs/SYNTH.md). All zero by default. The diagnosis must
/// recognise each as the bench's, never as an effect of the motor.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Artefacts {
    /// Relative noise of the drive voltage as read back around its constant set point
    /// (0.005: ±0.5 % standard deviation); the motor runs at the set point.
    pub readback_rel: f64,
    /// Noise floor of the speed-stability instrument [rev/min]: it reads
    /// √(true² + floor²) (plus its noise).
    pub speed_std_floor_rpm: f64,
    /// Zero offset of the torque sensor [N·m]: the file records the true load plus it.
    pub torque_offset_nm: f64,
    /// Resolution of the speed readings [rev/min] (0: none): readings are rounded to it.
    pub speed_quantum_rpm: f64,
    /// Offset of the stator temperature sensor [K]: it reads the stator's temperature
    /// plus this.
    pub temperature_offset_k: f64,
    /// Time constant of the stator temperature sensor [s]: a first-order sensor lags the
    /// warm-up ([`crate::thermal::sensor_rise_k`]).
    pub temperature_lag_s: f64,
    /// Fraction of readings replaced by gross outliers (a reading off by 5-15 of its σ).
    pub outlier_fraction: f64,
    /// Zero offset of the preload reading [N]: the file records the axial force on the
    /// contact plus this.
    pub preload_offset_n: f64,
    /// Relative gain error of the current reading (-): it shows the phase current times
    /// (1 + this), before its noise.
    pub current_gain_rel: f64,
    /// Phase error of the power meter [rad]: the power reading shows P·cos δ + Q·sin δ of
    /// the whole reactive power Q ([`meter_power_w`]; the diagnosis' bench model keeps
    /// only its clamped capacitance's part) and the efficiency reading the output power
    /// over it, before their noise.
    pub power_phase_rad: f64,
}

impl Artefacts {
    /// Names of the artefacts as written in `name=value` lists.
    pub const NAMES: [&'static str; 10] = [
        "readback_rel",
        "speed_std_floor_rpm",
        "torque_offset_nm",
        "speed_quantum_rpm",
        "outlier_fraction",
        "temperature_offset_k",
        "temperature_lag_s",
        "preload_offset_n",
        "current_gain_rel",
        "power_phase_rad",
    ];

    /// Parses `name=value,...` (e.g. `readback_rel=0.005,speed_std_floor_rpm=0.3`); the
    /// error names the bad item and lists the valid names.
    pub fn parse(spec: &str) -> Result<Artefacts, TrumError> {
        let mut a = Artefacts::default();
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (k, v) = item.split_once('=').ok_or_else(|| {
                TrumError::input(format!(
                    "bench artefact '{item}': write name=value; names are {}",
                    Self::NAMES.join(", ")
                ))
            })?;
            let x: f64 =
                v.trim().parse().ok().filter(|x: &f64| x.is_finite()).ok_or_else(|| {
                    TrumError::input(format!("bench artefact '{item}': '{v}' is not a finite number"))
                })?;
            let slot = match k.trim() {
                "readback_rel" => &mut a.readback_rel,
                "speed_std_floor_rpm" => &mut a.speed_std_floor_rpm,
                "torque_offset_nm" => &mut a.torque_offset_nm,
                "speed_quantum_rpm" => &mut a.speed_quantum_rpm,
                "outlier_fraction" => &mut a.outlier_fraction,
                "temperature_offset_k" => &mut a.temperature_offset_k,
                "temperature_lag_s" => &mut a.temperature_lag_s,
                "preload_offset_n" => &mut a.preload_offset_n,
                "current_gain_rel" => &mut a.current_gain_rel,
                "power_phase_rad" => &mut a.power_phase_rad,
                other => {
                    return Err(TrumError::input(format!(
                        "unknown bench artefact '{other}'; valid names are: {}",
                        Self::NAMES.join(", ")
                    )))
                }
            };
            *slot = x;
        }
        let bad = |name: &str, why: &str| Err(TrumError::input(format!("bench artefact {name}: {why}")));
        if !(0.0..0.2).contains(&a.readback_rel) {
            return bad("readback_rel", "must be in [0, 0.2)");
        }
        if a.speed_std_floor_rpm < 0.0 || a.speed_quantum_rpm < 0.0 {
            return bad("speed_std_floor_rpm / speed_quantum_rpm", "must be >= 0");
        }
        if !(0.0..0.5).contains(&a.outlier_fraction) {
            return bad("outlier_fraction", "must be in [0, 0.5)");
        }
        if a.temperature_lag_s < 0.0 {
            return bad("temperature_lag_s", "must be >= 0");
        }
        if !(-0.5..0.5).contains(&a.current_gain_rel) {
            return bad("current_gain_rel", "must be in (-0.5, 0.5)");
        }
        if !(-0.5..0.5).contains(&a.power_phase_rad) {
            return bad("power_phase_rad", "must be in (-0.5, 0.5) rad");
        }
        Ok(a)
    }
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
            truth_form_b: false,
            nominal_effects: Effects::none(),
            omit: Vec::new(),
            artefacts: Artefacts::default(),
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

/// The parameters perturbed in the true motor, each with its relative standard deviation
/// as a multiple of `perturbation`: every parameter a real motor of the design differs in,
/// the machined geometry less than the materials, the resonance frequency (whose absolute
/// scale is much larger) least.
pub const PERTURBED: [(&str, f64); 11] = [
    ("friction_layer.friction_coefficient", 1.0),
    ("friction_layer.youngs_modulus_pa", 1.0),
    ("stator.modal_damping_ns_per_m", 1.0),
    ("stator.force_factor_n_per_v", 1.0),
    ("stator.resonance_frequency_hz", 0.1),
    ("geometry.neutral_plane_distance_m", 0.7),
    ("geometry.mean_radius_m", 0.3),
    ("stator.modal_mass_kg", 1.0),
    ("electrical.dielectric_loss_tangent", 2.0),
    ("electrical.clamped_capacitance_f", 0.5),
    ("electrical.feedback_gain_v_per_m", 1.0),
];

/// The true motor: `motor` with its uncertain parameters perturbed, its effects in the
/// forms `cfg` gives (truth forms for all but the nominal model's own).
pub fn true_motor(motor: &Motor, cfg: &SynthConfig) -> Motor {
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.motor_seed.unwrap_or(cfg.seed) ^ 0x005e_ed0f_7e57);
    let mut m = motor.clone();
    for (key, factor) in PERTURBED {
        let rel = factor * cfg.perturbation;
        let z: f64 = Normal::new(0.0, 1.0).map(|n| n.sample(&mut rng)).unwrap_or(0.0);
        if let Some(v) = m.param_mut(key) {
            *v *= (rel * z.clamp(-3.0, 3.0)).exp();
        }
    }
    m.effects.set_truth_forms(cfg.truth_forms);
    if cfg.truth_forms && cfg.truth_form_b {
        m.effects.set_truth_form_b(true);
    }
    for e in m.effects.active() {
        if cfg.nominal_effects.get(e) == m.effects.get(e) {
            m.effects.set_truth_form(e, false);
        }
    }
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

/// What a power meter whose current channel lags its voltage channel by `phase_rad` shows
/// of the input power of `s` [W]: V·I·cos(φ − δ) = P·cos δ + Q·sin δ with the whole
/// reactive power Q of both phases, motional branch included.
pub fn meter_power_w(s: &crate::Solution, phase_rad: f64) -> f64 {
    if phase_rad == 0.0 {
        return s.input_power_w;
    }
    let (sin, cos) = phase_rad.sin_cos();
    s.input_power_w * cos + s.reactive_power_var() * sin
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
    // the artefacts draw from their own stream, so that data without them stay as they were
    let mut bench = ChaCha8Rng::seed_from_u64(cfg.seed ^ 0xa47e_fac7);
    let art = cfg.artefacts;
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
                    let mut v = match o {
                        Observable::InputPowerW => meter_power_w(&s, art.power_phase_rad),
                        Observable::Efficiency if art.power_phase_rad != 0.0 => {
                            crate::losses::efficiency(s.output_power_w, meter_power_w(&s, art.power_phase_rad))
                        }
                        _ => o.predict(&s, ambient),
                    };
                    if o == Observable::SpeedStdRpm && art.speed_std_floor_rpm > 0.0 {
                        v = v.hypot(art.speed_std_floor_rpm);
                    }
                    if o == Observable::TemperatureC {
                        if art.temperature_lag_s > 0.0 {
                            v = ambient
                                + crate::thermal::sensor_rise_k(
                                    s.temperature_rise_k,
                                    s.temperature_rise_at_elapsed_k,
                                    op.elapsed_s,
                                    art.temperature_lag_s,
                                );
                        }
                        v += art.temperature_offset_k;
                    }
                    if o == Observable::CurrentA {
                        v *= 1.0 + art.current_gain_rel;
                    }
                    let mut x = v + noise.gauss(reading_noise(o, v));
                    if art.outlier_fraction > 0.0 && bench.random::<f64>() < art.outlier_fraction {
                        let sign = if bench.random::<bool>() { 1.0 } else { -1.0 };
                        x += sign * (5.0 + 10.0 * bench.random::<f64>()) * reading_noise(o, v);
                    }
                    if o == Observable::SpeedRpm && art.speed_quantum_rpm > 0.0 {
                        x = (x / art.speed_quantum_rpm).round() * art.speed_quantum_rpm;
                    }
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
            if art.readback_rel > 0.0 {
                let z: f64 = Normal::new(0.0, 1.0).map(|n| n.sample(&mut bench)).unwrap_or(0.0);
                m_op.voltage_v = (m_op.voltage_v * (1.0 + art.readback_rel * z.clamp(-3.0, 3.0))).max(1.0);
            }
            if art.torque_offset_nm != 0.0 {
                m_op.torque_nm = (m_op.torque_nm + art.torque_offset_nm).max(0.0);
            }
            if art.preload_offset_n != 0.0 {
                m_op.preload_n = (m_op.preload_n + art.preload_offset_n).max(1.0);
            }
            rows.push(SynthRow { op: m_op, time_series: ts, readings, ambient_c: ambient, run_id: run });
        }
    }
    Ok(rows)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_data_and_zero_noise_is_exact() {
        let m = crate::calibrate::tests::reference_motor();
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

    /// A power meter's phase error reads the power as P·cos δ + Q·sin δ of the whole
    /// reactive power (the same rows solved by hand) and the efficiency as the output over
    /// it; at δ = 0 the readings are the model's. Out of (−0.5, 0.5) rad it is refused,
    /// naming the artefact.
    #[test]
    fn a_power_meters_phase_error_reads_power_and_efficiency_through_the_whole_reactive_power() {
        let m = crate::calibrate::tests::reference_motor();
        let delta: f64 = 0.05;
        let art = Artefacts::parse(&format!("power_phase_rad={delta}")).unwrap();
        let base =
            SynthConfig { campaign: Campaign::PreloadTorque, noise: 0.0, perturbation: 0.0, ..SynthConfig::default() };
        let rows = synthesize(&m, &SynthConfig { artefacts: art, ..base.clone() }).unwrap();
        let plain = synthesize(&m, &base).unwrap();
        let mut checked = 0;
        for (r, p) in rows.iter().zip(&plain) {
            let s = crate::solve(&m, &r.op);
            let read = |rows: &[(Observable, f64)], o| rows.iter().find(|x| x.0 == o).map(|x| x.1);
            let whole = s.input_power_w * delta.cos() + s.reactive_power_var() * delta.sin();
            let power = read(&r.readings, Observable::InputPowerW).unwrap();
            assert!((power - whole.max(0.0)).abs() <= 1e-9 * whole.abs().max(1.0), "{power} vs {whole}");
            assert_eq!(read(&p.readings, Observable::InputPowerW), Some(s.input_power_w.max(0.0)));
            if let Some(eff) = read(&r.readings, Observable::Efficiency) {
                assert!((eff - crate::losses::efficiency(s.output_power_w, whole)).abs() < 1e-12);
                checked += 1;
            }
        }
        assert!(checked > 10, "{checked} efficiency readings");
        let err = Artefacts::parse("power_phase_rad=0.6").unwrap_err().to_string();
        assert!(err.contains("power_phase_rad"), "{err}");
    }

    #[test]
    fn campaigns_have_the_expected_shape() {
        let m = crate::calibrate::tests::reference_motor();
        let rows =
            synthesize(&m, &SynthConfig { campaign: Campaign::PreloadTorque, ..SynthConfig::default() }).unwrap();
        assert_eq!(rows.len(), 56);
        let ws = synthesize(&m, &SynthConfig { campaign: Campaign::WarmUp, ..SynthConfig::default() }).unwrap();
        assert!(ws.iter().all(|r| r.time_series && r.readings.iter().any(|x| x.0 == Observable::TemperatureC)));
        assert!(Campaign::from_name("bogus").unwrap_err().to_string().contains("valid campaigns are"));
    }

    /// The nominal model's own effects keep their candidate form (the form the model a
    /// diagnosis starts from has); an added effect, or an own one at another strength, is
    /// the bench's unknown physics and takes its truth form.
    #[test]
    fn own_effects_keep_their_candidate_form_and_added_ones_take_their_truth_form() {
        use crate::effects::Effect;
        let mut m = crate::calibrate::tests::reference_motor();
        m.effects.set_strength(Effect::PreloadStiffening, 0.2);
        let cfg = SynthConfig {
            campaign: Campaign::PreloadTorque,
            noise: 0.0,
            nominal_effects: m.effects.clone(),
            ..SynthConfig::default()
        };
        let candidate = SynthConfig { truth_forms: false, ..cfg.clone() };
        let all_truth = SynthConfig { nominal_effects: Effects::none(), ..cfg.clone() };
        // the own effect alone: the data are the candidate forms' data, bit for bit, and
        // differ from those of its truth form
        assert!(!true_motor(&m, &cfg).effects.is_truth_form(Effect::PreloadStiffening));
        let own = synthesize(&m, &cfg).unwrap();
        assert_eq!(own, synthesize(&m, &candidate).unwrap());
        assert_ne!(own, synthesize(&m, &all_truth).unwrap());
        // an added effect takes its truth form, the own one stays candidate: the data differ
        // from both the all-candidate and the all-truth data
        let mut added = m.clone();
        added.effects.set_strength(Effect::VoltageSag, 200.0);
        let t = true_motor(&added, &cfg).effects;
        assert!(t.is_truth_form(Effect::VoltageSag) && !t.is_truth_form(Effect::PreloadStiffening));
        let mixed = synthesize(&added, &cfg).unwrap();
        assert_ne!(mixed, synthesize(&added, &candidate).unwrap());
        assert_ne!(mixed, synthesize(&added, &all_truth).unwrap());
        // the second family for the added effect only
        let b = true_motor(&added, &SynthConfig { truth_form_b: true, ..cfg.clone() }).effects;
        assert!(b.is_truth_form_b(Effect::VoltageSag) && !b.is_truth_form(Effect::PreloadStiffening));
        // the own effect at another strength is not the model's: truth form
        let mut changed = m.clone();
        changed.effects.set_strength(Effect::PreloadStiffening, 0.4);
        assert!(true_motor(&changed, &cfg).effects.is_truth_form(Effect::PreloadStiffening));
        // with --candidate-forms nothing takes a truth form
        assert!(!true_motor(&added, &candidate).effects.is_truth_form(Effect::VoltageSag));
    }
}

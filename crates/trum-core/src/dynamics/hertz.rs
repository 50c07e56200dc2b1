//! Single-sided Hertzian-contact forced oscillator of a TRUM stator (the Hertzian driving-circuit paper (2022)).
//!
//! Model (the Hertzian driving-circuit paper (2022) eq. 2-3, with the linear modal stiffness `k` the printed eq. 2 omits):
//!
//! ```text
//! m·w'' + c·w' + k·w + β(N, V)·w³ = F_n + F_d,
//! F_n = N·(1 + k_c·cos Ωt)   (preload plus dynamic contact force, eq. 3)
//! F_d = A·V·cos Ωt            (piezoelectric drive, eq. 3; V = voltage amplitude)
//! ```
//!
//! β < 0 is a softening (Hertzian) restoring force: the backbone bends to lower
//! frequency, the resonance curve leans left and jumps appear once the nonlinear shift
//! exceeds the damping bandwidth (spec effect `hertz_softening`). The static preload N
//! deflects the modal coordinate to `w_s` (k·w_s + β·w_s³ = N); about `w_s` the
//! oscillator is a Duffing–quadratic oscillator with k_eff = k + 3β·w_s², quadratic
//! coefficient 3β·w_s and cubic coefficient β. For the first-order amplitude–frequency
//! response the quadratic term folds into the equivalent cubic
//! β_eq = β − 10·(3β·w_s)²/(9·k_eff) (Nayfeh & Mook, *Nonlinear Oscillations*, §4.1.4;
//! this is the `−5β²/12ω̄³` term of the Hertzian driving-circuit paper (2022)'s coefficient `C`, eq. 11).
//!
//! Sub-modules: [`sim`] (RK4 time simulation, sweeps), [`ident`] (harmonic-balance
//! identification of β, eq. 5-9). All functions validate their inputs and return
//! [`HertzError`] instead of panicking.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use thiserror::Error;

pub mod ident;
pub mod sim;
#[cfg(test)]
mod tests;

pub use ident::{identify_beta, linear_stiffness_from_resonance_n_per_m, BetaIdentification, BetaIdentificationInput};
pub use sim::{
    find_jump, FrequencySweep, OscillatorState, RecordOptions, SimulationSettings, SteadyState, SweepJump, SweepPoint,
    TimeSeries,
};

/// Errors of the Hertzian-oscillator model, response, simulation and identification.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum HertzError {
    /// A parameter or argument is outside its valid range (or not finite).
    #[error("invalid `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name (with unit suffix).
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// The softening spring cannot carry the static preload (no static equilibrium).
    #[error("static preload {preload_n} N exceeds the largest static force {max_force_n} N of the softening spring")]
    NoStaticEquilibrium {
        /// Requested static preload, N.
        preload_n: f64,
        /// Largest force k·w + β·w³ reaches before the softening spring folds, N.
        max_force_n: f64,
    },
    /// Too few samples or too short a record for the requested analysis.
    #[error("input too short: {reason}")]
    TooShort {
        /// What is missing.
        reason: String,
    },
    /// A NaN or infinite value in an input array.
    #[error("non-finite value in `{name}` at index {index}")]
    NonFinite {
        /// Input array name.
        name: &'static str,
        /// First offending index.
        index: usize,
    },
    /// Input arrays of different lengths.
    #[error("length mismatch: {left} vs {right}")]
    LengthMismatch {
        /// Length of the first array.
        left: usize,
        /// Length of the second array.
        right: usize,
    },
    /// Sample times not strictly increasing.
    #[error("sample times are not strictly increasing at index {index}")]
    NonMonotonicTime {
        /// First offending index.
        index: usize,
    },
    /// The waveform is not periodic at the drive frequency (transient, sub-harmonic, …).
    #[error("waveform is not periodic at the drive frequency: {reason}")]
    NonPeriodic {
        /// Which check failed.
        reason: String,
    },
    /// A least-squares or root-finding problem is singular.
    #[error("degenerate problem: {0}")]
    Degenerate(&'static str),
    /// The time integration left the bounded region (escape over the softening barrier).
    #[error("simulation diverged at t = {time_s} s")]
    Diverged {
        /// Time of divergence, s.
        time_s: f64,
    },
    /// The requested simulation needs more steps than the safety limit.
    #[error("simulation needs {steps} steps, more than the limit {limit}")]
    TooManySteps {
        /// Steps required.
        steps: f64,
        /// Limit.
        limit: f64,
    },
}

/// `true` unless `x > y` (NaN-safe "not greater").
pub(crate) fn not_gt(x: f64, y: f64) -> bool {
    !matches!(x.partial_cmp(&y), Some(std::cmp::Ordering::Greater))
}

/// `true` unless `x >= y` (NaN-safe "not greater or equal").
pub(crate) fn not_ge(x: f64, y: f64) -> bool {
    !matches!(x.partial_cmp(&y), Some(std::cmp::Ordering::Greater | std::cmp::Ordering::Equal))
}

/// Result alias of this module.
pub type HertzResult<T> = Result<T, HertzError>;

pub(crate) fn check_finite(name: &'static str, value: f64) -> HertzResult<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(HertzError::InvalidParameter { name, value, reason: "must be finite" })
    }
}

pub(crate) fn check_positive(name: &'static str, value: f64) -> HertzResult<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(HertzError::InvalidParameter { name, value, reason: "must be finite and > 0" })
    }
}

pub(crate) fn check_non_negative(name: &'static str, value: f64) -> HertzResult<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(HertzError::InvalidParameter { name, value, reason: "must be finite and >= 0" })
    }
}

/// Parameters of the single-sided Hertzian-contact forced oscillator (the Hertzian driving-circuit paper (2022), eq. 2-4),
/// reduced to the stator's B09 modal coordinate `w` (m).
///
/// Defaults: a 60 mm TRUM (see [`HertzOscillator::default`] and `docs/DYNAMICS.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzOscillator {
    /// Modal mass m, kg (the Hertzian driving-circuit paper (2022) §3: 0.0577809 kg from an impedance analyzer). > 0.
    pub modal_mass_kg: f64,
    /// Modal viscous damping c, N·s/m (the Hertzian driving-circuit paper (2022) §3: 1 N·s/m). > 0.
    pub damping_ns_per_m: f64,
    /// Linear modal stiffness k, N/m (not in the printed eq. 2; assumed from the linear
    /// resonance, k = m·(2π·41 kHz)²). > 0.
    pub linear_stiffness_n_per_m: f64,
    /// Cubic coefficient β at the reference preload and voltage, N/m³; negative is
    /// softening (Hertzian). Assumed value, see `docs/DYNAMICS.md`.
    pub beta_n_per_m3: f64,
    /// Piezoelectric force factor A of F_d = A·V·cos Ωt, N/V (V = voltage amplitude).
    pub force_factor_n_per_v: f64,
    /// Dynamic contact force coefficient k_c of F_n = N(1 + k_c cos Ωt), dimensionless.
    pub dynamic_contact_coefficient: f64,
    /// Reference preload N_ref at which `beta_n_per_m3` holds, N. > 0.
    pub reference_preload_n: f64,
    /// Reference voltage amplitude V_ref at which `beta_n_per_m3` holds, V. > 0.
    pub reference_voltage_v: f64,
    /// Exponent p_N of the assumed law β = β_ref·(N/N_ref)^p_N·(V/V_ref)^p_V. >= 0.
    pub beta_preload_exponent: f64,
    /// Exponent p_V of the assumed law β = β_ref·(N/N_ref)^p_N·(V/V_ref)^p_V. >= 0.
    pub beta_voltage_exponent: f64,
}

/// Default linear resonance of the 60 mm TRUM B09 mode, Hz (assumed, between the
/// 40.1 kHz high-voltage peak of the Hertzian driving-circuit paper (2022) Fig. 5 and the 41.5 kHz drive of Fig. 3).
pub const DEFAULT_LINEAR_RESONANCE_HZ: f64 = 41_000.0;

impl Default for HertzOscillator {
    /// 60 mm TRUM: m, c from the Hertzian driving-circuit paper (2022) §3; k from an assumed 41.0 kHz linear resonance;
    /// β_ref = −1.0e19 N/m³ at 400 N (the Hertzian driving-circuit paper (2022)'s test preload) and 200 V (assumed: gives
    /// ≈130 Hz softening shift at ≈1.8 µm); A = 2.1e-3 N/V and k_c = 1.25e-4 (assumed:
    /// peak amplitude ≈1.0 / 1.8 / 2.6 µm at 100 / 200 / 300 V, 400 N); p_N = p_V = 1
    /// (assumed, reproduces the monotonic growth of Fig. 9 and 12).
    fn default() -> Self {
        let m = 0.057_780_9;
        let w0 = 2.0 * PI * DEFAULT_LINEAR_RESONANCE_HZ;
        Self {
            modal_mass_kg: m,
            damping_ns_per_m: 1.0,
            linear_stiffness_n_per_m: m * w0 * w0,
            beta_n_per_m3: -1.0e19,
            force_factor_n_per_v: 2.1e-3,
            dynamic_contact_coefficient: 1.25e-4,
            reference_preload_n: 400.0,
            reference_voltage_v: 200.0,
            beta_preload_exponent: 1.0,
            beta_voltage_exponent: 1.0,
        }
    }
}

/// Operating point: drive voltage amplitude and static preload.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OperatingPoint {
    /// Drive voltage amplitude V (zero-to-peak), V. >= 0.
    pub voltage_v: f64,
    /// Static axial preload N, N. >= 0.
    pub preload_n: f64,
}

/// The oscillator linearised about its static equilibrium at one operating point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EffectiveDuffing {
    /// Modal mass, kg.
    pub modal_mass_kg: f64,
    /// Modal damping, N·s/m.
    pub damping_ns_per_m: f64,
    /// Static deflection w_s solving k·w_s + β·w_s³ = N, m.
    pub static_deflection_m: f64,
    /// Tangent stiffness k_eff = k + 3β·w_s², N/m.
    pub stiffness_n_per_m: f64,
    /// Quadratic coefficient 3β·w_s about w_s, N/m².
    pub quadratic_n_per_m2: f64,
    /// Cubic coefficient β(N, V), N/m³.
    pub beta_n_per_m3: f64,
    /// Equivalent cubic β_eq = β − 10(3β·w_s)²/(9 k_eff) for primary resonance, N/m³.
    pub equivalent_beta_n_per_m3: f64,
    /// Harmonic force amplitude F = A·V + k_c·N, N.
    pub forcing_amplitude_n: f64,
}

impl EffectiveDuffing {
    /// Linear (small-amplitude) resonance about the static equilibrium,
    /// f = √(k_eff/m)/2π, Hz (the Hertzian driving-circuit paper (2022) eq. 11: ν̄² = k_eff/m, the linearised restoring
    /// force about the preload deflection). Always finite for a value built by
    /// [`HertzOscillator::effective`].
    pub fn linear_resonance_hz(&self) -> f64 {
        (self.stiffness_n_per_m / self.modal_mass_kg).sqrt() / (2.0 * PI)
    }
}

impl HertzOscillator {
    /// The oscillator of a motor, so that `trum resonance` and the steady solver describe
    /// one motor: m = `stator.modal_mass_kg`, c = `stator.modal_damping_ns_per_m`,
    /// k = m·(2π·`stator.resonance_frequency_hz`)² (its linear resonance is the free
    /// stator's), A = `stator.force_factor_n_per_v` (the modal force per volt of Chen et
    /// al. 2020 Appendix A is the Hertzian driving-circuit paper (2022)'s A of eq. 3).
    /// β comes from the motor's `hertz_softening` effect, β(N) = −β0·(1 + g·N) (softening
    /// is negative here): `beta_n_per_m3` is its value at the reference preload N_ref and
    /// `beta_preload_exponent` = g·N_ref/(1 + g·N_ref) matches its slope there, with no
    /// voltage dependence; without the effect β = 0 (the linear oscillator). The dynamic
    /// contact coefficient k_c and the references keep their defaults (the motor has no
    /// counterpart). The friction layer's contact stiffness and damping are not in this
    /// oscillator: it is the stator's modal resonator under the static preload.
    pub fn from_motor(motor: &crate::params::Motor) -> HertzOscillator {
        use crate::effects::Effect;
        let st = &motor.stator;
        let d = HertzOscillator::default();
        let (beta0, gain) =
            (motor.effects.value(Effect::HertzSoftening, 0), motor.effects.value(Effect::HertzSoftening, 1));
        let growth = gain * d.reference_preload_n;
        HertzOscillator {
            modal_mass_kg: st.modal_mass_kg,
            damping_ns_per_m: st.modal_damping_ns_per_m,
            linear_stiffness_n_per_m: crate::stator::modal_stiffness_n_per_m(
                st.modal_mass_kg,
                st.resonance_frequency_hz,
            ),
            beta_n_per_m3: -beta0 * (1.0 + growth),
            force_factor_n_per_v: st.force_factor_n_per_v,
            beta_preload_exponent: if beta0 > 0.0 { growth / (1.0 + growth) } else { 0.0 },
            beta_voltage_exponent: 0.0,
            ..d
        }
    }

    /// Checks every field (finite, positive where required). the Hertzian driving-circuit paper (2022) eq. 2-3.
    pub fn validate(&self) -> HertzResult<()> {
        check_positive("modal_mass_kg", self.modal_mass_kg)?;
        check_positive("damping_ns_per_m", self.damping_ns_per_m)?;
        check_positive("linear_stiffness_n_per_m", self.linear_stiffness_n_per_m)?;
        check_finite("beta_n_per_m3", self.beta_n_per_m3)?;
        check_non_negative("force_factor_n_per_v", self.force_factor_n_per_v)?;
        check_non_negative("dynamic_contact_coefficient", self.dynamic_contact_coefficient)?;
        check_positive("reference_preload_n", self.reference_preload_n)?;
        check_positive("reference_voltage_v", self.reference_voltage_v)?;
        check_non_negative("beta_preload_exponent", self.beta_preload_exponent)?;
        check_non_negative("beta_voltage_exponent", self.beta_voltage_exponent)?;
        Ok(())
    }

    /// Parameter names, as the fields are called in a TOML file or a dict.
    pub const PARAM_KEYS: [&'static str; 10] = [
        "modal_mass_kg",
        "damping_ns_per_m",
        "linear_stiffness_n_per_m",
        "beta_n_per_m3",
        "force_factor_n_per_v",
        "dynamic_contact_coefficient",
        "reference_preload_n",
        "reference_voltage_v",
        "beta_preload_exponent",
        "beta_voltage_exponent",
    ];

    /// The parameter called `key` (one of [`Self::PARAM_KEYS`]), for setting it by name.
    pub fn param_mut(&mut self, key: &str) -> Option<&mut f64> {
        Some(match key {
            "modal_mass_kg" => &mut self.modal_mass_kg,
            "damping_ns_per_m" => &mut self.damping_ns_per_m,
            "linear_stiffness_n_per_m" => &mut self.linear_stiffness_n_per_m,
            "beta_n_per_m3" => &mut self.beta_n_per_m3,
            "force_factor_n_per_v" => &mut self.force_factor_n_per_v,
            "dynamic_contact_coefficient" => &mut self.dynamic_contact_coefficient,
            "reference_preload_n" => &mut self.reference_preload_n,
            "reference_voltage_v" => &mut self.reference_voltage_v,
            "beta_preload_exponent" => &mut self.beta_preload_exponent,
            "beta_voltage_exponent" => &mut self.beta_voltage_exponent,
            _ => return None,
        })
    }

    /// Sets the parameter `key` to `value` if the oscillator stays valid (an error names
    /// the parameter and the range otherwise, and nothing changes). `Ok(false)`: `key` is
    /// not a parameter.
    pub fn set_param(&mut self, key: &str, value: f64) -> HertzResult<bool> {
        let mut next = self.clone();
        let Some(slot) = next.param_mut(key) else { return Ok(false) };
        *slot = value;
        next.validate()?;
        *self = next;
        Ok(true)
    }

    /// Builds an oscillator with the default TRUM values but a given linear resonance
    /// `frequency_hz` (> 0), i.e. k = m(2πf)². the Hertzian driving-circuit paper (2022) eq. 2.
    pub fn with_linear_resonance_hz(frequency_hz: f64) -> HertzResult<Self> {
        check_positive("frequency_hz", frequency_hz)?;
        let mut o = Self::default();
        let w0 = 2.0 * PI * frequency_hz;
        o.linear_stiffness_n_per_m = o.modal_mass_kg * w0 * w0;
        Ok(o)
    }

    /// Linear resonance without preload, f0 = √(k/m)/2π, Hz. the Hertzian driving-circuit paper (2022) eq. 2 with β = 0.
    pub fn linear_resonance_hz(&self) -> f64 {
        (self.linear_stiffness_n_per_m / self.modal_mass_kg).sqrt() / (2.0 * PI)
    }

    /// Cubic coefficient at an operating point, N/m³ (ASSUMED law, the Hertzian driving-circuit paper (2022) gives only the
    /// trend "nonlinearity grows with preload and voltage", Fig. 9, 11, 12):
    /// β(N, V) = β_ref·(N/N_ref)^p_N·(V/V_ref)^p_V. Valid for N, V >= 0.
    pub fn beta_at_n_per_m3(&self, op: &OperatingPoint) -> HertzResult<f64> {
        self.validate()?;
        check_non_negative("voltage_v", op.voltage_v)?;
        check_non_negative("preload_n", op.preload_n)?;
        let fac_n = scaled_power(op.preload_n / self.reference_preload_n, self.beta_preload_exponent);
        let fac_v = scaled_power(op.voltage_v / self.reference_voltage_v, self.beta_voltage_exponent);
        let beta = self.beta_n_per_m3 * fac_n * fac_v;
        check_finite("beta_n_per_m3 at operating point", beta)
    }

    /// Harmonic force amplitude F = A·V + k_c·N (the Hertzian driving-circuit paper (2022) eq. 3, both terms taken in phase
    /// at the drive frequency), N. Valid for N, V >= 0.
    pub fn forcing_amplitude_n(&self, op: &OperatingPoint) -> HertzResult<f64> {
        self.validate()?;
        check_non_negative("voltage_v", op.voltage_v)?;
        check_non_negative("preload_n", op.preload_n)?;
        let f = self.force_factor_n_per_v * op.voltage_v + self.dynamic_contact_coefficient * op.preload_n;
        check_finite("forcing_amplitude_n", f)
    }

    /// Static equilibrium and the equivalent Duffing oscillator about it (the Hertzian driving-circuit paper (2022) eq. 2-3
    /// with the constant part N of F_n; Nayfeh & Mook §4.1.4 for β_eq). Errors with
    /// [`HertzError::NoStaticEquilibrium`] if a softening spring cannot carry N.
    pub fn effective(&self, op: &OperatingPoint) -> HertzResult<EffectiveDuffing> {
        let beta = self.beta_at_n_per_m3(op)?;
        let force = self.forcing_amplitude_n(op)?;
        let k = self.linear_stiffness_n_per_m;
        let ws = static_deflection_m(k, beta, op.preload_n)?;
        let k_eff = k + 3.0 * beta * ws * ws;
        if not_gt(k_eff, 0.0) {
            return Err(HertzError::NoStaticEquilibrium { preload_n: op.preload_n, max_force_n: f64::NAN });
        }
        let q = 3.0 * beta * ws;
        let beta_eq = beta - 10.0 * q * q / (9.0 * k_eff);
        Ok(EffectiveDuffing {
            modal_mass_kg: self.modal_mass_kg,
            damping_ns_per_m: self.damping_ns_per_m,
            static_deflection_m: ws,
            stiffness_n_per_m: k_eff,
            quadratic_n_per_m2: q,
            beta_n_per_m3: beta,
            equivalent_beta_n_per_m3: beta_eq,
            forcing_amplitude_n: force,
        })
    }
}

/// x^p with 0^0 = 1 and 0^p = 0 for p > 0.
fn scaled_power(x: f64, p: f64) -> f64 {
    if p == 0.0 {
        1.0
    } else if x <= 0.0 {
        0.0
    } else {
        x.powf(p)
    }
}

/// Static deflection w_s ≥ 0 of k·w + β·w³ = N on the branch through the origin, m.
/// For β < 0 the spring folds at w* = √(k/(3|β|)) with force (2/3)k·w*; larger N has no
/// equilibrium. the Hertzian driving-circuit paper (2022) eq. 2-3 (constant part of F_n).
pub fn static_deflection_m(stiffness_n_per_m: f64, beta_n_per_m3: f64, preload_n: f64) -> HertzResult<f64> {
    let k = check_positive("stiffness_n_per_m", stiffness_n_per_m)?;
    let beta = check_finite("beta_n_per_m3", beta_n_per_m3)?;
    let n = check_non_negative("preload_n", preload_n)?;
    if n == 0.0 {
        return Ok(0.0);
    }
    let force = |w: f64| k * w + beta * w * w * w;
    let (lo, hi) = if beta < 0.0 {
        let w_star = (k / (3.0 * beta.abs())).sqrt();
        let f_max = force(w_star);
        if n >= f_max {
            return Err(HertzError::NoStaticEquilibrium { preload_n: n, max_force_n: f_max });
        }
        (0.0, w_star)
    } else {
        (0.0, n / k)
    };
    Ok(bisect(|w| force(w) - n, lo, hi, 200))
}

/// Bisection for a sign change of `f` on [lo, hi]; returns the midpoint after `iters`
/// halvings or when the interval stops shrinking in floating point.
pub(crate) fn bisect<F: Fn(f64) -> f64>(f: F, mut lo: f64, mut hi: f64, iters: usize) -> f64 {
    let mut flo = f(lo);
    if flo == 0.0 {
        return lo;
    }
    if f(hi) == 0.0 {
        return hi;
    }
    for _ in 0..iters {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return mid;
        }
        if (fm < 0.0) == (flo < 0.0) {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

// ---------------------------------------------------------------------------------------
// Amplitude–frequency response
// ---------------------------------------------------------------------------------------

/// Which first-order approximation of the steady state is used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ResponseMethod {
    /// Multiple scales, the Hertzian driving-circuit paper (2022) eq. 10-12 (corrected, see `docs/DYNAMICS.md`):
    /// σ = Ω − ω0, κ = 3β_eq/(8mω0), H = F/(2mω0), μ = c/(2m).
    #[default]
    MultipleScales,
    /// One-term harmonic balance: a²[(k_eff − mΩ² + ¾β_eq a²)² + (cΩ)²] = F²,
    /// written in the same slow-flow form with σ = (Ω² − ω0²)/(2Ω), κ = 3β_eq/(8mΩ),
    /// H = F/(2mΩ). Exact linear resonance for β = 0.
    HarmonicBalance,
}

/// Which root of the amplitude equation a response point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Branch {
    /// Only one real amplitude at this frequency.
    Single,
    /// Smallest of three amplitudes (stable).
    Lower,
    /// Middle of three amplitudes (saddle, unstable).
    Middle,
    /// Largest of three amplitudes (stable).
    Upper,
}

impl Branch {
    /// The word written in `branch` columns: `single`, `lower`, `middle`, `upper`.
    pub fn as_str(self) -> &'static str {
        match self {
            Branch::Single => "single",
            Branch::Lower => "lower",
            Branch::Middle => "middle",
            Branch::Upper => "upper",
        }
    }
}

/// One steady-state solution of the amplitude equation (the Hertzian driving-circuit paper (2022) eq. 12).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ResponsePoint {
    /// Drive frequency, Hz.
    pub frequency_hz: f64,
    /// Amplitude of the fundamental about the static deflection, m.
    pub amplitude_m: f64,
    /// Phase lag φ of w = w_s + a·cos(Ωt − φ) behind the drive, rad, in (0, π).
    pub phase_lag_rad: f64,
    /// Stable fixed point of the slow flow (eq. 10): μ² + (σ−κa²)(σ−3κa²) > 0.
    pub stable: bool,
    /// Which root.
    pub branch: Branch,
}

/// One point of the backbone (free-oscillation frequency versus amplitude).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BackbonePoint {
    /// Amplitude, m.
    pub amplitude_m: f64,
    /// Nonlinear free-oscillation frequency, Hz.
    pub frequency_hz: f64,
}

/// Saddle-node (jump) points of the forced response.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JumpFrequencies {
    /// Frequency where the lower branch ends and the amplitude jumps up, Hz
    /// (reached by sweeping up when β < 0, down when β > 0).
    pub jump_up_hz: f64,
    /// Amplitude at the jump-up saddle node (before the jump), m.
    pub jump_up_amplitude_m: f64,
    /// Frequency where the upper branch ends and the amplitude jumps down, Hz
    /// (reached by sweeping down when β < 0, up when β > 0).
    pub jump_down_hz: f64,
    /// Amplitude at the jump-down saddle node (before the jump), m.
    pub jump_down_amplitude_m: f64,
}

/// Response of one operating point (used for the voltage and preload families).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResponseCurve {
    /// Operating point.
    pub operating_point: OperatingPoint,
    /// Equivalent cubic coefficient used, N/m³.
    pub equivalent_beta_n_per_m3: f64,
    /// All branches at every requested frequency.
    pub points: Vec<ResponsePoint>,
    /// Saddle-node points, if the response is multivalued.
    pub jumps: Option<JumpFrequencies>,
}

/// Slow-flow coefficients at one drive frequency (all rad/s, force per mass per rad/s).
#[derive(Debug, Clone, Copy)]
struct SlowFlow {
    mu: f64,
    sigma: f64,
    kappa: f64,
    h: f64,
}

fn slow_flow(eff: &EffectiveDuffing, omega: f64, method: ResponseMethod) -> SlowFlow {
    let m = eff.modal_mass_kg;
    let w0 = (eff.stiffness_n_per_m / m).sqrt();
    let mu = eff.damping_ns_per_m / (2.0 * m);
    let (sigma, w_ref) = match method {
        ResponseMethod::MultipleScales => (omega - w0, w0),
        ResponseMethod::HarmonicBalance => ((omega - w0) * (omega + w0) / (2.0 * omega), omega),
    };
    SlowFlow {
        mu,
        sigma,
        kappa: 3.0 * eff.equivalent_beta_n_per_m3 / (8.0 * m * w_ref),
        h: eff.forcing_amplitude_n / (2.0 * m * w_ref),
    }
}

/// Roots x ∈ (0, 1] of p(x) = K²x³ − 2sKx² + (1+s²)x − 1 (dimensionless eq. 12, x = a²μ²/H²,
/// s = σ/μ, K = κH²/μ³), ascending.
fn dimensionless_roots(s: f64, kk: f64) -> Vec<f64> {
    if kk == 0.0 {
        return vec![1.0 / (1.0 + s * s)];
    }
    let p = |x: f64| ((kk * kk * x - 2.0 * s * kk) * x + (1.0 + s * s)) * x - 1.0;
    // Critical points of p.
    let mut knots = vec![0.0];
    let disc = s * s - 3.0;
    if disc > 0.0 {
        let r = kk.abs() * disc.sqrt();
        for c in [(2.0 * s * kk - r) / (3.0 * kk * kk), (2.0 * s * kk + r) / (3.0 * kk * kk)] {
            if c > 0.0 && c < 1.0 {
                knots.push(c);
            }
        }
    }
    knots.push(1.0);
    knots.sort_by(|a, b| a.total_cmp(b));
    let mut roots: Vec<f64> = Vec::with_capacity(3);
    for w in knots.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (pa, pb) = (p(a), p(b));
        if pa == 0.0 && a > 0.0 {
            roots.push(a);
        }
        if (pa < 0.0 && pb > 0.0) || (pa > 0.0 && pb < 0.0) {
            roots.push(bisect(p, a, b, 200));
        }
    }
    if p(1.0) == 0.0 {
        roots.push(1.0);
    }
    roots.sort_by(|a, b| a.total_cmp(b));
    roots.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * b.abs().max(1e-300));
    if roots.is_empty() {
        // p(0) = −1 < 0 ≤ p(1) guarantees a root; keep a safe fallback anyway.
        roots.push(bisect(p, 0.0, 1.0, 200));
    }
    roots
}

fn validate_frequency(frequency_hz: f64) -> HertzResult<f64> {
    check_positive("frequency_hz", frequency_hz)
}

/// Steady-state branches at one frequency for an equivalent Duffing oscillator.
fn response_at(eff: &EffectiveDuffing, frequency_hz: f64, method: ResponseMethod) -> Vec<ResponsePoint> {
    let omega = 2.0 * PI * frequency_hz;
    let sf = slow_flow(eff, omega, method);
    if sf.h == 0.0 {
        return vec![ResponsePoint {
            frequency_hz,
            amplitude_m: 0.0,
            phase_lag_rad: 0.0,
            stable: true,
            branch: Branch::Single,
        }];
    }
    let s = sf.sigma / sf.mu;
    let x_ref = (sf.h / sf.mu).powi(2);
    let kk = sf.kappa * x_ref / sf.mu;
    let roots = dimensionless_roots(s, kk);
    let n = roots.len();
    roots
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let amp = (x * x_ref).sqrt();
            let detuning = sf.sigma - sf.kappa * amp * amp;
            let det = sf.mu * sf.mu + detuning * (sf.sigma - 3.0 * sf.kappa * amp * amp);
            let branch = match (n, i) {
                (3, 0) => Branch::Lower,
                (3, 1) => Branch::Middle,
                (3, _) => Branch::Upper,
                _ => Branch::Single,
            };
            ResponsePoint {
                frequency_hz,
                amplitude_m: amp,
                phase_lag_rad: sf.mu.atan2(-detuning),
                stable: det > 0.0,
                branch,
            }
        })
        .collect()
}

impl HertzOscillator {
    /// Amplitude–frequency response at `op` (the Hertzian driving-circuit paper (2022) eq. 10-12, corrected): every real
    /// amplitude (1 or 3) at each frequency in `frequencies_hz` (Hz, > 0), with slow-flow
    /// stability. Amplitudes in m about the static deflection.
    pub fn frequency_response(
        &self,
        op: &OperatingPoint,
        frequencies_hz: &[f64],
        method: ResponseMethod,
    ) -> HertzResult<Vec<ResponsePoint>> {
        let eff = self.effective(op)?;
        let mut out = Vec::with_capacity(frequencies_hz.len());
        for &f in frequencies_hz {
            validate_frequency(f)?;
            out.extend(response_at(&eff, f, method));
        }
        Ok(out)
    }

    /// Backbone curve (free nonlinear frequency versus amplitude) at `op`: multiple scales
    /// f = f0 + 3β_eq a²/(16π m ω0) (the Hertzian driving-circuit paper (2022) eq. 11-12 with H = 0, μ = 0); harmonic balance
    /// f = √(ω0² + ¾β_eq a²/m)/2π. Amplitudes in m (>= 0). Points where the softening
    /// backbone reaches zero frequency are omitted.
    pub fn backbone(
        &self,
        op: &OperatingPoint,
        amplitudes_m: &[f64],
        method: ResponseMethod,
    ) -> HertzResult<Vec<BackbonePoint>> {
        let eff = self.effective(op)?;
        let m = eff.modal_mass_kg;
        let w0 = (eff.stiffness_n_per_m / m).sqrt();
        let b = eff.equivalent_beta_n_per_m3;
        let mut out = Vec::with_capacity(amplitudes_m.len());
        for &a in amplitudes_m {
            check_non_negative("amplitude_m", a)?;
            let omega = match method {
                ResponseMethod::MultipleScales => w0 + 3.0 * b * a * a / (8.0 * m * w0),
                ResponseMethod::HarmonicBalance => {
                    let w2 = w0 * w0 + 0.75 * b * a * a / m;
                    if w2 > 0.0 {
                        w2.sqrt()
                    } else {
                        -1.0
                    }
                }
            };
            if omega > 0.0 && omega.is_finite() {
                out.push(BackbonePoint { amplitude_m: a, frequency_hz: omega / (2.0 * PI) });
            }
        }
        Ok(out)
    }

    /// Jump (saddle-node) frequencies at `op`, or `None` if the response is single valued.
    ///
    /// Found numerically for either method as the frequencies where the discriminant of
    /// the cubic (in a²) of the Hertzian driving-circuit paper (2022) eq. 12 changes sign (8000-point scan over the band
    /// that can be bistable, plus bisection). A band narrower than the scan step (only
    /// just above the hysteresis threshold |κ|H²/μ³ = 8/(3√3)) is reported as `None`.
    /// For the multiple-scales method the closed form
    /// [`HertzOscillator::jump_frequencies_closed_form`] gives the same points.
    pub fn jump_frequencies(
        &self,
        op: &OperatingPoint,
        method: ResponseMethod,
    ) -> HertzResult<Option<JumpFrequencies>> {
        let eff = self.effective(op)?;
        let m = eff.modal_mass_kg;
        let w0 = (eff.stiffness_n_per_m / m).sqrt();
        let sf0 = slow_flow(&eff, w0, method);
        if sf0.h == 0.0 || sf0.kappa == 0.0 {
            return Ok(None);
        }
        let kk0 = sf0.kappa * (sf0.h / sf0.mu).powi(2) / sf0.mu;
        // Bistable detuning lies within |s| <= max(|K|, 1.5(2|K|)^(1/3)) + 2 (see docs).
        let s_max = kk0.abs().max(1.5 * (2.0 * kk0.abs()).cbrt()) + 2.0;
        let span = 1.5 * s_max * sf0.mu;
        let (lo, hi) = if kk0 < 0.0 { (w0 - span, w0 + 0.2 * span) } else { (w0 - 0.2 * span, w0 + span) };
        let lo = lo.max(1e-6 * w0);
        let disc = |omega: f64| {
            let sf = slow_flow(&eff, omega, method);
            let s = sf.sigma / sf.mu;
            let kk = sf.kappa * (sf.h / sf.mu).powi(2) / sf.mu;
            cubic_discriminant(kk * kk, -2.0 * s * kk, 1.0 + s * s, -1.0)
        };
        let n_scan = 8000;
        let mut crossings = Vec::new();
        let mut prev_w = lo;
        let mut prev_d = disc(lo);
        for i in 1..=n_scan {
            let w = lo + (hi - lo) * (i as f64) / (n_scan as f64);
            let d = disc(w);
            if (prev_d > 0.0) != (d > 0.0) {
                crossings.push(bisect(disc, prev_w, w, 200));
            }
            prev_w = w;
            prev_d = d;
        }
        if crossings.len() < 2 {
            return Ok(None);
        }
        let (w_a, w_b) = (crossings[0], crossings[crossings.len() - 1]);
        let (f_a, f_b) = (w_a / (2.0 * PI), w_b / (2.0 * PI));
        let (a_a, a_b) = (saddle_amplitude(&eff, w_a, method), saddle_amplitude(&eff, w_b, method));
        let jf = if kk0 < 0.0 {
            // Softening: the lower branch ends at the high-frequency saddle node (jump up
            // on an up-sweep), the upper branch at the low-frequency one (jump down).
            JumpFrequencies { jump_up_hz: f_b, jump_up_amplitude_m: a_b, jump_down_hz: f_a, jump_down_amplitude_m: a_a }
        } else {
            JumpFrequencies { jump_up_hz: f_a, jump_up_amplitude_m: a_a, jump_down_hz: f_b, jump_down_amplitude_m: a_b }
        };
        Ok(Some(jf))
    }

    /// Closed-form multiple-scales saddle nodes (the Hertzian driving-circuit paper (2022) eq. 12 with d(σ)/d(a) = 0).
    ///
    /// With u = σ − κa², the saddle-node condition μ² + (σ−κa²)(σ−3κa²) = 0 and eq. 12 give
    /// (μ² + u²)² = 2κH²u, a² = (μ² + u²)/(2κu), σ = u + κa². The quartic has two roots of
    /// the sign of κ when |κ|H²/μ³ > 8/(3√3), else the response is single valued (`None`).
    pub fn jump_frequencies_closed_form(&self, op: &OperatingPoint) -> HertzResult<Option<JumpFrequencies>> {
        let eff = self.effective(op)?;
        let m = eff.modal_mass_kg;
        let w0 = (eff.stiffness_n_per_m / m).sqrt();
        let sf = slow_flow(&eff, w0, ResponseMethod::MultipleScales);
        if sf.h == 0.0 || sf.kappa == 0.0 {
            return Ok(None);
        }
        let kk = sf.kappa * (sf.h / sf.mu).powi(2) / sf.mu;
        let ka = kk.abs();
        // g(v) = (1+v²)² − 2|K|v for v = |u|/μ > 0; minimum where 4v(1+v²) = 2|K|.
        let g = |v: f64| (1.0 + v * v).powi(2) - 2.0 * ka * v;
        let gp = |v: f64| 4.0 * v * (1.0 + v * v) - 2.0 * ka;
        let v_hi_bound = (2.0 * ka).cbrt() + 1.0;
        let v_min = bisect(gp, 0.0, v_hi_bound, 200);
        if g(v_min) >= 0.0 {
            return Ok(None);
        }
        let v1 = bisect(g, 0.0, v_min, 200);
        let v2 = bisect(g, v_min, v_hi_bound, 200);
        let sign = kk.signum();
        let point = |v: f64| {
            let u = sign * v;
            let x = (1.0 + u * u) / (2.0 * kk * u); // dimensionless a²·μ²/H²
            let s = u + kk * x;
            let omega = w0 + s * sf.mu;
            let amp = (x * (sf.h / sf.mu).powi(2)).sqrt();
            (omega / (2.0 * PI), amp)
        };
        // Small |u|: large amplitude (peak, upper branch end); large |u|: lower branch end.
        let (f_upper_end, a_upper_end) = point(v1);
        let (f_lower_end, a_lower_end) = point(v2);
        Ok(Some(JumpFrequencies {
            jump_up_hz: f_lower_end,
            jump_up_amplitude_m: a_lower_end,
            jump_down_hz: f_upper_end,
            jump_down_amplitude_m: a_upper_end,
        }))
    }

    /// Response curves for several voltage amplitudes `voltages_v` (V, >= 0) at a fixed
    /// preload `preload_n` (N, >= 0): the Hertzian driving-circuit paper (2022) Fig. 11a, eq. 12 with β(N, V).
    pub fn response_vs_voltage(
        &self,
        preload_n: f64,
        voltages_v: &[f64],
        frequencies_hz: &[f64],
        method: ResponseMethod,
    ) -> HertzResult<Vec<ResponseCurve>> {
        voltages_v
            .iter()
            .map(|&v| self.response_curve(&OperatingPoint { voltage_v: v, preload_n }, frequencies_hz, method))
            .collect()
    }

    /// Response curves for several preloads `preloads_n` (N, >= 0) at a fixed voltage
    /// amplitude `voltage_v` (V, >= 0): the Hertzian driving-circuit paper (2022) Fig. 11b, eq. 12 with β(N, V).
    pub fn response_vs_preload(
        &self,
        voltage_v: f64,
        preloads_n: &[f64],
        frequencies_hz: &[f64],
        method: ResponseMethod,
    ) -> HertzResult<Vec<ResponseCurve>> {
        preloads_n
            .iter()
            .map(|&n| self.response_curve(&OperatingPoint { voltage_v, preload_n: n }, frequencies_hz, method))
            .collect()
    }

    /// One [`ResponseCurve`]: branches, equivalent β and jump points at `op`
    /// (the Hertzian driving-circuit paper (2022) eq. 10-12). Frequencies in Hz (> 0).
    pub fn response_curve(
        &self,
        op: &OperatingPoint,
        frequencies_hz: &[f64],
        method: ResponseMethod,
    ) -> HertzResult<ResponseCurve> {
        let eff = self.effective(op)?;
        Ok(ResponseCurve {
            operating_point: *op,
            equivalent_beta_n_per_m3: eff.equivalent_beta_n_per_m3,
            points: self.frequency_response(op, frequencies_hz, method)?,
            jumps: self.jump_frequencies(op, method)?,
        })
    }
}

/// One curve of [`HertzOscillator::response_family`]: the response (or why there is none,
/// e.g. [`HertzError::NoStaticEquilibrium`]) and its backbone up to 1.2 × the largest
/// amplitude of the curve (101 points, starting at the linear resonance).
#[derive(Debug, Clone, PartialEq)]
pub struct FamilyCurve {
    /// Operating point.
    pub operating_point: OperatingPoint,
    /// Branches and jumps, or the reason the operating point has no response.
    pub response: HertzResult<ResponseCurve>,
    /// Backbone (empty when `response` is an error).
    pub backbone: Vec<BackbonePoint>,
}

impl HertzOscillator {
    /// A frequency band holding every linear resonance and backbone peak (at the linear peak
    /// amplitude F/(c·ω0)) of `ops`, with 30 % of its width plus ten damping bandwidths
    /// c/(2πm) of margin on each side, in Hz; `None` if no point has a static equilibrium.
    pub fn response_band_hz(&self, ops: &[OperatingPoint], method: ResponseMethod) -> Option<(f64, f64)> {
        let (mut lo, mut hi, mut bw) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for op in ops {
            let Ok(eff) = self.effective(op) else { continue };
            let f0 = eff.linear_resonance_hz();
            let peak_amp = eff.forcing_amplitude_n / (eff.damping_ns_per_m * 2.0 * PI * f0);
            let f_peak = self.backbone(op, &[peak_amp], method).ok().and_then(|b| b.first().map(|p| p.frequency_hz));
            for f in [Some(f0), f_peak].into_iter().flatten() {
                lo = lo.min(f);
                hi = hi.max(f);
            }
            bw = bw.max(eff.damping_ns_per_m / (2.0 * PI * eff.modal_mass_kg));
        }
        if !lo.is_finite() {
            return None;
        }
        let margin = 0.3 * (hi - lo) + 10.0 * bw;
        Some(((lo - margin).max(0.5 * lo), hi + margin))
    }

    /// Response curves with backbones for every operating point of `ops` (the Hertzian driving-circuit paper (2022)
    /// Fig. 11, eq. 10-12). A point without a response is kept with its error; invalid
    /// frequencies are an error of the whole family.
    pub fn response_family(
        &self,
        ops: &[OperatingPoint],
        frequencies_hz: &[f64],
        method: ResponseMethod,
    ) -> HertzResult<Vec<FamilyCurve>> {
        for &f in frequencies_hz {
            validate_frequency(f)?;
        }
        Ok(ops
            .iter()
            .map(|op| {
                let response = self.response_curve(op, frequencies_hz, method);
                let backbone = match &response {
                    Ok(c) => {
                        let top = 1.2 * c.points.iter().map(|p| p.amplitude_m).fold(0.0, f64::max);
                        let amps: Vec<f64> = (0..=100).map(|i| top * i as f64 / 100.0).collect();
                        self.backbone(op, &amps, method).unwrap_or_default()
                    }
                    Err(_) => Vec::new(),
                };
                FamilyCurve { operating_point: *op, response, backbone }
            })
            .collect())
    }
}

/// Amplitude at a saddle node: the double root of the cubic p(x) is the critical point of p
/// (p = p' = 0) with the smaller |p|; falls back to the largest root if none is found.
fn saddle_amplitude(eff: &EffectiveDuffing, omega: f64, method: ResponseMethod) -> f64 {
    let sf = slow_flow(eff, omega, method);
    let s = sf.sigma / sf.mu;
    let x_ref = (sf.h / sf.mu).powi(2);
    let kk = sf.kappa * x_ref / sf.mu;
    let disc = s * s - 3.0;
    let fallback = || response_at(eff, omega / (2.0 * PI), method).iter().map(|p| p.amplitude_m).fold(0.0, f64::max);
    if disc < 0.0 || kk == 0.0 {
        return fallback();
    }
    let r = kk.abs() * disc.sqrt();
    let c1 = (2.0 * s * kk - r) / (3.0 * kk * kk);
    let c2 = (2.0 * s * kk + r) / (3.0 * kk * kk);
    let p = |x: f64| ((kk * kk * x - 2.0 * s * kk) * x + (1.0 + s * s)) * x - 1.0;
    let x = if p(c1).abs() < p(c2).abs() { c1 } else { c2 };
    if x > 0.0 {
        (x * x_ref).sqrt()
    } else {
        fallback()
    }
}

/// Discriminant of a·x³ + b·x² + c·x + d (> 0: three distinct real roots).
fn cubic_discriminant(a: f64, b: f64, c: f64, d: f64) -> f64 {
    18.0 * a * b * c * d - 4.0 * b * b * b * d + b * b * c * c - 4.0 * a * c * c * c - 27.0 * a * a * d * d
}

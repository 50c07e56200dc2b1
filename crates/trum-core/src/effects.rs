//! The library of named, switchable unmodelled effects (names fixed by
//! the diagnosis document, docs/DIAGNOSIS_JSON.md). Like PyBaMM's model options: an explicit set of named
//! effects, each with one to three strength parameters in physical units and shape
//! parameters that choose among its forms, `none` by default, validated with errors that
//! list the valid names.
//!
//! This module holds the registry and the switch; the physics of each effect lives next
//! to the part of the model it changes and is applied by [`crate::solve`].

use crate::error::ParamError;
use crate::toml_text::{fmt_toml_number, line_of_key, Num};
use std::fmt;

/// One strength parameter of an effect.
#[derive(Clone, Copy, Debug)]
pub struct EffectParam {
    /// Parameter name with unit suffix.
    pub name: &'static str,
    /// Meaning and unit.
    pub doc: &'static str,
    /// A typical "clearly present" value (used by `trum synth` examples and docs).
    pub typical: f64,
    /// Smallest valid value.
    pub min: f64,
    /// Largest valid value.
    pub max: f64,
    /// A shape parameter, not a strength: `NAME=STRENGTH` and a motor-file table that
    /// leaves it out keep its typical value, and the diagnosis fits it over its whole range
    /// from the middle (and probes it there).
    pub shape: bool,
    /// A shape parameter the local fits hold where their start puts it (its typical value,
    /// the candidate's plainest form, or the level the scan found): the diagnosis's scan of
    /// the effect's range tries it at [`EffectParam::levels`] (docs/DIAGNOSIS.md, "Fits
    /// that search"). False for strengths and for shape parameters the fits free.
    pub held: bool,
    /// The values of a held shape parameter the scan tries besides its typical value (the
    /// scan derives `voltage_sag`'s knee current from the data instead).
    pub levels: &'static [f64],
}

impl EffectParam {
    /// Where a fit or a sensitivity probe places a further (non-primary) parameter: its
    /// typical value, or the middle of its range for a shape parameter the fits free (whose
    /// typical value may sit on a bound, where a fit's transformed gradient vanishes).
    pub fn start(&self) -> f64 {
        if self.shape && !self.held {
            0.5 * (self.min + self.max)
        } else {
            self.typical
        }
    }
}

/// Registry entry of one effect.
#[derive(Clone, Copy, Debug)]
pub struct EffectInfo {
    /// The effect's fixed name.
    pub name: &'static str,
    /// What it changes.
    pub summary: &'static str,
    /// Where its physics comes from.
    pub source: &'static str,
    /// Its strength parameters; the first is the primary one (`NAME=STRENGTH`).
    pub params: &'static [EffectParam],
    /// Where a fit that adds the effect to a calibrated model starts its primary strength,
    /// as a fraction of its typical value (the diagnosis; docs/DIAGNOSIS.md, step 4).
    pub fit_start: f64,
}

/// Index of an effect in [`EFFECTS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)]
pub enum Effect {
    RadialFriction = 0,
    PreloadStiffening = 1,
    HertzSoftening = 2,
    ThermalDrift = 3,
    VoltageSag = 4,
    Eccentricity = 5,
    TangentialCompliance = 6,
}

/// Number of effects in the registry.
pub const N_EFFECTS: usize = 7;

/// Most parameters an effect has (`thermal_drift`: stiffness, damping and friction
/// coefficients and the interface node's share).
pub const MAX_PARAMS: usize = 4;

/// All effects, in the order of [`Effect`].
pub const ALL: [Effect; N_EFFECTS] = [
    Effect::RadialFriction,
    Effect::PreloadStiffening,
    Effect::HertzSoftening,
    Effect::ThermalDrift,
    Effect::VoltageSag,
    Effect::Eccentricity,
    Effect::TangentialCompliance,
];

/// The registry, indexed by [`Effect`].
pub const EFFECTS: [EffectInfo; N_EFFECTS] = [
    EffectInfo {
        name: "radial_friction",
        summary: "stator surface points also slip radially; friction acts along the total slip, \
                  driving force drops and radial slip dissipates power",
        source: "the radial-friction paper (radial friction in the contact mechanism), eq. 19-21 and 27",
        params: &[
            EffectParam {
                name: "radial_velocity_ratio",
                doc: "peak radial surface speed over peak tangential surface speed [-]",
                typical: 1.0,
                min: 0.0,
                max: 3.0,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "preload_exponent",
                doc: "growth of the radial-speed ratio with the preload [-]: rho·(F_N/100 N)^q, \
                      rho then the ratio at 100 N; 0 a ratio the preload does not change, 0.5 \
                      one that follows the contact width of a Hertzian line contact",
                typical: 0.0,
                min: 0.0,
                max: 1.5,
                shape: true,
                held: true,
                levels: &[0.5, 1.0],
            },
        ],
        fit_start: 0.5,
    },
    EffectInfo {
        name: "preload_stiffening",
        summary: "the pressed friction layer adds stiffness to the stator mode: resonance moves up \
                  and amplitude changes with preload",
        source: "Sun et al. 2021 eq. 8 and 14; the radial-friction paper section 5.3",
        params: &[
            EffectParam {
                name: "stiffness_scale",
                doc: "multiplier of the contact stiffness added to the mode [-]",
                typical: 0.05,
                min: 0.0,
                max: 5.0,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "modal_fraction",
                doc: "how the pressure becomes modal stiffness [-]: 0 the axial force over the \
                      amplitude (Sun et al. 2021 eq. 8), 1 its projection on the mode shape \
                      (the radial-friction paper, section 5.3), between a blend of the two",
                typical: 0.0,
                min: 0.0,
                max: 1.0,
                shape: true,
                held: false,
                levels: &[],
            },
        ],
        fit_start: 0.5,
    },
    EffectInfo {
        name: "hertz_softening",
        summary: "softening cubic restoring force at high amplitude: resonance shifts down with \
                  amplitude, changing with preload",
        source: "the Hertzian driving-circuit paper (2022) eq. 2-4 and 10-12",
        params: &[
            EffectParam {
                name: "beta_n_per_m3",
                doc: "softening cubic stiffness coefficient at zero preload [N/m^3]",
                typical: 1.0e18,
                min: 0.0,
                max: 1.0e23,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "preload_gain_per_n",
                doc: "relative growth of the cubic coefficient per newton of preload [1/N]",
                typical: 0.004,
                min: 0.0,
                max: 1.0,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "preload_exponent",
                doc: "exponent n of the preload dependence of the cubic coefficient [-]: \
                      2·beta·((1 + g·F_N)/2)^n, which meets the candidate's beta·(1 + g·F_N) \
                      where g·F_N = 1; 1 linear growth, 1.5 the growth of a Hertzian \
                      contact's stiffness with its load, -1 the cubic term of a Hertzian \
                      contact expanded about its preloaded compression (falls as 1/F_N)",
                typical: 1.0,
                min: -1.0,
                max: 3.0,
                shape: true,
                held: true,
                levels: &[-1.0, 0.5, 1.5, 2.0],
            },
        ],
        fit_start: 0.5,
    },
    EffectInfo {
        name: "thermal_drift",
        summary: "losses heat the stator over a run; modal stiffness, modal damping and friction \
                  change with temperature, so speed drifts",
        source: "Chen et al. 2020 eq. 11 and section 4.2",
        params: &[
            EffectParam {
                name: "stiffness_coefficient_per_k",
                doc: "relative change of modal stiffness per kelvin of temperature rise [1/K] \
                      (negative: softening)",
                typical: -4.0e-4,
                min: -0.05,
                max: 0.05,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "friction_coefficient_per_k",
                doc: "relative change of the friction coefficient per kelvin [1/K]",
                typical: -2.0e-3,
                min: -0.05,
                max: 0.05,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "damping_coefficient_per_k",
                doc: "relative change of the modal damping per kelvin [1/K] (positive: the \
                      piezoceramic's mechanical quality factor falls as it warms)",
                typical: 2.0e-3,
                min: -0.05,
                max: 0.05,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "interface_fraction",
                doc: "share of the temperature rise carried by a fast node at the friction \
                      interface, with a tenth of the lumped time constant [-]: 0 one lumped \
                      capacity (Chen et al. 2020 eq. 11)",
                typical: 0.0,
                min: 0.0,
                max: 0.9,
                shape: true,
                held: true,
                levels: &[0.4, 0.8],
            },
        ],
        fit_start: 0.5,
    },
    EffectInfo {
        name: "voltage_sag",
        summary: "the driver cannot hold the set voltage: the electrode voltage falls with the \
                  load current through the driver's output impedance",
        source: "Sun et al. 2021 section 3.1",
        params: &[
            EffectParam {
                name: "source_resistance_ohm",
                doc: "output resistance of the drive electronics per phase [ohm] (with a knee: \
                      acting on the current above it)",
                typical: 150.0,
                min: 0.0,
                max: 1.0e5,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "knee_current_a",
                doc: "current amplitude per phase up to which the driver holds its set voltage \
                      [A]: a current-limited driver sags only with the current above it; 0 a \
                      plain resistive source",
                typical: 0.0,
                min: 0.0,
                max: 100.0,
                shape: true,
                held: true,
                levels: &[],
            },
        ],
        fit_start: 0.5,
    },
    EffectInfo {
        name: "eccentricity",
        summary: "assembly error makes the preload vary once per revolution; contact angle and \
                  speed fluctuate and the mean speed shifts",
        source: "Chen et al. 2020 section 4.3 and eq. 12",
        params: &[
            EffectParam {
                name: "runout_m",
                doc: "once-per-revolution axial runout of the rotor [m] (the peak of the whole \
                      ripple where it has harmonics)",
                typical: 20.0e-6,
                min: 0.0,
                max: 1.0e-3,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "second_harmonic_fraction",
                doc: "amplitude of a twice-per-revolution ripple relative to the \
                      once-per-revolution one [-]: a tilted rotor face",
                typical: 0.0,
                min: 0.0,
                max: 1.0,
                shape: true,
                held: true,
                levels: &[0.3, 0.7],
            },
            EffectParam {
                name: "third_harmonic_fraction",
                doc: "amplitude of a three-times-per-revolution ripple relative to the \
                      once-per-revolution one [-]: a three-lobed rotor or a three-point mount",
                typical: 0.0,
                min: 0.0,
                max: 1.0,
                shape: true,
                held: true,
                levels: &[0.3, 0.7],
            },
        ],
        fit_start: 0.5,
    },
    EffectInfo {
        name: "tangential_compliance",
        summary: "shear compliance of the friction layer: partial stick inside the contact and a \
                  smooth speed-torque curve instead of a sharp stall",
        source: "the bar-type transient paper eq. 1-2; Storck and Wallaschek, Int. J. Non-Linear Mech. 38 (2003)",
        params: &[
            EffectParam {
                name: "shear_compliance_ratio",
                doc: "ratio of tangential to normal compliance of the friction layer [-]",
                typical: 1.0,
                min: 0.0,
                max: 20.0,
                shape: false,
                held: false,
                levels: &[],
            },
            EffectParam {
                name: "stick_sharpness",
                doc: "sharpness n of the layer's turn from stick to slip [-]: traction \
                      tanh(x^n)^(1/n) at slip speed x over its scale; 1 the smooth saturation, \
                      large n an elastic layer that sticks (traction in proportion to its \
                      shear) and then slips at full friction",
                typical: 1.0,
                min: 1.0,
                max: 4.0,
                shape: true,
                held: true,
                levels: &[2.0, 4.0],
            },
        ],
        // Weak: from half its typical strength a fit can stick in a basin beyond a barrier
        // from zero, neither fitting the data nor reaching the baseline it nests (on the
        // 1000-row radial-friction benchmark at twice the baseline's χ², 140 passes, 6 of
        // its 16 CPU-s; from 0.05 it collapses onto the baseline in 7). The blind
        // benchmark, tangential_compliance cases at 0.3 and 1 × typical included, gives the
        // same verdicts, confounded sets and shrinks from 0.03, 0.05 and 0.1 as from 0.5.
        fit_start: 0.05,
    },
];

impl EffectInfo {
    /// Parameter values with the primary at `primary` and the others where fits and probes
    /// place them ([`EffectParam::start`]).
    pub fn with_primary(&self, primary: f64) -> Vec<f64> {
        self.params.iter().enumerate().map(|(i, p)| if i == 0 { primary } else { p.start() }).collect()
    }
}

impl Effect {
    /// The effect's fixed name.
    pub fn name(self) -> &'static str {
        EFFECTS[self as usize].name
    }
    /// Registry entry.
    pub fn info(self) -> &'static EffectInfo {
        &EFFECTS[self as usize]
    }
    /// Looks up an effect by name; the error lists the valid names.
    pub fn from_name(name: &str) -> Result<Effect, String> {
        ALL.iter()
            .copied()
            .find(|e| e.name() == name)
            .ok_or_else(|| format!("unknown effect '{name}'; valid effects are: {}", valid_names()))
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Comma-separated list of valid effect names.
pub fn valid_names() -> String {
    EFFECTS.iter().map(|e| e.name).collect::<Vec<_>>().join(", ")
}

/// The set of switched-on effects with their parameters. `Effects::none()` is the
/// baseline model. An effect whose parameters are all zero is switched on but changes
/// nothing (tests check that it reproduces the baseline exactly).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Effects {
    on: [bool; N_EFFECTS],
    values: [[f64; MAX_PARAMS]; N_EFFECTS],
    /// Per effect (registry order): its bench-truth form instead of its candidate form.
    truth: [bool; N_EFFECTS],
    /// For the effects in truth form: the second family of bench-truth forms
    /// (docs/EFFECTS.md), held out of every tuning of the diagnosis.
    truth_b: bool,
    instrument: Instrument,
}

/// The bench's own instrument artefacts, which calibration and the diagnosis estimate as
/// nuisance parameters beside the motor's (docs/DIAGNOSIS.md, "The bench model"). They
/// change what a reading shows, never the motor's state, and are never reported as an
/// effect of the motor. Zero by default; not part of a motor file.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Instrument {
    /// Noise floor of the speed-stability reading [rpm]: the instrument reads
    /// √(true² + floor²) of a speed standard deviation.
    pub speed_std_floor_rpm: f64,
    /// Zero offset of the torque transducer [N·m]: a row's torque column reads the load
    /// the rotor carries plus this offset. A transducer's zero drifts with temperature and
    /// mounting by a fraction of a percent of its full scale, which on a steep
    /// speed-torque line is a speed error of the order of the readings' own noise.
    pub torque_offset_nm: f64,
    /// Offset of the stator temperature reading [K]: the sensor shows the stator's
    /// temperature plus this. A thermocouple or a resistance thermometer read against an
    /// ambient sensor elsewhere is off by up to about 1.5 K (a class-1 thermocouple's
    /// tolerance, IEC 60584-1), which on a warm-up of a few kelvin is a gap far beyond a
    /// reading's noise.
    pub temperature_offset_k: f64,
    /// Time constant of the stator temperature sensor [s]: a first-order sensor lags the
    /// stator's warm-up ([`crate::thermal::sensor_rise_k`]). 0: it follows at once.
    pub temperature_lag_s: f64,
    /// Zero offset of the preload reading [N]: a row's preload column reads the axial force
    /// on the contact plus this. The load cell's zero, and the friction of the axial guide
    /// between the cell and the rotor, put the force the contact carries a few newtons off
    /// the reading.
    pub preload_offset_n: f64,
    /// Relative gain error of the current reading (-): the instrument shows the phase
    /// current times (1 + this). A current probe or shunt amplifier is good to 1-3 % of its
    /// reading.
    pub current_gain_rel: f64,
    /// Phase error of the power reading [rad]: the meter's current channel lags its voltage
    /// channel by this angle (a probe's delay τ is an angle ω·τ), so it shows
    /// P·cos δ + Q·sin δ of the active power P and the reactive power Q. A piezoelectric
    /// stator is a capacitive load of low power factor (0.05-0.6), so a degree of phase
    /// error, which an unmatched current probe shows at tens of kilohertz, moves the power
    /// reading by a large part of itself; at one drive setting it is nearly a constant zero
    /// offset. The model keeps the clamped capacitance's part of Q
    /// ([`Instrument::power_reading_w`]). The efficiency reading, computed from the same
    /// meter, follows it.
    pub power_phase_rad: f64,
}

impl Instrument {
    /// The operating point the motor ran at when a row's set points read `op`: the load
    /// torque is the reading less the transducer's zero offset, never below zero (a
    /// reading within the offset of zero is an unloaded rotor); the preload is the reading
    /// less the load cell's offset (the fit's bounds keep it positive).
    pub fn operating_point(&self, op: &crate::OperatingPoint) -> crate::OperatingPoint {
        if self.torque_offset_nm == 0.0 && self.preload_offset_n == 0.0 {
            return *op;
        }
        crate::OperatingPoint {
            torque_nm: (op.torque_nm - self.torque_offset_nm).max(0.0),
            preload_n: op.preload_n - self.preload_offset_n,
            ..*op
        }
    }

    /// What the power meter shows of the input power of solution `s` [W]: a current channel
    /// lagging by δ = [`Instrument::power_phase_rad`] reads V·I·cos(φ − δ) = P·cos δ + Q·sin δ
    /// of the active power P and the reactive power Q of both phases (Q > 0 for a leading,
    /// capacitive current). Of Q the model keeps the clamped capacitance's part Q_c = ω·C0·V²
    /// ([`crate::Solution::capacitive_reactive_power_var`]) and leaves out the motional
    /// branch's, δ·Q_m: at one drive setting Q_c is the constant offset that a phase error
    /// puts on the power reading, while δ·Q_m, which follows the amplitude and the detuning,
    /// is a second power term that a fit can trade against the loss tangent (δ and tan δ move
    /// Q_c's and the dielectric loss's shares alike) to follow what an effect does to the
    /// input power. Where the motional branch cancels much of Q_c (a stator driven just
    /// above its resonance) the fitted δ is an equivalent angle, δ·Q/Q_c of the meter's
    /// (docs/DIAGNOSIS.md, "The bench model"). P itself at δ = 0; valid for |δ| up to a
    /// few degrees.
    pub fn power_reading_w(&self, s: &crate::Solution) -> f64 {
        if self.power_phase_rad == 0.0 {
            return s.input_power_w;
        }
        let (sin, cos) = self.power_phase_rad.sin_cos();
        s.input_power_w * cos + s.capacitive_reactive_power_var() * sin
    }

    /// What the bench's efficiency reading shows for solution `s`: the output power over
    /// the power meter's reading ([`Instrument::power_reading_w`]), within [0, 1] as the
    /// model's own efficiency; that efficiency itself at δ = 0.
    pub fn efficiency_reading(&self, s: &crate::Solution) -> f64 {
        if self.power_phase_rad == 0.0 {
            return s.efficiency;
        }
        crate::losses::efficiency(s.output_power_w, self.power_reading_w(s))
    }

    /// What the instrument shows of quantity `o` when the motor's value is `model`.
    pub fn reading(&self, o: crate::observable::Observable, model: f64) -> f64 {
        match o {
            crate::observable::Observable::SpeedStdRpm if self.speed_std_floor_rpm > 0.0 => {
                model.hypot(self.speed_std_floor_rpm)
            }
            crate::observable::Observable::TemperatureC => model + self.temperature_offset_k,
            crate::observable::Observable::CurrentA => model * (1.0 + self.current_gain_rel),
            _ => model,
        }
    }
}

impl Effects {
    /// No effects: the baseline model.
    pub fn none() -> Effects {
        Effects::default()
    }

    /// Use the bench-truth forms of every effect (different in form from the candidate
    /// forms that calibration and diagnosis fit; see docs/EFFECTS.md), or none. `trum synth`
    /// uses them for the effects it adds so a diagnosis cannot pass by recognising its own
    /// formulas.
    pub fn set_truth_forms(&mut self, on: bool) {
        self.truth = [on; N_EFFECTS];
        self.truth_b &= on;
    }

    /// Use the second family of bench-truth forms (`true`) or the first (`false`) for every
    /// effect; either switches the truth forms of every effect on. The second family differs
    /// in form from the first and from every candidate; the blind benchmark keeps it, and
    /// its artefacts, out of every tuning of the diagnosis (docs/DIAGNOSIS.md).
    pub fn set_truth_form_b(&mut self, on: bool) {
        self.truth = [true; N_EFFECTS];
        self.truth_b = on;
    }

    /// Use effect `e`'s bench-truth form (`true`, of the family the others' truth forms
    /// use: [`Effects::set_truth_form_b`]) or its candidate form (`false`), whether or not
    /// it is switched on; the other effects keep theirs.
    pub fn set_truth_form(&mut self, e: Effect, on: bool) {
        self.truth[e as usize] = on;
    }

    /// True when effect `e` takes a bench-truth form (either family).
    #[inline]
    pub fn is_truth_form(&self, e: Effect) -> bool {
        self.truth[e as usize]
    }

    /// True when effect `e` takes the second family of bench-truth forms.
    #[inline]
    pub fn is_truth_form_b(&self, e: Effect) -> bool {
        self.truth[e as usize] && self.truth_b
    }

    /// True when every effect takes the second family of bench-truth forms.
    pub fn truth_form_b(&self) -> bool {
        self.truth_forms() && self.truth_b
    }

    /// The bench's instrument artefacts (nuisance parameters of a fit).
    pub fn instrument(&self) -> &Instrument {
        &self.instrument
    }

    /// Mutable access to the instrument artefacts.
    pub fn instrument_mut(&mut self) -> &mut Instrument {
        &mut self.instrument
    }

    /// True when every effect takes its bench-truth form.
    pub fn truth_forms(&self) -> bool {
        self.truth.iter().all(|&t| t)
    }

    /// True when no effect is switched on.
    pub fn is_none(&self) -> bool {
        !self.on.iter().any(|&b| b)
    }

    /// Switches an effect on with all its parameters (missing ones are 0, a missing held
    /// shape parameter its typical value: the candidate's plainest form).
    pub fn set(&mut self, e: Effect, params: &[f64]) {
        self.on[e as usize] = true;
        let mut v = [0.0; MAX_PARAMS];
        for (slot, p) in v.iter_mut().zip(e.info().params).filter(|(_, p)| p.held) {
            *slot = p.typical;
        }
        for (slot, p) in v.iter_mut().zip(params) {
            *slot = *p;
        }
        self.values[e as usize] = v;
    }

    /// Switches an effect on with its primary parameter, the others at their typical value.
    pub fn set_strength(&mut self, e: Effect, strength: f64) {
        let info = e.info();
        let mut v = [0.0; MAX_PARAMS];
        for (i, p) in info.params.iter().enumerate() {
            v[i] = if i == 0 { strength } else { p.typical };
        }
        self.set(e, &v[..info.params.len()]);
    }

    /// Switches an effect off.
    pub fn clear(&mut self, e: Effect) {
        self.on[e as usize] = false;
        self.values[e as usize] = [0.0; MAX_PARAMS];
    }

    /// True when the effect is switched on.
    pub fn is_on(&self, e: Effect) -> bool {
        self.on[e as usize]
    }

    /// Parameters of an effect if switched on.
    pub fn get(&self, e: Effect) -> Option<&[f64]> {
        self.on[e as usize].then(|| &self.values[e as usize][..e.info().params.len()])
    }

    /// Parameter `i` of an effect, 0 when the effect is off.
    #[inline]
    pub fn value(&self, e: Effect, i: usize) -> f64 {
        if self.on[e as usize] {
            self.values[e as usize][i]
        } else {
            0.0
        }
    }

    /// Mutable parameter slot (for calibration of effect strengths).
    pub fn value_mut(&mut self, e: Effect, i: usize) -> &mut f64 {
        self.on[e as usize] = true;
        &mut self.values[e as usize][i]
    }

    /// Switched-on effects in registry order.
    pub fn active(&self) -> Vec<Effect> {
        ALL.iter().copied().filter(|e| self.is_on(*e)).collect()
    }

    /// Parses `NAME=STRENGTH` or `NAME:param=value,param=value` (CLI form).
    pub fn parse_assignment(&mut self, spec: &str) -> Result<(), String> {
        let spec = spec.trim();
        if spec == "none" {
            *self = Effects::none();
            return Ok(());
        }
        if let Some((name, rest)) = spec.split_once(':') {
            let e = Effect::from_name(name.trim())?;
            let info = e.info();
            let mut v: Vec<f64> = info.params.iter().map(|p| p.typical).collect();
            for kv in rest.split(',') {
                let (k, val) = kv.split_once('=').ok_or_else(|| format!("effect '{spec}': expected param=value"))?;
                let idx = info.params.iter().position(|p| p.name == k.trim()).ok_or_else(|| {
                    format!(
                        "effect '{}' has no parameter '{}'; its parameters are: {}",
                        e,
                        k.trim(),
                        info.params.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
                    )
                })?;
                v[idx] =
                    val.trim().parse().map_err(|_| format!("effect '{spec}': '{}' is not a number", val.trim()))?;
            }
            self.set(e, &v);
        } else {
            let (name, val) = spec.split_once('=').ok_or_else(|| {
                format!("effect '{spec}': expected NAME=STRENGTH; valid effects are: {}", valid_names())
            })?;
            let e = Effect::from_name(name.trim())?;
            let s: f64 =
                val.trim().parse().map_err(|_| format!("effect '{spec}': '{}' is not a number", val.trim()))?;
            self.set_strength(e, s);
        }
        self.check().map_err(|(_, m)| m)
    }

    fn check(&self) -> Result<(), (String, String)> {
        for e in self.active() {
            for (p, v) in e.info().params.iter().zip(self.values[e as usize]) {
                if !v.is_finite() || v < p.min || v > p.max {
                    return Err((
                        format!("effects.{}.{}", e.name(), p.name),
                        format!("{v} is outside the valid range [{}, {}] ({})", p.min, p.max, p.doc),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Validates parameter ranges; errors name the key and, with `text`, the line.
    pub fn validate(&self, source_name: &str, text: Option<&str>) -> Result<(), ParamError> {
        self.check().map_err(|(key, reason)| {
            let name = key.split('.').nth(1).unwrap_or("");
            ParamError {
                source_name: source_name.into(),
                line: text.and_then(|t| line_of_key(t, "effects", name)),
                key,
                reason,
            }
        })
    }

    /// Reads the `[effects]` table of a motor file: `name = STRENGTH`,
    /// `name = { param = value }` or a `[effects.name]` table; `name = "none"` or an
    /// empty table switches everything off.
    pub(crate) fn from_toml_table(t: &toml::Table, text: &str, source_name: &str) -> Result<Effects, ParamError> {
        let mut fx = Effects::none();
        for (name, val) in t {
            if name == "form" {
                match val.as_str() {
                    Some("truth") => fx.set_truth_form_b(false),
                    Some("truth-b") => fx.set_truth_form_b(true),
                    Some("candidate") => fx.set_truth_forms(false),
                    _ => {
                        return Err(ParamError {
                            source_name: source_name.into(),
                            line: line_of_key(text, "effects", "form"),
                            key: "effects.form".into(),
                            reason: "must be \"candidate\", \"truth\" or \"truth-b\"".into(),
                        })
                    }
                }
                continue;
            }
            let err = |reason: String, key: String| ParamError {
                source_name: source_name.into(),
                line: line_of_key(text, "effects", name),
                key,
                reason,
            };
            let e = Effect::from_name(name).map_err(|m| err(m, format!("effects.{name}")))?;
            let info = e.info();
            match val {
                toml::Value::Integer(_) | toml::Value::Float(_) => {
                    let v = num(val).unwrap_or(f64::NAN);
                    fx.set_strength(e, v);
                }
                toml::Value::Table(tab) => {
                    let mut v: Vec<f64> = vec![0.0; info.params.len()];
                    let mut seen = vec![false; info.params.len()];
                    for (k, x) in tab {
                        let idx = info.params.iter().position(|p| p.name == k).ok_or_else(|| {
                            err(
                                format!(
                                    "unknown parameter '{k}'; parameters of '{name}' are: {}",
                                    info.params.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
                                ),
                                format!("effects.{name}.{k}"),
                            )
                        })?;
                        v[idx] =
                            num(x).ok_or_else(|| err("expected a number".into(), format!("effects.{name}.{k}")))?;
                        seen[idx] = true;
                    }
                    // a shape parameter left out keeps its typical value (files written before
                    // `preload_stiffening` had one stay valid, with Sun et al. 2021 eq. 8); a strength
                    // left out is an error
                    for ((p, x), s) in info.params.iter().zip(v.iter_mut()).zip(seen.iter_mut()) {
                        if p.shape && !*s {
                            (*x, *s) = (p.typical, true);
                        }
                    }
                    if let Some(i) = seen.iter().position(|s| !s) {
                        return Err(err(
                            format!("missing parameter '{}' ({})", info.params[i].name, info.params[i].doc),
                            format!("effects.{name}"),
                        ));
                    }
                    fx.set(e, &v);
                }
                _ => {
                    return Err(err(
                        "expected a number (the strength) or a table of parameters".into(),
                        format!("effects.{name}"),
                    ))
                }
            }
        }
        fx.validate(source_name, Some(text))?;
        Ok(fx)
    }

    /// `[effects]` section in TOML (empty string when none is on).
    pub fn to_toml(&self) -> String {
        // the `form` key sets every effect's form: a mix (synthetic data's true motor) is
        // written as the forms of its switched-on effects when they agree, else candidate
        let active = self.active();
        let truth = if active.is_empty() { self.truth_forms() } else { active.iter().all(|&e| self.is_truth_form(e)) };
        let form = match (truth, self.truth_b) {
            (true, true) => "form = \"truth-b\"\n",
            (true, false) => "form = \"truth\"\n",
            _ => "",
        };
        if self.is_none() {
            return format!("\n[effects]  # none switched on; see `trum effects`\n{form}");
        }
        let mut s = String::from("\n[effects]\n");
        s.push_str(form);
        for e in self.active() {
            let parts: Vec<String> = e
                .info()
                .params
                .iter()
                .zip(self.values[e as usize])
                .filter(|(p, v)| written(p, *v))
                .map(|(p, v)| format!("{} = {}", p.name, fmt_toml_number(v, false)))
                .collect();
            s.push_str(&format!("{} = {{ {} }}\n", e.name(), parts.join(", ")));
        }
        s
    }
}

impl fmt::Display for Effects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_none() {
            return f.write_str("none");
        }
        let parts: Vec<String> = self
            .active()
            .into_iter()
            .map(|e| {
                let ps: Vec<String> = e
                    .info()
                    .params
                    .iter()
                    .zip(self.values[e as usize])
                    .filter(|(p, v)| written(p, *v))
                    .map(|(p, v)| format!("{}={}", p.name, v))
                    .collect();
                format!("{}({})", e.name(), ps.join(", "))
            })
            .collect();
        f.write_str(&parts.join(" + "))?;
        let truth: Vec<&str> = self.active().into_iter().filter(|&e| self.is_truth_form(e)).map(|e| e.name()).collect();
        let family = if self.truth_b { " [truth forms b" } else { " [truth forms" };
        if truth.len() == self.active().len() && self.truth_forms() {
            write!(f, "{family}]")?;
        } else if !truth.is_empty() {
            write!(f, "{family}: {}]", truth.join(", "))?;
        }
        Ok(())
    }
}

/// Whether a parameter is written out: a held shape parameter at its typical value (the
/// candidate's plainest form, which a table that leaves it out reads back) is not.
fn written(p: &EffectParam, v: f64) -> bool {
    !(p.held && v == p.typical)
}

fn num(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        _ => None,
    }
}

// Keep the `Num` import meaningful for readers: effect values accept integers like other keys.
#[allow(dead_code)]
fn _accepts_integers(n: Num) -> f64 {
    n.0
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::*;

    /// The power meter's reading is V·|I|·cos(φ − δ) from the phase current's magnitude and
    /// phase (an independent route through the current's polar form) less the motional
    /// branch's δ-term the model leaves out, is the model's input power at δ = 0, and the
    /// efficiency reading is the output power over it.
    #[test]
    fn the_power_meters_reading_is_the_power_at_its_phase_error() {
        let m = crate::calibrate::tests::reference_motor();
        for (f, t) in [(150.0, 0.0), (250.0, 0.3), (350.0, 0.6)] {
            let s = crate::solve(&m, &crate::OperatingPoint::new(f, t, 200.0, 43e3));
            assert_eq!(Instrument::default().power_reading_w(&s), s.input_power_w);
            assert_eq!(Instrument::default().efficiency_reading(&s), s.efficiency);
            // the clamped capacitance's current, ω·C0·V at 43 kHz and 200 V
            let ic = 2.0 * std::f64::consts::PI * 43e3 * m.electrical.clamped_capacitance_f * 200.0;
            assert!((s.capacitive_current_a / ic - 1.0).abs() < 1e-12);
            let phi = s.current_quadrature_a.atan2(s.current_in_phase_a);
            let motional_var = s.electrode_voltage_v * (s.current_quadrature_a - s.capacitive_current_a);
            for delta in [-0.05, 0.01, 0.2] {
                let meter = Instrument { power_phase_rad: delta, ..Default::default() };
                let polar = s.electrode_voltage_v * s.current_a * (phi - delta).cos() - motional_var * delta.sin();
                let got = meter.power_reading_w(&s);
                assert!((got / polar - 1.0).abs() < 1e-12, "{got} vs {polar}");
                // a capacitive load: a lagging current channel reads high
                assert_eq!(got > s.input_power_w, delta > 0.0);
                let eff = meter.efficiency_reading(&s);
                assert!((eff - (s.output_power_w / got).clamp(0.0, 1.0)).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn names_match_the_spec() {
        let names: Vec<&str> = EFFECTS.iter().map(|e| e.name).collect();
        assert_eq!(
            names,
            [
                "radial_friction",
                "preload_stiffening",
                "hertz_softening",
                "thermal_drift",
                "voltage_sag",
                "eccentricity",
                "tangential_compliance"
            ]
        );
        for (i, e) in ALL.iter().enumerate() {
            assert_eq!(*e as usize, i);
        }
    }

    #[test]
    fn unknown_effect_lists_valid_names() {
        let mut fx = Effects::none();
        let err = fx.parse_assignment("radial=0.5").unwrap_err();
        assert!(err.contains("unknown effect 'radial'"), "{err}");
        assert!(err.contains("tangential_compliance"), "{err}");
        let err = fx.parse_assignment("eccentricity=-1").unwrap_err();
        assert!(err.contains("outside the valid range"), "{err}");
    }

    #[test]
    fn assignment_forms() {
        let mut fx = Effects::none();
        fx.parse_assignment("thermal_drift:stiffness_coefficient_per_k=-1e-4,friction_coefficient_per_k=0").unwrap();
        // the parameter not named keeps its typical value
        assert_eq!(fx.get(Effect::ThermalDrift), Some(&[-1e-4, 0.0, 2e-3, 0.0][..]));
        fx.parse_assignment("radial_friction=0.3").unwrap();
        assert_eq!(fx.value(Effect::RadialFriction, 0), 0.3);
        assert_eq!(fx.active().len(), 2);
        assert_eq!(fx.to_string(), "radial_friction(radial_velocity_ratio=0.3) + thermal_drift(stiffness_coefficient_per_k=-0.0001, friction_coefficient_per_k=0, damping_coefficient_per_k=0.002)");
        fx.parse_assignment("none").unwrap();
        assert!(fx.is_none());
    }

    /// A motor file's effect table may leave out a shape parameter (files written before
    /// `preload_stiffening` had `modal_fraction` stay valid, with Sun et al. 2021 eq. 8), not a
    /// strength; `to_toml` writes every parameter and reads back the same.
    #[test]
    fn a_table_may_leave_out_a_shape_parameter_not_a_strength() {
        let read = |text: &str| {
            let t: toml::Table = text.parse().expect("toml");
            let fx = t.get("effects").and_then(|v| v.as_table()).expect("[effects]");
            Effects::from_toml_table(fx, text, "m.toml")
        };
        let fx = read("[effects]\npreload_stiffening = { stiffness_scale = 0.1 }\n").expect("valid");
        assert_eq!(fx.get(Effect::PreloadStiffening), Some(&[0.1, 0.0][..]));
        let back = read(&fx.to_toml()).expect("round trip");
        assert_eq!(back, fx);
        let err =
            read("[effects]\nthermal_drift = { stiffness_coefficient_per_k = 1e-4, friction_coefficient_per_k = 0 }\n")
                .expect_err("a strength left out")
                .to_string();
        assert!(err.contains("missing parameter 'damping_coefficient_per_k'"), "{err}");
        let err = read("[effects]\npreload_stiffening = { modal_fraction = 1 }\n")
            .expect_err("the strength left out")
            .to_string();
        assert!(err.contains("missing parameter 'stiffness_scale'"), "{err}");
    }

    /// The global setters set every effect's form (a motor file's `form` key, before or
    /// after the effects, means the same); one effect's form is set apart from the others',
    /// and the family of the truth forms is shared.
    #[test]
    fn truth_forms_are_chosen_per_effect() {
        let read = |text: &str| {
            let t: toml::Table = text.parse().expect("toml");
            let fx = t.get("effects").and_then(|v| v.as_table()).expect("[effects]");
            Effects::from_toml_table(fx, text, "m.toml").expect("valid")
        };
        for text in
            ["[effects]\nform = \"truth-b\"\nvoltage_sag = 100\n", "[effects]\nvoltage_sag = 100\nform = \"truth-b\"\n"]
        {
            let fx = read(text);
            assert!(fx.truth_forms() && fx.truth_form_b(), "{text}");
            assert!(ALL.iter().all(|&e| fx.is_truth_form(e) && fx.is_truth_form_b(e)), "{text}");
            assert_eq!(read(&fx.to_toml()), fx, "round trip");
        }
        let mut fx = Effects::none();
        fx.set_strength(Effect::VoltageSag, 100.0);
        fx.set_strength(Effect::RadialFriction, 0.3);
        assert!(!ALL.iter().any(|&e| fx.is_truth_form(e)));
        fx.set_truth_form_b(true);
        fx.set_truth_form(Effect::RadialFriction, false);
        assert!(fx.is_truth_form_b(Effect::VoltageSag) && fx.is_truth_form(Effect::ThermalDrift));
        assert!(!fx.is_truth_form(Effect::RadialFriction) && !fx.is_truth_form_b(Effect::RadialFriction));
        assert!(!fx.truth_forms() && !fx.truth_form_b());
        assert!(fx.to_string().ends_with("[truth forms b: voltage_sag]"), "{fx}");
        // a mix is written as candidate (the `form` key sets every effect)
        assert!(!fx.to_toml().contains("form ="), "{}", fx.to_toml());
        fx.set_truth_forms(false);
        assert!(!ALL.iter().any(|&e| fx.is_truth_form(e)) && !fx.to_string().contains("truth"));
        fx.set_truth_form(Effect::VoltageSag, true);
        assert!(fx.is_truth_form(Effect::VoltageSag) && !fx.is_truth_form_b(Effect::VoltageSag));
        assert!(fx.to_string().ends_with("[truth forms: voltage_sag]"), "{fx}");
    }
}

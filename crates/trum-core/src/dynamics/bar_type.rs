//! Bar-type ultrasonic motor: the stator as a rigid disc on torsional springs, driven by
//! a moment, with a discrete stick-slip contact (the bar-type transient paper: *Transient
//! analysis of bar-type ultrasonic motors*, section IV.A, eq. 1-5).
//!
//! ```text
//! stator tilt   I_t·θ̈_x + c_t·θ̇_x + k_t·θ_x = M₀·cos ωt        + M_C,x     (eq. 3, x and y)
//!               I_t·θ̈_y + c_t·θ̇_y + k_t·θ_y = M₀·cos(ωt − Δφ)  + M_C,y
//! stator twist  J_s·θ̈_z + c_z·θ̇_z + k_z·θ_z = −T_c                          (eq. 3, z)
//! rotor, turn   J_r·Ω̇ + d_r·Ω = T_c − T_load                                  (eq. 4)
//! rotor, axial  m_r·z̈ + d_z·ż + k_sp·(z − z₀) = F_c − F_N                    (eq. 5)
//! ```
//!
//! A contact point at angle φ on the circle of radius R, a height h above the disc's
//! tilt centre, moves axially by w = R·(θ_x·sin φ − θ_y·cos φ) and tangentially by
//! h·∂w/∂(Rφ) + R·θ_z. With q_A = −R·θ_y and q_B = R·θ_x this is the surface of a
//! two-mode stator with one wave around the circumference, w = q_A·cos φ + q_B·sin φ, of
//! modal mass I_t/R², modal stiffness k_t/R² and modal force M₀/R, so the bar-type motor
//! runs on the integrator and the per-node Coulomb return mapping of
//! [`crate::dynamics::transient`] (the same contact step, the same metrics). The tilt
//! springs are tuned to the natural frequency f_n and Q of the paper (k_t = I_t·ω_n²,
//! c_t = I_t·ω_n/Q), likewise the twist. The normal contact forces' moment on the disc
//! (M_C of eq. 3) is included: for a rigid disc it is not a modelling option. The
//! gyroscopic term ω_s × (I_s·ω_s) of eq. 3 is second order in the vibration angles: its
//! ratio to the spring moments is of the order of the tilt angle (≈ 5·10⁻⁴ rad for a
//! 2 µm amplitude on a 4.5 mm radius), so it is left out.
//!
//! Node j of the n nodes on the circle carries a normal spring k_n·Δs and a tangential
//! spring k_τ·Δs (Δs = 2πR/n; the paper's serial rotor springs, Fig. 7). Stick-slip per
//! node follows eq. 2 with the static coefficient μ_s (a node sticks while its no-slip
//! force |f*| ≤ μ_s·p) and eq. 1 with the dynamic coefficient μ_d (a slipping node carries
//! μ_d·p against the slip).
//!
//! The motor file (`kind = "bar"`, docs/MOTOR_FILE.md) and the `bar36` preset
//! (docs/PRESETS.md) hold the parameters; the paper gives f_n = 36.5 kHz, Q = 200, the
//! drive 0.25 N·m at 36.7 kHz and 90°, and 256 nodes; the rest is assumed there.

use super::transient::sim::{self, Plant, Torsion};
use super::transient::{response, StepResponse, TransientError, MAX_STEPS};
use crate::error::ParamError;
use crate::stator::angular_frequency;
use crate::toml_text::{line_of_key, line_of_offset};
use std::fmt::Write as _;

/// Rigid-disc stator, contact, rotor and drive of a bar-type motor. All SI.
#[derive(Clone, Debug, PartialEq)]
pub struct BarMotor {
    /// Display name.
    pub name: String,
    /// The preset it came from, if any.
    pub preset: Option<String>,
    /// Radius R of the contact circle [m].
    pub contact_radius_m: f64,
    /// Height h of the contact surface above the disc's tilt centre [m].
    pub contact_height_m: f64,
    /// Tilt moment of inertia I_t of the equivalent disc about a diameter [kg·m²].
    pub tilt_inertia_kg_m2: f64,
    /// Natural frequency of the tilt (bending) modes f_n [Hz].
    pub natural_frequency_hz: f64,
    /// Quality factor Q of the tilt modes [-].
    pub quality_factor: f64,
    /// Polar moment of inertia J_s of the equivalent disc [kg·m²].
    pub torsion_inertia_kg_m2: f64,
    /// Natural frequency of the stator's twist about the axis [Hz].
    pub torsion_natural_frequency_hz: f64,
    /// Quality factor of the twist [-].
    pub torsion_quality_factor: f64,
    /// Normal contact stiffness per unit circumferential length k_n [N/m²].
    pub normal_stiffness_n_per_m2: f64,
    /// Tangential contact stiffness per unit circumferential length k_τ [N/m²].
    pub tangential_stiffness_n_per_m2: f64,
    /// Static friction coefficient μ_s (stick test, eq. 2) [-].
    pub static_friction_coefficient: f64,
    /// Dynamic friction coefficient μ_d (slip force, eq. 1), ≤ μ_s [-].
    pub dynamic_friction_coefficient: f64,
    /// Rotor moment of inertia J_r [kg·m²].
    pub rotor_inertia_kg_m2: f64,
    /// Rotor viscous (air) damping d_r [N·m·s].
    pub rotor_viscous_damping_nms: f64,
    /// Rotor mass m_r [kg].
    pub rotor_mass_kg: f64,
    /// Stiffness k_sp of the spring pressing the rotor on the stator [N/m].
    pub axial_spring_stiffness_n_per_m: f64,
    /// Axial damping of the rotor d_z [N·s/m].
    pub axial_damping_ns_per_m: f64,
    /// The drive of the source figures: moment amplitude per axis M₀ [N·m].
    pub moment_amplitude_nm: f64,
    /// Drive frequency [Hz].
    pub frequency_hz: f64,
    /// Phase of the y moment behind the x moment [deg] (90: travelling wave).
    pub phase_difference_deg: f64,
    /// Axial preload F_N [N].
    pub preload_n: f64,
}

/// How a key is checked: `true` = finite and > 0, `false` = finite.
type KeyRow = (&'static str, &'static str, bool, &'static str);

/// Every key of a bar-type motor file: section, key, must be > 0, meaning.
pub const BAR_KEYS: &[KeyRow] = &[
    ("geometry", "contact_radius_m", true, "radius R of the contact circle [m]"),
    ("geometry", "contact_height_m", true, "height h of the contact surface above the tilt centre [m]"),
    ("stator", "tilt_inertia_kg_m2", true, "tilt inertia I_t of the equivalent rigid disc [kg m^2]"),
    ("stator", "natural_frequency_hz", true, "natural frequency f_n of the tilt modes [Hz]"),
    ("stator", "quality_factor", true, "quality factor Q of the tilt modes [-]"),
    ("stator", "torsion_inertia_kg_m2", true, "polar inertia J_s of the equivalent disc [kg m^2]"),
    ("stator", "torsion_natural_frequency_hz", true, "natural frequency of the twist about the axis [Hz]"),
    ("stator", "torsion_quality_factor", true, "quality factor of the twist [-]"),
    ("contact", "normal_stiffness_n_per_m2", true, "normal contact stiffness per unit length k_n [N/m^2]"),
    ("contact", "tangential_stiffness_n_per_m2", true, "tangential contact stiffness per unit length [N/m^2]"),
    ("contact", "static_friction_coefficient", true, "static friction coefficient mu_s [-]"),
    ("contact", "dynamic_friction_coefficient", true, "dynamic friction coefficient mu_d <= mu_s [-]"),
    ("rotor", "inertia_kg_m2", true, "rotor moment of inertia J_r [kg m^2]"),
    ("rotor", "viscous_damping_nms", true, "rotor viscous (air) damping d_r [N m s]"),
    ("rotor", "mass_kg", true, "rotor mass m_r [kg]"),
    ("rotor", "axial_spring_stiffness_n_per_m", true, "stiffness k_sp of the preload spring [N/m]"),
    ("rotor", "axial_damping_ns_per_m", true, "axial damping d_z of the rotor [N s/m]"),
    ("drive", "moment_amplitude_nm", true, "drive moment amplitude per axis M0 [N m]"),
    ("drive", "frequency_hz", true, "drive frequency [Hz]"),
    ("drive", "phase_difference_deg", false, "phase of the y moment behind the x moment [deg]"),
    ("drive", "preload_n", true, "axial preload F_N [N]"),
];

impl BarMotor {
    /// The value of a dotted key (`stator.quality_factor`), mutably.
    pub fn param_mut(&mut self, dotted: &str) -> Option<&mut f64> {
        Some(match dotted {
            "geometry.contact_radius_m" => &mut self.contact_radius_m,
            "geometry.contact_height_m" => &mut self.contact_height_m,
            "stator.tilt_inertia_kg_m2" => &mut self.tilt_inertia_kg_m2,
            "stator.natural_frequency_hz" => &mut self.natural_frequency_hz,
            "stator.quality_factor" => &mut self.quality_factor,
            "stator.torsion_inertia_kg_m2" => &mut self.torsion_inertia_kg_m2,
            "stator.torsion_natural_frequency_hz" => &mut self.torsion_natural_frequency_hz,
            "stator.torsion_quality_factor" => &mut self.torsion_quality_factor,
            "contact.normal_stiffness_n_per_m2" => &mut self.normal_stiffness_n_per_m2,
            "contact.tangential_stiffness_n_per_m2" => &mut self.tangential_stiffness_n_per_m2,
            "contact.static_friction_coefficient" => &mut self.static_friction_coefficient,
            "contact.dynamic_friction_coefficient" => &mut self.dynamic_friction_coefficient,
            "rotor.inertia_kg_m2" => &mut self.rotor_inertia_kg_m2,
            "rotor.viscous_damping_nms" => &mut self.rotor_viscous_damping_nms,
            "rotor.mass_kg" => &mut self.rotor_mass_kg,
            "rotor.axial_spring_stiffness_n_per_m" => &mut self.axial_spring_stiffness_n_per_m,
            "rotor.axial_damping_ns_per_m" => &mut self.axial_damping_ns_per_m,
            "drive.moment_amplitude_nm" => &mut self.moment_amplitude_nm,
            "drive.frequency_hz" => &mut self.frequency_hz,
            "drive.phase_difference_deg" => &mut self.phase_difference_deg,
            "drive.preload_n" => &mut self.preload_n,
            _ => return None,
        })
    }

    /// The value of a dotted key.
    pub fn param(&self, dotted: &str) -> Option<f64> {
        self.clone().param_mut(dotted).map(|v| *v)
    }

    /// Sets a dotted key and validates; an unknown key or a bad value is an error naming it.
    pub fn set_param(&mut self, dotted: &str, value: f64, source_name: &str) -> Result<(), ParamError> {
        let Some(slot) = self.param_mut(dotted) else {
            let valid: Vec<String> = BAR_KEYS.iter().map(|(s, k, _, _)| format!("{s}.{k}")).collect();
            return Err(ParamError {
                source_name: source_name.into(),
                line: None,
                key: dotted.into(),
                reason: format!("unknown parameter; valid keys are: {}", valid.join(", ")),
            });
        };
        *slot = value;
        self.validate(source_name, None)
    }

    /// Checks every value (finite, sign) and μ_d ≤ μ_s; `text` lets the error point at
    /// the line of the TOML source.
    pub fn validate(&self, source_name: &str, text: Option<&str>) -> Result<(), ParamError> {
        let err = |sec: &str, key: &str, reason: String| ParamError {
            source_name: source_name.into(),
            line: text.and_then(|t| line_of_key(t, sec, key)),
            key: format!("{sec}.{key}"),
            reason,
        };
        for &(sec, key, positive, _) in BAR_KEYS {
            let v = self.param(&format!("{sec}.{key}")).unwrap_or(f64::NAN);
            if !v.is_finite() {
                return Err(err(sec, key, format!("{v} is not a finite number")));
            }
            if positive && v <= 0.0 {
                return Err(err(sec, key, format!("{v} must be > 0")));
            }
        }
        if self.dynamic_friction_coefficient > self.static_friction_coefficient {
            return Err(err(
                "contact",
                "dynamic_friction_coefficient",
                format!(
                    "{} exceeds the static coefficient {}; Coulomb's law needs mu_d <= mu_s",
                    self.dynamic_friction_coefficient, self.static_friction_coefficient
                ),
            ));
        }
        Ok(())
    }

    /// True when a TOML text is a bar-type motor file (`kind = "bar"`, or a `preset` that
    /// names a bar-type preset). Never fails: unreadable text is not a bar-type file.
    pub fn is_bar_file(text: &str) -> bool {
        let Ok(t) = text.parse::<toml::Table>() else { return false };
        t.get("kind").and_then(|v| v.as_str()) == Some("bar")
            || t.get("preset").and_then(|v| v.as_str()).is_some_and(|p| crate::presets::find_bar(p).is_some())
    }

    /// Reads a bar-type motor file: `kind = "bar"`, optional `name`, and either every key
    /// of [`BAR_KEYS`] or `preset = "bar36"` with some of them as overrides. Unknown keys
    /// and sections are errors naming the file, line and key.
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<BarMotor, ParamError> {
        let perr = |line: Option<usize>, key: &str, reason: String| ParamError {
            source_name: source_name.into(),
            line,
            key: key.into(),
            reason,
        };
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            perr(e.span().map(|s| line_of_offset(text, s.start)), "", e.message().trim().to_string())
        })?;
        let at = |sec: &str, key: &str| line_of_key(text, sec, key);
        let mut motor = match table.get("preset") {
            None => None,
            Some(toml::Value::String(p)) => match crate::presets::find_bar(p) {
                Some(b) => Some(b.motor()),
                None => {
                    let names: Vec<&str> = crate::presets::BAR_PRESETS.iter().map(|b| b.name).collect();
                    return Err(perr(
                        at("", "preset"),
                        "preset",
                        format!("'{p}' is not a bar-type preset; valid ones are: {}", names.join(", ")),
                    ));
                }
            },
            Some(_) => return Err(perr(at("", "preset"), "preset", "expected a preset name in quotes".into())),
        };
        let complete = motor.is_none();
        let mut m = motor.take().unwrap_or_else(|| BarMotor { name: source_name.into(), ..BarMotor::nan() });
        let mut seen = std::collections::BTreeSet::new();
        for (k, v) in &table {
            match (k.as_str(), v) {
                ("kind", toml::Value::String(s)) if s == "bar" => {}
                ("kind", _) => return Err(perr(at("", "kind"), "kind", "a bar-type motor file has kind = \"bar\"".into())),
                ("name", toml::Value::String(s)) => m.name = s.clone(),
                ("preset", _) => {}
                (sec, toml::Value::Table(t)) if BAR_KEYS.iter().any(|r| r.0 == sec) => {
                    for (key, val) in t {
                        let dotted = format!("{sec}.{key}");
                        let num = match val {
                            toml::Value::Float(x) => *x,
                            toml::Value::Integer(i) => *i as f64,
                            _ => return Err(perr(at(sec, key), &dotted, "expected a number".into())),
                        };
                        let Some(slot) = m.param_mut(&dotted) else {
                            let valid: Vec<&str> = BAR_KEYS.iter().filter(|r| r.0 == sec).map(|r| r.1).collect();
                            return Err(perr(
                                at(sec, key),
                                &dotted,
                                format!("unknown key; [{sec}] has: {}", valid.join(", ")),
                            ));
                        };
                        *slot = num;
                        seen.insert(dotted);
                    }
                }
                (other, _) => {
                    return Err(perr(
                        at("", other),
                        other,
                        "unknown key or section; a bar-type motor file has kind, name, preset and the sections geometry, stator, contact, rotor, drive".into(),
                    ))
                }
            }
        }
        if complete {
            if let Some(&(sec, key, _, _)) = BAR_KEYS.iter().find(|(s, k, _, _)| !seen.contains(&format!("{s}.{k}"))) {
                return Err(perr(
                    None,
                    &format!("{sec}.{key}"),
                    "missing key (without `preset = \"...\"` every key is required)".into(),
                ));
            }
        }
        m.preset = table.get("preset").and_then(|v| v.as_str()).map(str::to_string);
        m.validate(source_name, Some(text))?;
        Ok(m)
    }

    fn nan() -> BarMotor {
        let n = f64::NAN;
        BarMotor {
            name: String::new(),
            preset: None,
            contact_radius_m: n,
            contact_height_m: n,
            tilt_inertia_kg_m2: n,
            natural_frequency_hz: n,
            quality_factor: n,
            torsion_inertia_kg_m2: n,
            torsion_natural_frequency_hz: n,
            torsion_quality_factor: n,
            normal_stiffness_n_per_m2: n,
            tangential_stiffness_n_per_m2: n,
            static_friction_coefficient: n,
            dynamic_friction_coefficient: n,
            rotor_inertia_kg_m2: n,
            rotor_viscous_damping_nms: n,
            rotor_mass_kg: n,
            axial_spring_stiffness_n_per_m: n,
            axial_damping_ns_per_m: n,
            moment_amplitude_nm: n,
            frequency_hz: n,
            phase_difference_deg: n,
            preload_n: n,
        }
    }

    /// A complete bar-type motor file that reads back to this motor; `notes` gives the
    /// comment beside a dotted key (its provenance).
    pub fn to_toml_annotated(&self, header: &str, notes: &dyn Fn(&str) -> Option<String>) -> String {
        let mut s = String::new();
        for l in header.lines() {
            let _ = writeln!(s, "# {l}");
        }
        let _ = writeln!(s, "kind = \"bar\"\nname = {:?}", self.name);
        let mut section = "";
        for &(sec, key, _, doc) in BAR_KEYS {
            if sec != section {
                let _ = writeln!(s, "\n[{sec}]");
                section = sec;
            }
            let dotted = format!("{sec}.{key}");
            let v = self.param(&dotted).unwrap_or(f64::NAN);
            let note = notes(&dotted).unwrap_or_else(|| doc.to_string());
            let _ = writeln!(s, "{key} = {v:?}  # {note}");
        }
        s
    }

    /// The default step-response settings at this motor's drive ([`BarMotor::frequency_hz`]
    /// etc.): 15 ms, 64 steps per period, 256 nodes (the paper's count).
    pub fn step_config(&self) -> BarStepConfig {
        BarStepConfig {
            duration_s: 15e-3,
            steps_per_period: 64,
            nodes: 256,
            phase_difference_rad: self.phase_difference_deg.to_radians(),
            load_torque_nm: 0.0,
            moment_amplitude_nm: self.moment_amplitude_nm,
            frequency_hz: self.frequency_hz,
            preload_n: self.preload_n,
            record_every: 16,
            snapshot_times_s: Vec::new(),
        }
    }
}

/// Settings of one bar-type step-response run. All SI. The drive moments switch on at
/// t = 0 with the stator at rest and the rotor at rest on its preloaded equilibrium.
#[derive(Clone, Debug, PartialEq)]
pub struct BarStepConfig {
    /// Simulated time [s], > 0.
    pub duration_s: f64,
    /// Time steps per drive period (≥ 16).
    pub steps_per_period: usize,
    /// Contact nodes on the circle (≥ 8; 256 in the paper).
    pub nodes: usize,
    /// Phase of the y moment behind the x moment [rad]; π/2 travelling wave, 0 standing.
    pub phase_difference_rad: f64,
    /// Load torque on the rotor T_load [N·m], ≥ 0: a Coulomb brake, T_load·sign Ω against
    /// the rotation in either direction, holding the rotor at rest while |T_c| ≤ T_load
    /// (the paper's eq. 4; the ring model's integrator, [`crate::dynamics::transient`]).
    pub load_torque_nm: f64,
    /// Drive moment amplitude per axis M₀ [N·m], > 0.
    pub moment_amplitude_nm: f64,
    /// Drive frequency [Hz], > 0.
    pub frequency_hz: f64,
    /// Axial preload F_N [N], > 0.
    pub preload_n: f64,
    /// Record the time series every this many steps (≥ 1).
    pub record_every: usize,
    /// Times [s] at which to return the contact state per node (each in [0, duration]).
    pub snapshot_times_s: Vec<f64>,
}

impl BarStepConfig {
    /// Checks every field; the error names the first offending one.
    pub fn validate(&self) -> Result<(), TransientError> {
        let check = |name: &'static str, value: f64, ok: bool, reason: &'static str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(TransientError::InvalidConfig { name, value, reason })
            }
        };
        check("duration_s", self.duration_s, self.duration_s > 0.0, "must be finite and > 0")?;
        let spp = self.steps_per_period as f64;
        check("steps_per_period", spp, self.steps_per_period >= 16, "must be >= 16")?;
        check("nodes", self.nodes as f64, self.nodes >= 8, "must be >= 8")?;
        check("phase_difference_rad", self.phase_difference_rad, true, "must be finite")?;
        check("load_torque_nm", self.load_torque_nm, self.load_torque_nm >= 0.0, "must be finite and >= 0")?;
        let m0 = self.moment_amplitude_nm;
        check("moment_amplitude_nm", m0, m0 > 0.0, "must be finite and > 0")?;
        check("frequency_hz", self.frequency_hz, self.frequency_hz > 0.0, "must be finite and > 0")?;
        check("preload_n", self.preload_n, self.preload_n > 0.0, "must be finite and > 0")?;
        check("record_every", self.record_every as f64, self.record_every >= 1, "must be >= 1")?;
        for &t in &self.snapshot_times_s {
            check("snapshot_times_s", t, t >= 0.0 && t <= self.duration_s, "must lie in [0, duration_s]")?;
        }
        let steps = (self.duration_s * self.frequency_hz * spp).ceil();
        if steps > MAX_STEPS as f64 {
            return Err(TransientError::TooManySteps { steps: steps as u64, limit: MAX_STEPS });
        }
        Ok(())
    }
}

/// The bar-type motor in the terms of the shared two-mode integrator (module docs).
fn plant(m: &BarMotor, cfg: &BarStepConfig) -> Plant {
    let r = m.contact_radius_m;
    let wn = angular_frequency(m.natural_frequency_hz);
    let wz = angular_frequency(m.torsion_natural_frequency_hz);
    let modal_mass = m.tilt_inertia_kg_m2 / (r * r);
    Plant {
        n_waves: 1.0,
        r0: r,
        h0: m.contact_height_m,
        kf_n_per_m2: m.normal_stiffness_n_per_m2,
        kt_n_per_m2: m.tangential_stiffness_n_per_m2,
        mu_static: m.static_friction_coefficient,
        mu_dynamic: m.dynamic_friction_coefficient,
        modal_mass_kg: modal_mass,
        modal_stiffness_n_per_m: modal_mass * wn * wn,
        modal_damping_ns_per_m: modal_mass * wn / m.quality_factor,
        drive_force_n: cfg.moment_amplitude_nm / r,
        rotor_inertia_kg_m2: m.rotor_inertia_kg_m2,
        rotor_damping_nms: m.rotor_viscous_damping_nms,
        rotor_mass_kg: m.rotor_mass_kg,
        axial_stiffness_n_per_m: m.axial_spring_stiffness_n_per_m,
        axial_damping_ns_per_m: m.axial_damping_ns_per_m,
        normal_coupling: 1.0,
        torsion: Some(Torsion {
            inertia_kg_m2: m.torsion_inertia_kg_m2,
            stiffness_nm_per_rad: m.torsion_inertia_kg_m2 * wz * wz,
            damping_nms: m.torsion_inertia_kg_m2 * wz / m.torsion_quality_factor,
        }),
        preload_n: cfg.preload_n,
        load_torque_nm: cfg.load_torque_nm,
        frequency_hz: cfg.frequency_hz,
        phase_difference_rad: cfg.phase_difference_rad,
        duration_s: cfg.duration_s,
        steps_per_period: cfg.steps_per_period,
        nodes_per_wavelength: cfg.nodes,
        record_every: cfg.record_every,
        snapshot_times_s: cfg.snapshot_times_s.clone(),
        initial_rotor_speed_rad_s: 0.0,
    }
}

/// Simulates the start-up of a bar-type motor after a step of the drive moments (the
/// bar-type transient paper eq. 1-5, module docs) and returns the time series (the
/// amplitude is the contact circle's axial vibration amplitude R·|θ| [m]), the step
/// metrics, the end-of-run averages and the requested contact snapshots (positions along
/// the circumference [m]). Never panics: invalid settings, an unstable time step or
/// divergence are errors.
pub fn bar_step_response(motor: &BarMotor, cfg: &BarStepConfig) -> Result<StepResponse, TransientError> {
    cfg.validate()?;
    motor.validate("motor", None).map_err(|e| TransientError::InvalidMotor(e.to_string()))?;
    let p = plant(motor, cfg);
    Ok(response(sim::run(&p)?, &p))
}

/// Steady-state tilt amplitude of the free stator (no contact) at a drive: R·M₀/|I_t·(ω_n² − ω²
/// + i·ω·ω_n/Q)| [m]. The single-degree-of-freedom forced response of eq. 3.
pub fn free_amplitude_m(motor: &BarMotor, moment_amplitude_nm: f64, frequency_hz: f64) -> f64 {
    let wn = angular_frequency(motor.natural_frequency_hz);
    let w = angular_frequency(frequency_hz);
    let d = (wn * wn - w * w).hypot(w * wn / motor.quality_factor);
    motor.contact_radius_m * moment_amplitude_nm / (motor.tilt_inertia_kg_m2 * d)
}

#[cfg(test)]
mod tests;

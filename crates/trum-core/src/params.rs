//! Motor parameters: the structs, the TOML motor file (`preset = "name"` plus overrides,
//! unknown keys rejected, every value validated with the key and line named), and the
//! annotated TOML writer that `trum presets show` uses.
//!
//! Keys carry their SI unit as a suffix (`mean_radius_m`, `modal_damping_ns_per_m`).
//! Numbers may be written as TOML integers or floats.

use crate::effects::Effects;
use crate::error::ParamError;
use crate::toml_text::{fmt_toml_number, line_of_key, line_of_offset, Num};
use serde::Deserialize;
use std::fmt::Write as _;

/// How a value is checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Check {
    /// finite and > 0
    Positive,
    /// finite and >= 0
    NonNegative,
    /// finite
    Finite,
    /// a whole number >= 1
    PositiveInteger,
    /// > 0, `inf` allowed (a limit that is not set)
    PositiveOrInf,
}

impl Check {
    fn reason(self, v: f64) -> Option<String> {
        if self == Check::PositiveOrInf {
            return (v.is_nan() || v <= 0.0).then(|| format!("{v} must be > 0 (or inf: no limit)"));
        }
        if !v.is_finite() {
            return Some(format!("{v} is not a finite number"));
        }
        match self {
            Check::Positive if v <= 0.0 => Some(format!("{v} must be > 0")),
            Check::NonNegative if v < 0.0 => Some(format!("{v} must be >= 0")),
            Check::PositiveInteger if v < 1.0 || v.fract() != 0.0 || v > 1e6 => {
                Some(format!("{v} must be a positive whole number"))
            }
            _ => None,
        }
    }
}

/// Describes one key for documentation, validation and the TOML writer.
#[derive(Clone, Copy, Debug)]
pub struct KeyInfo {
    /// Section name (`stator`).
    pub section: &'static str,
    /// Key name with unit suffix (`modal_mass_kg`).
    pub key: &'static str,
    /// One-line meaning with unit.
    pub doc: &'static str,
    pub(crate) check: Check,
}

macro_rules! section {
    (
        $(#[$m:meta])* $name:ident / $patch:ident = $sec:literal {
            $( $(#[$fm:meta])* $field:ident : $check:ident = $doc:literal ),* $(,)?
        }
    ) => {
        $(#[$m])*
        #[derive(Clone, Debug, PartialEq)]
        pub struct $name { $( $(#[$fm])* pub $field: f64, )* }

        #[derive(Debug, Default, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub(crate) struct $patch { $( $field: Option<Num>, )* }

        impl $name {
            /// Keys of this section, in file order.
            pub const KEYS: &'static [KeyInfo] = &[
                $( KeyInfo { section: $sec, key: stringify!($field), doc: $doc, check: Check::$check }, )*
            ];
            fn values(&self) -> Vec<f64> { vec![ $( self.$field, )* ] }
            fn apply(&mut self, p: &$patch) { $( if let Some(v) = p.$field { self.$field = v.0; } )* }
            // (unused for a section that is optional in a complete file)
            #[allow(dead_code)]
            fn from_patch(p: &$patch) -> Result<Self, &'static str> {
                Ok(Self { $( $field: p.$field.ok_or(stringify!($field))?.0, )* })
            }
            /// Mutable access by key name (for overrides from the CLI, Python and calibration).
            pub fn get_mut(&mut self, key: &str) -> Option<&mut f64> {
                match key { $( stringify!($field) => Some(&mut self.$field), )* _ => None }
            }
        }
    };
}

section! {
    /// Ring geometry and kinematics (Chen et al. 2020 Table A1, Sun et al. 2021 Table 1).
    Geometry / GeometryPatch = "geometry" {
        /// N: number of traveling waves around the ring (9 for the TRUM-60 family).
        wave_number: PositiveInteger = "number of traveling waves N around the ring [-]",
        /// R0: mean radius of the stator/rotor contact ring [m].
        mean_radius_m: Positive = "mean radius R0 of the contact ring [m]",
        /// b_f: radial width of the contact (friction layer) [m].
        contact_width_m: Positive = "radial width b_f of the friction-layer contact [m]",
        /// h0: distance from the stator tooth surface to the neutral plane [m] (Sun et al.
        /// 2021 eq. 12).
        neutral_plane_distance_m: Positive = "distance h0 from tooth surface to neutral plane [m]",
    }
}

section! {
    /// Friction layer bonded to the rotor (Sun et al. 2021 eq. 4).
    FrictionLayer / FrictionLayerPatch = "friction_layer" {
        /// E_f: Young's modulus of the friction layer [Pa].
        youngs_modulus_pa: Positive = "Young's modulus E_f of the friction layer [Pa]",
        /// h_f: thickness of the friction layer [m].
        thickness_m: Positive = "thickness h_f of the friction layer [m]",
        /// μ: Coulomb friction coefficient stator/friction layer [-].
        friction_coefficient: Positive = "Coulomb friction coefficient mu [-]",
    }
}

section! {
    /// Modal model of the stator: one traveling wave = two degenerate standing modes
    /// (Sun et al. 2021 eq. 6; Chen et al. 2020 Appendix A).
    Stator / StatorPatch = "stator" {
        /// m: modal mass of each standing mode, mode shape normalised to 1 at the contact surface [kg].
        modal_mass_kg: Positive = "modal mass m of each standing mode [kg]",
        /// f_r: resonance frequency of the free stator (no contact) [Hz].
        resonance_frequency_hz: Positive = "resonance frequency f_r of the free stator [Hz]",
        /// c: modal damping of each standing mode [N·s/m].
        modal_damping_ns_per_m: Positive = "modal damping c of each standing mode [N s/m]",
        /// Θ: electromechanical force factor, modal force per volt [N/V].
        force_factor_n_per_v: Positive = "force factor Theta, modal force per phase volt [N/V]",
    }
}

section! {
    /// Electrical side of the piezoceramic (Chen et al. 2020 eq. 7, Sun et al. 2021 eq. 1
    /// and 15).
    Electrical / ElectricalPatch = "electrical" {
        /// C0: clamped capacitance of one phase [F].
        clamped_capacitance_f: NonNegative = "clamped capacitance C0 of one phase [F]",
        /// tan δ: dielectric loss tangent [-].
        dielectric_loss_tangent: NonNegative = "dielectric loss tangent tan(delta) [-]",
        /// K_WV: feedback (isolated) electrode voltage amplitude per metre of wave amplitude [V/m].
        feedback_gain_v_per_m: NonNegative = "feedback-electrode volts per metre of amplitude K_WV [V/m]",
    }
}

section! {
    /// Rotor (Chen et al. 2020 Table A1).
    Rotor / RotorPatch = "rotor" {
        /// d_r: viscous (bearing/air) rotor damping torque per angular speed [N·m·s].
        viscous_damping_nms: NonNegative = "rotor viscous damping d_r [N m s]",
        /// J_r: rotor moment of inertia [kg·m²].
        inertia_kg_m2: Positive = "rotor moment of inertia J_r [kg m^2]",
        /// m_r: rotor mass [kg].
        mass_kg: Positive = "rotor mass m_r [kg]",
    }
}

section! {
    /// Lumped thermal model of the motor (Chen et al. 2020 eq. 11).
    Thermal / ThermalPatch = "thermal" {
        /// α: convective heat-transfer coefficient [W/(m²·K)].
        heat_transfer_coefficient_w_per_m2k: Positive = "convective heat-transfer coefficient alpha [W/(m^2 K)]",
        /// S: motor surface area exchanging heat [m²].
        surface_area_m2: Positive = "motor surface area S [m^2]",
        /// C_usm: heat capacity of the motor [J/K].
        heat_capacity_j_per_k: Positive = "heat capacity C_usm of the motor [J/K]",
        /// T_air: ambient temperature [°C].
        ambient_c: Finite = "ambient temperature T_air [degC]",
    }
}

section! {
    /// Assembly of the preload path (Chen et al. 2020 section 4.3).
    Assembly / AssemblyPatch = "assembly" {
        /// k_sp: axial stiffness of the preload spring (disc spring or gasket) [N/m].
        axial_spring_stiffness_n_per_m: Positive = "axial stiffness of the preload spring [N/m]",
    }
}

section! {
    /// Physical limits of the motor: every solved point names the limits it exceeds
    /// ([`crate::limits`]). A motor file without `[limits]` takes the defaults of the
    /// piezoceramic traveling-wave ring motor ([`Limits::piezoceramic_ring`],
    /// docs/MOTOR_FILE.md gives their sources); `inf` switches a limit off.
    Limits / LimitsPatch = "limits" {
        /// Highest drive voltage amplitude per phase, zero-to-peak [V].
        max_voltage_v: PositiveOrInf = "highest drive voltage amplitude per phase, zero-to-peak [V]",
        /// Highest wave amplitude at the contact surface [m].
        max_amplitude_m: PositiveOrInf = "highest wave amplitude at the contact surface [m]",
        /// Highest steady motor temperature, ambient plus the steady rise [°C].
        max_stator_temperature_c: PositiveOrInf = "highest steady stator temperature, ambient plus steady rise [degC]",
        /// Highest electrical input power, both phases [W].
        max_input_power_w: PositiveOrInf = "highest electrical input power, both phases [W]",
    }
}

/// A complete motor definition. Build one from a preset ([`crate::presets::preset`]) or
/// a TOML motor file ([`Motor::from_toml_str`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Motor {
    /// Display name.
    pub name: String,
    /// The preset this motor started from, if any.
    pub preset: Option<String>,
    /// Ring geometry.
    pub geometry: Geometry,
    /// Friction layer.
    pub friction_layer: FrictionLayer,
    /// Stator modal model.
    pub stator: Stator,
    /// Electrical parameters.
    pub electrical: Electrical,
    /// Rotor.
    pub rotor: Rotor,
    /// Thermal model.
    pub thermal: Thermal,
    /// Preload path and assembly errors.
    pub assembly: Assembly,
    /// Switched-on unmodelled effects (none by default).
    pub effects: Effects,
    /// Physical limits the solved points are checked against.
    pub limits: Limits,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotorFile {
    name: Option<String>,
    preset: Option<String>,
    geometry: Option<GeometryPatch>,
    friction_layer: Option<FrictionLayerPatch>,
    stator: Option<StatorPatch>,
    electrical: Option<ElectricalPatch>,
    rotor: Option<RotorPatch>,
    thermal: Option<ThermalPatch>,
    assembly: Option<AssemblyPatch>,
    effects: Option<toml::Table>,
    sweep: Option<SweepPatch>,
    tolerances: Option<toml::Table>,
    drive: Option<DrivePatch>,
    limits: Option<LimitsPatch>,
    plausible: Option<crate::measurements::PlausibleTable>,
}

/// Reads the `[plausible]` table of a motor file: the plausible range of each measured
/// column that calibration and the diagnosis accept from this motor's bench
/// (docs/MEASUREMENTS.md, "Plausible ranges"), as `speed_rpm = [0, 20000]` (inclusive;
/// `inf`/`-inf` for no bound at that end) or `speed_rpm = "any"`. Returns the default
/// ranges with the table's applied (the defaults alone without a table). Unknown keys and
/// bad values are errors naming the file, line and key.
pub fn plausible_from_toml_str(
    text: &str,
    source_name: &str,
) -> Result<crate::measurements::PlausibleRanges, ParamError> {
    let file: MotorFile = match toml::from_str(text) {
        Ok(f) => f,
        // the motor reader words a TOML error with its key and line
        Err(e) => {
            return Err(Motor::from_toml_str(text, source_name).err().unwrap_or_else(|| ParamError {
                source_name: source_name.into(),
                line: e.span().map(|s| line_of_offset(text, s.start)),
                key: "plausible".into(),
                reason: e.message().trim().to_string(),
            }))
        }
    };
    let mut ranges = crate::measurements::PlausibleRanges::default();
    if let Some(table) = &file.plausible {
        table.apply(&mut ranges, |key, reason| ParamError {
            source_name: source_name.into(),
            line: line_of_key(text, "plausible", key),
            key: format!("plausible.{key}"),
            reason,
        })?;
    }
    Ok(ranges)
}

/// Reads the `[tolerances]` table of a motor file: how well each uncertain baseline
/// parameter is known before calibration, as the prior standard deviation of its
/// logarithm (0.05 ≈ ±5 %; 0 holds the parameter at its file value; `inf` fits it without a
/// prior). Keys are dotted motor keys (`"geometry.neutral_plane_distance_m" = 0.02`) or
/// sub-tables (`[tolerances.geometry]`), limited to the parameters calibration fits
/// ([`crate::tolerances::TOLERANCES`], docs/DIAGNOSIS.md); the bench's speed-std floor is
/// `bench.speed_std_floor_rpm` (0: the bench has none), the torque transducer's zero offset
/// `bench.torque_offset_nm` (the prior's standard deviation in N·m; 0: no offset), the
/// temperature reading's offset `bench.temperature_offset_k` (in K; 0: no offset), the
/// temperature sensor's lag `bench.temperature_lag_s` (the standard deviation of its
/// logarithm; 0: no lag), the preload reading's offset `bench.preload_offset_n` (in N; 0:
/// no offset), the current reading's gain error `bench.current_gain_rel` (relative; 0:
/// exact) and the power reading's phase error `bench.power_phase_rad` (in rad; 0: exact).
/// Empty
/// without a table; errors name
/// the file, line and key.
pub fn tolerances_from_toml_str(
    text: &str,
    source_name: &str,
) -> Result<std::collections::BTreeMap<String, f64>, ParamError> {
    let file: MotorFile = toml::from_str(text).map_err(|e| ParamError {
        source_name: source_name.into(),
        line: e.span().map(|s| line_of_offset(text, s.start)),
        key: "tolerances".into(),
        reason: e.message().trim().to_string(),
    })?;
    let mut out = std::collections::BTreeMap::new();
    let Some(table) = file.tolerances else { return Ok(out) };
    let mut flat: Vec<(String, &toml::Value)> = Vec::new();
    for (k, v) in &table {
        match v {
            toml::Value::Table(sub) => flat.extend(sub.iter().map(|(k2, v2)| (format!("{k}.{k2}"), v2))),
            _ => flat.push((k.clone(), v)),
        }
    }
    for (key, v) in flat {
        let (sec, name) = key.split_once('.').unwrap_or(("", key.as_str()));
        let err = |reason: String| ParamError {
            source_name: source_name.into(),
            line: line_of_key(text, &format!("tolerances.{sec}"), name)
                .or_else(|| line_of_key(text, "tolerances", &key)),
            key: format!("tolerances.{key}"),
            reason,
        };
        let x = match v {
            toml::Value::Integer(i) => *i as f64,
            toml::Value::Float(x) => *x,
            _ => {
                // an unknown key is named as such before its value's type
                check_tolerance(&key, 0.0).map_err(&err)?;
                return Err(err("expected a number (relative standard deviation, 0 or inf)".into()));
            }
        };
        check_tolerance(&key, x).map_err(err)?;
        out.insert(key, x);
    }
    Ok(out)
}

/// The keys a `[tolerances]` table accepts: the parameters calibration fits
/// ([`crate::tolerances::TOLERANCES`]) by dotted motor key, then the bench's
/// `bench.speed_std_floor_rpm`, `bench.torque_offset_nm`, `bench.temperature_offset_k`,
/// `bench.temperature_lag_s`, `bench.preload_offset_n`, `bench.current_gain_rel` and
/// `bench.power_phase_rad`.
pub fn tolerance_keys() -> Vec<String> {
    crate::tolerances::TOLERANCES
        .iter()
        .map(|t| t.key.to_string())
        .chain(
            [
                "bench.speed_std_floor_rpm",
                "bench.torque_offset_nm",
                "bench.temperature_offset_k",
                "bench.temperature_lag_s",
                "bench.preload_offset_n",
                "bench.current_gain_rel",
                "bench.power_phase_rad",
            ]
            .map(String::from),
        )
        .collect()
}

/// Whether `x` may be the tolerance of `key` (see [`tolerances_from_toml_str`]): a valid key
/// and a value ≥ 0 (or inf). The error is the reason, listing the valid keys for an unknown one.
fn check_tolerance(key: &str, x: f64) -> Result<(), String> {
    let valid = tolerance_keys();
    if !valid.iter().any(|k| k == key) {
        return Err(format!("not a calibrated parameter; valid keys are: {}", valid.join(", ")));
    }
    if x.is_nan() || x < 0.0 {
        return Err(format!("{x} must be >= 0 (or inf)"));
    }
    Ok(())
}

/// Tolerances given as (key, value) pairs, such as a Python mapping, checked as the
/// `[tolerances]` table's entries are ([`tolerances_from_toml_str`]); an error names
/// `source_name` and the key. A later pair of the same key wins.
pub fn tolerances_from_pairs(
    pairs: &[(String, f64)],
    source_name: &str,
) -> Result<std::collections::BTreeMap<String, f64>, ParamError> {
    let mut out = std::collections::BTreeMap::new();
    for (key, x) in pairs {
        check_tolerance(key, *x).map_err(|reason| ParamError {
            source_name: source_name.into(),
            line: None,
            key: format!("tolerances.{key}"),
            reason,
        })?;
        out.insert(key.clone(), *x);
    }
    Ok(out)
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct DrivePatch {
    voltage_v: Option<Num>,
    frequency_hz: Option<Num>,
}

/// The `[drive]` table of a motor file: the drive the motor's source figures were taken
/// at, which commands use when neither the command line nor `[sweep]` sets one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Drive voltage amplitude per phase [V], > 0.
    pub voltage_v: f64,
    /// Drive frequency [Hz], > 0.
    pub frequency_hz: f64,
}

impl Drive {
    /// The `[drive]` table of a motor file; without one, the drive of the preset the file
    /// names (`preset = "..."`); `None` when neither gives one. Both keys are required and
    /// must be finite and > 0; the error names the file, line and key.
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Option<Drive>, ParamError> {
        let file: MotorFile = toml::from_str(text).map_err(|e| ParamError {
            source_name: source_name.into(),
            line: e.span().map(|s| line_of_offset(text, s.start)),
            key: "drive".into(),
            reason: e.message().trim().to_string(),
        })?;
        let Some(d) = &file.drive else {
            return match &file.preset {
                Some(p) => Ok(crate::presets::find(p)?.drive()),
                None => Ok(None),
            };
        };
        let value = |v: &Option<Num>, key: &str| -> Result<f64, ParamError> {
            let err = |reason: String| ParamError {
                source_name: source_name.into(),
                line: line_of_key(text, "drive", key),
                key: format!("drive.{key}"),
                reason,
            };
            match v {
                None => Err(err("missing key ([drive] needs voltage_v and frequency_hz)".into())),
                Some(Num(x)) if x.is_finite() && *x > 0.0 => Ok(*x),
                Some(Num(x)) => Err(err(format!("{x} must be a finite number > 0"))),
            }
        };
        Ok(Some(Drive {
            voltage_v: value(&d.voltage_v, "voltage_v")?,
            frequency_hz: value(&d.frequency_hz, "frequency_hz")?,
        }))
    }
}

/// One axis in a `[sweep]` table: a single value or `[start, stop, n]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum AxisSpec {
    Value(Num),
    Range((Num, Num, Num)),
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepPatch {
    preload_n: Option<AxisSpec>,
    voltage_v: Option<AxisSpec>,
    frequency_hz: Option<AxisSpec>,
    torque_nm: Option<AxisSpec>,
}

/// The `[sweep]` table of a motor file: the axes it sets (others left to the caller).
/// Each axis is written `key = value` or `key = [start, stop, n]`.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct SweepTable {
    /// Preload axis [N], if set.
    pub preload_n: Option<crate::axis::Axis>,
    /// Voltage axis [V], if set.
    pub voltage_v: Option<crate::axis::Axis>,
    /// Frequency axis [Hz], if set.
    pub frequency_hz: Option<crate::axis::Axis>,
    /// Torque axis [N·m], if set.
    pub torque_nm: Option<crate::axis::Axis>,
}

fn axis_from_spec(
    spec: &Option<AxisSpec>,
    key: &str,
    text: &str,
    source_name: &str,
) -> Result<Option<crate::axis::Axis>, ParamError> {
    let err = |reason: String| ParamError {
        source_name: source_name.into(),
        line: line_of_key(text, "sweep", key),
        key: format!("sweep.{key}"),
        reason,
    };
    let axis = match spec {
        None => return Ok(None),
        Some(AxisSpec::Value(v)) => crate::axis::Axis::fixed(v.0),
        Some(AxisSpec::Range((a, b, n))) => {
            if !(n.0.fract() == 0.0 && n.0 >= 1.0 && n.0 <= 1e12) {
                return Err(err(format!("the point count {} must be a positive whole number", n.0)));
            }
            crate::axis::Axis::linspace(a.0, b.0, n.0 as usize)
        }
    };
    let strict = key != "torque_nm";
    for v in [axis.start, axis.stop] {
        if !v.is_finite() || (strict && v <= 0.0) || (!strict && v < 0.0) {
            return Err(err(format!("{v} must be a finite number {}", if strict { "> 0" } else { ">= 0" })));
        }
    }
    Ok(Some(axis))
}

impl Motor {
    /// All keys of the numeric sections, in file order.
    pub fn all_keys() -> Vec<KeyInfo> {
        [
            Geometry::KEYS,
            FrictionLayer::KEYS,
            Stator::KEYS,
            Electrical::KEYS,
            Rotor::KEYS,
            Thermal::KEYS,
            Assembly::KEYS,
            Limits::KEYS,
        ]
        .concat()
    }

    fn values(&self) -> Vec<f64> {
        [
            self.geometry.values(),
            self.friction_layer.values(),
            self.stator.values(),
            self.electrical.values(),
            self.rotor.values(),
            self.thermal.values(),
            self.assembly.values(),
            self.limits.values(),
        ]
        .concat()
    }

    /// Mutable access to a numeric parameter by dotted key (`stator.modal_mass_kg`).
    pub fn param_mut(&mut self, dotted: &str) -> Option<&mut f64> {
        let (sec, key) = dotted.split_once('.')?;
        match sec {
            "geometry" => self.geometry.get_mut(key),
            "friction_layer" => self.friction_layer.get_mut(key),
            "stator" => self.stator.get_mut(key),
            "electrical" => self.electrical.get_mut(key),
            "rotor" => self.rotor.get_mut(key),
            "thermal" => self.thermal.get_mut(key),
            "assembly" => self.assembly.get_mut(key),
            "limits" => self.limits.get_mut(key),
            _ => None,
        }
    }

    /// Value of a numeric parameter by dotted key.
    pub fn param(&self, dotted: &str) -> Option<f64> {
        self.clone().param_mut(dotted).map(|v| *v)
    }

    /// Sets a numeric parameter by dotted key and validates it.
    pub fn set_param(&mut self, dotted: &str, value: f64, source_name: &str) -> Result<(), ParamError> {
        let valid = Self::all_keys().iter().map(|k| format!("{}.{}", k.section, k.key)).collect::<Vec<_>>();
        let slot = self.param_mut(dotted).ok_or_else(|| ParamError {
            source_name: source_name.into(),
            line: None,
            key: dotted.into(),
            reason: format!("unknown parameter; valid keys are: {}", valid.join(", ")),
        })?;
        *slot = value;
        self.validate(source_name, None)
    }

    /// Checks every value (finite, sign, integrality, and the physical consistency checks
    /// the model needs). `text` lets errors point at a line of the TOML source.
    pub fn validate(&self, source_name: &str, text: Option<&str>) -> Result<(), ParamError> {
        // A control character in the name would be written raw into motor files' comments,
        // tables and terminals (an ESC changes the terminal's state); no use for one.
        if let Some((i, c)) = self.name.char_indices().find(|(_, c)| c.is_control()) {
            return Err(ParamError {
                source_name: source_name.into(),
                line: text.and_then(|t| line_of_key(t, "", "name")),
                key: "name".into(),
                reason: format!(
                    "contains the control character U+{:04X} at byte {i}; a motor name must be printable text",
                    c as u32
                ),
            });
        }
        for (info, v) in Self::all_keys().iter().zip(self.values()) {
            if let Some(reason) = info.check.reason(v) {
                return Err(ParamError {
                    source_name: source_name.into(),
                    line: text.and_then(|t| line_of_key(t, info.section, info.key)),
                    key: format!("{}.{}", info.section, info.key),
                    reason,
                });
            }
        }
        // The friction layer must be thinner than the neutral-plane distance is irrelevant;
        // but the contact model needs a contact radius larger than the wave's width scale.
        let k = self.geometry.wave_number / self.geometry.mean_radius_m;
        if k * self.geometry.contact_width_m > 2.0 * std::f64::consts::PI {
            return Err(ParamError {
                source_name: source_name.into(),
                line: text.and_then(|t| line_of_key(t, "geometry", "contact_width_m")),
                key: "geometry.contact_width_m".into(),
                reason: "contact width exceeds one wavelength; check units (metres)".into(),
            });
        }
        self.effects.validate(source_name, text)
    }

    /// Reads a TOML motor file and its optional `[sweep]` table (used by `trum map`).
    pub fn from_toml_str_with_sweep(text: &str, source_name: &str) -> Result<(Motor, SweepTable), ParamError> {
        let motor = Self::from_toml_str(text, source_name)?;
        // The file parsed once already, so this cannot fail on syntax.
        let file: MotorFile = toml::from_str(text).unwrap_or_default();
        let sw = file.sweep.unwrap_or_default();
        let table = SweepTable {
            preload_n: axis_from_spec(&sw.preload_n, "preload_n", text, source_name)?,
            voltage_v: axis_from_spec(&sw.voltage_v, "voltage_v", text, source_name)?,
            frequency_hz: axis_from_spec(&sw.frequency_hz, "frequency_hz", text, source_name)?,
            torque_nm: axis_from_spec(&sw.torque_nm, "torque_nm", text, source_name)?,
        };
        Ok((motor, table))
    }

    /// Reads a TOML motor file. `source_name` is used in error messages (the file name).
    /// A `[sweep]` table is accepted and ignored here (see [`Motor::from_toml_str_with_sweep`]).
    ///
    /// With `preset = "name"` every other key is an override; without it every key of
    /// every section is required. Unknown keys and sections are errors.
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Motor, ParamError> {
        let file: MotorFile = toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| line_of_offset(text, s.start));
            let token = e.span().map(|s| text.get(s.clone()).unwrap_or("").trim().to_string()).unwrap_or_default();
            let msg = e.message().trim().to_string();
            let msg = msg.replace("unknown field", "unknown key").replace("field", "key");
            // serde's untagged-enum message names a Rust type; say what the key accepts.
            if msg.contains("untagged enum AxisSpec") {
                let line = e.span().map(|s| line_of_offset(text, s.start));
                let key = line
                    .and_then(|l| text.lines().nth(l - 1))
                    .and_then(|l| l.split('=').next())
                    .map(|k| format!("sweep.{}", k.trim()))
                    .unwrap_or_else(|| "sweep".into());
                return ParamError {
                    source_name: source_name.into(),
                    line,
                    key,
                    reason: "expected a number or [start, stop, n]".into(),
                };
            }
            let key = if token.len() < 64 && !token.contains('\n') && !token.is_empty() && msg.starts_with("unknown") {
                // qualify the key with the section header above it
                let start = e.span().map(|s| s.start).unwrap_or(0).min(text.len());
                let section = text[..start]
                    .lines()
                    .rev()
                    .find_map(|l| l.trim().strip_prefix('[').map(|h| h.trim_end_matches(']').trim().to_string()))
                    .filter(|sec| !sec.is_empty());
                match section {
                    Some(sec) if sec != token => format!("{sec}.{token}"),
                    _ => token,
                }
            } else {
                line.map(|l| key_on_line(text, l)).unwrap_or_default()
            };
            ParamError { source_name: source_name.into(), line, key, reason: msg }
        })?;
        let mut motor = match &file.preset {
            Some(p) => crate::presets::preset(p).map_err(|mut e| {
                e.source_name = source_name.into();
                e.line = line_of_key(text, "", "preset");
                e.key = "preset".into();
                e
            })?,
            None => Self::from_complete_file(&file, text, source_name)?,
        };
        macro_rules! apply {
            ($($sec:ident),*) => { $( if let Some(p) = &file.$sec { motor.$sec.apply(p); } )* };
        }
        apply!(geometry, friction_layer, stator, electrical, rotor, thermal, assembly, limits);
        if let Some(name) = &file.name {
            motor.name = name.clone();
        } else if file.preset.is_none() {
            motor.name = source_name.to_string();
        }
        motor.preset = file.preset.clone();
        if let Some(t) = &file.effects {
            motor.effects = Effects::from_toml_table(t, text, source_name)?;
        }
        motor.validate(source_name, Some(text))?;
        Ok(motor)
    }

    fn from_complete_file(file: &MotorFile, text: &str, source_name: &str) -> Result<Motor, ParamError> {
        let missing = |sec: &str, key: &str| ParamError {
            source_name: source_name.into(),
            line: None,
            key: if key.is_empty() { sec.to_string() } else { format!("{sec}.{key}") },
            reason: if key.is_empty() {
                "missing section (without `preset = \"...\"` every section and key is required)".into()
            } else {
                "missing key (without `preset = \"...\"` every key is required)".into()
            },
        };
        let _ = text;
        macro_rules! build {
            ($sec:ident, $ty:ident) => {
                match &file.$sec {
                    None => return Err(missing(stringify!($sec), "")),
                    Some(p) => $ty::from_patch(p).map_err(|k| missing(stringify!($sec), k))?,
                }
            };
        }
        Ok(Motor {
            name: String::new(),
            preset: None,
            geometry: build!(geometry, Geometry),
            friction_layer: build!(friction_layer, FrictionLayer),
            stator: build!(stator, Stator),
            electrical: build!(electrical, Electrical),
            rotor: build!(rotor, Rotor),
            thermal: build!(thermal, Thermal),
            assembly: build!(assembly, Assembly),
            effects: Effects::none(),
            limits: Limits::piezoceramic_ring(),
        })
    }

    /// Writes the motor as a complete, commented TOML motor file that
    /// [`Motor::from_toml_str`] reads back to an identical `Motor`. `notes` maps a dotted
    /// key to its provenance (paper value, assumed, calibrated) and is written as comments.
    pub fn to_toml_annotated(&self, header: &str, notes: &dyn Fn(&str) -> Option<String>) -> String {
        let mut s = String::new();
        let header = printable(header);
        for l in header.lines() {
            let _ = writeln!(s, "# {l}").map(|_| ());
            if l.is_empty() {
                s.pop();
                s.pop();
                s.push('\n');
            }
        }
        let _ = writeln!(s, "name = {}", toml_string(&self.name));
        if let Some(p) = &self.preset {
            let _ = writeln!(s, "preset = {}  # every value below overrides the preset's", toml_string(p));
        }
        let mut section = "";
        for (info, v) in Self::all_keys().iter().zip(self.values()) {
            if info.section != section {
                section = info.section;
                let _ = writeln!(s, "\n[{section}]");
            }
            let dotted = format!("{}.{}", info.section, info.key);
            let val = fmt_toml_number(v, info.check == Check::PositiveInteger);
            let note = notes(&dotted).map(|n| format!(" ({})", printable(&n).replace('\n', " "))).unwrap_or_default();
            let _ = writeln!(s, "{} = {}  # {}{}", info.key, val, info.doc, note);
        }
        s.push_str(&self.effects.to_toml());
        s
    }

    /// Plain TOML (no provenance notes).
    pub fn to_toml(&self) -> String {
        self.to_toml_annotated(&format!("trum motor file: {}", self.name), &|_| None)
    }
}

/// The dotted key a TOML error's line holds: `stator.modal_mass_kg` for a key under
/// `[stator]`, `stator` for a table header, empty when the line is neither (the toml
/// crate's messages, `duplicate key` or `invalid type: integer `1``, do not name it).
fn key_on_line(text: &str, line: usize) -> String {
    let Some(l) = text.lines().nth(line.saturating_sub(1)).map(str::trim) else { return String::new() };
    if let Some(h) = l.strip_prefix('[') {
        return h.trim_start_matches('[').split(']').next().unwrap_or("").trim().to_string();
    }
    let Some((k, _)) = l.split_once('=') else { return String::new() };
    let k = k.trim().trim_matches('"');
    if k.is_empty() || k.contains('#') {
        return String::new();
    }
    let section =
        text.lines().take(line.saturating_sub(1)).collect::<Vec<_>>().into_iter().rev().find_map(|l| {
            l.trim().strip_prefix('[').map(|h| h.trim_matches(|c| c == '[' || c == ']').trim().to_string())
        });
    match section {
        Some(sec) if !sec.is_empty() => format!("{sec}.{k}"),
        _ => k.to_string(),
    }
}

/// `s` with every control character but the line feed written as `\u{1b}`: a TOML
/// comment may hold no control character but the tab, and the header of a written motor
/// file carries text from outside (a data file's name).
fn printable(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c.is_control() && c != '\n' {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// A TOML basic string: quotes, backslashes and every control character escaped (TOML
/// allows none of them raw, DEL included).
pub(crate) fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

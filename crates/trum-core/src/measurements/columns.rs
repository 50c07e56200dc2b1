//! The column table of the measurement layout: names, units, ranges, and where each
//! column's cells live.

use super::{Measurements, Row};
use std::fmt;

/// Where a column's values must lie (the layout's "unit / range" column, docs/MEASUREMENTS.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Range {
    /// Strictly positive: `> 0`.
    Positive,
    /// Non-negative: `>= 0`.
    NonNegative,
    /// A fraction: `0 <= x <= 1`.
    Fraction,
    /// A temperature in °C, at or above absolute zero (`>= -273.15`).
    Celsius,
    /// Free text (not a number).
    Text,
}

/// Absolute zero in degrees Celsius, the lower bound of the temperature columns.
pub const ABSOLUTE_ZERO_C: f64 = -273.15;

/// One column of the layout: name with unit suffix, unit, range and meaning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnSpec {
    /// Which column this is.
    pub column: Column,
    /// Column name exactly as it appears in the header.
    pub name: &'static str,
    /// Whether every file must have this column, with a value in every row.
    pub required: bool,
    /// Unit symbol as printed in messages (`N·m`, `rev/min`; empty for a fraction or text).
    pub unit: &'static str,
    /// Unit spelled out, for suggestions (`newton-metres`).
    pub unit_name: &'static str,
    /// Short name of the quantity as used in messages (`load torque`).
    pub quantity: &'static str,
    /// Where the values must lie.
    pub range: Range,
    /// Default plausible range, inclusive (docs/MEASUREMENTS.md, "Plausible ranges"): the
    /// values a bench of a traveling-wave rotary ultrasonic motor can produce, from
    /// millimetre to 150 mm stators, with a decade or more of margin. A value outside is a
    /// typo, a unit slip or a bench fault far more often than a measurement;
    /// [`super::PlausibleRanges`] overrides it.
    pub plausible: (f64, f64),
    /// Meaning, as in docs/MEASUREMENTS.md.
    pub meaning: &'static str,
    /// Other spellings of the quantity (without unit), recognised in headers to suggest
    /// the right column name instead of ignoring the column as unknown.
    pub aliases: &'static [&'static str],
    /// Where the column's cells live in [`Measurements`] and in a [`Row`].
    pub(crate) access: Access,
}

/// Every column of the layout, in the order of docs/MEASUREMENTS.md (and of written files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Column {
    /// `preload_n`: axial preload pressing rotor on stator, N, > 0 (required).
    PreloadN,
    /// `voltage_v`: drive voltage amplitude, zero-to-peak, per phase, V, > 0 (required).
    VoltageV,
    /// `frequency_hz`: drive frequency, Hz, > 0 (required).
    FrequencyHz,
    /// `torque_nm`: load torque applied to the rotor, N·m, >= 0 (required).
    TorqueNm,
    /// `speed_rpm`: mean rotor speed, rev/min, >= 0 (required).
    SpeedRpm,
    /// `input_power_w`: electrical input power, both phases together, W, >= 0.
    InputPowerW,
    /// `current_a`: drive current amplitude per phase, A, >= 0.
    CurrentA,
    /// `efficiency`: output mechanical power / input electrical power, 0..1.
    Efficiency,
    /// `feedback_v`: amplitude of the isolated (feedback) electrode voltage, V, >= 0.
    FeedbackV,
    /// `temperature_c`: near-interface (stator) temperature, °C.
    TemperatureC,
    /// `ambient_c`: ambient temperature, °C.
    AmbientC,
    /// `elapsed_s`: time since the drive was switched on, s, >= 0.
    ElapsedS,
    /// `speed_std_rpm`: standard deviation of speed over at least one revolution, rev/min, >= 0.
    SpeedStdRpm,
    /// `run_id`: text grouping the rows of one run.
    RunId,
}

/// Where a column's cells live in [`Measurements`] and in a [`Row`]: the one place that
/// ties a [`Column`] to its fields (every reader, writer and accessor goes through it).
#[derive(Clone, Copy)]
pub(crate) enum Access {
    /// A required numeric column: a value in every row.
    Required {
        /// The column's values in [`Measurements`].
        cells: fn(&Measurements) -> &Vec<f64>,
        /// The same, to append to.
        cells_mut: fn(&mut Measurements) -> &mut Vec<f64>,
        /// The value in a [`Row`].
        value: fn(&Row) -> f64,
    },
    /// An optional numeric column: absent (`None`), or a cell, empty or not, in every row.
    Optional {
        /// The column's cells in [`Measurements`].
        cells: fn(&Measurements) -> &Option<Vec<Option<f64>>>,
        /// The same, to create and append to.
        cells_mut: fn(&mut Measurements) -> &mut Option<Vec<Option<f64>>>,
        /// The value in a [`Row`], if set.
        value: fn(&Row) -> Option<f64>,
        /// The same, to set.
        value_mut: fn(&mut Row) -> &mut Option<f64>,
    },
    /// The `run_id` text column ([`Measurements::run_id`], [`Row::run_id`]).
    Text,
}

impl Access {
    fn kind(&self) -> &'static str {
        match self {
            Access::Required { .. } => "required",
            Access::Optional { .. } => "optional",
            Access::Text => "text",
        }
    }
}

impl fmt::Debug for Access {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind())
    }
}

/// Accesses compare by kind: the layout's `column` tells columns apart.
impl PartialEq for Access {
    fn eq(&self, other: &Access) -> bool {
        self.kind() == other.kind()
    }
}

/// The [`Access`] of a required column held in the field `$f` of [`Measurements`] and [`Row`].
macro_rules! required {
    ($f:ident) => {
        Access::Required { cells: |m| &m.$f, cells_mut: |m| &mut m.$f, value: |r| r.$f }
    };
}

/// The [`Access`] of an optional column held in the field `$f` of [`Measurements`] and [`Row`].
macro_rules! optional {
    ($f:ident) => {
        Access::Optional { cells: |m| &m.$f, cells_mut: |m| &mut m.$f, value: |r| r.$f, value_mut: |r| &mut r.$f }
    };
}

/// The column table, indexed by `Column as usize`: name, unit, range, meaning, aliases and
/// where the cells live, per column.
pub const COLUMNS: [ColumnSpec; 14] = [
    ColumnSpec {
        column: Column::PreloadN,
        name: "preload_n",
        required: true,
        unit: "N",
        unit_name: "newtons",
        quantity: "preload",
        range: Range::Positive,
        plausible: (1e-3, 1e5),
        meaning: "axial preload pressing rotor on stator",
        aliases: &["preload", "pre_load", "axial_preload", "preload_force", "axial_force"],
        access: required!(preload_n),
    },
    ColumnSpec {
        column: Column::VoltageV,
        name: "voltage_v",
        required: true,
        unit: "V",
        unit_name: "volts, zero-to-peak amplitude per phase",
        quantity: "drive voltage",
        range: Range::Positive,
        plausible: (1e-3, 1e4),
        meaning: "drive voltage amplitude, zero-to-peak, per phase",
        aliases: &["voltage", "drive_voltage", "voltage_amplitude", "volt"],
        access: required!(voltage_v),
    },
    ColumnSpec {
        column: Column::FrequencyHz,
        name: "frequency_hz",
        required: true,
        unit: "Hz",
        unit_name: "hertz",
        quantity: "drive frequency",
        range: Range::Positive,
        plausible: (100.0, 1e7),
        meaning: "drive frequency",
        aliases: &["frequency", "freq", "drive_frequency"],
        access: required!(frequency_hz),
    },
    ColumnSpec {
        column: Column::TorqueNm,
        name: "torque_nm",
        required: true,
        unit: "N·m",
        unit_name: "newton-metres",
        quantity: "load torque",
        range: Range::NonNegative,
        plausible: (0.0, 1e3),
        meaning: "load torque applied to the rotor",
        aliases: &["torque", "load_torque"],
        access: required!(torque_nm),
    },
    ColumnSpec {
        column: Column::SpeedRpm,
        name: "speed_rpm",
        required: true,
        unit: "rpm",
        unit_name: "revolutions per minute",
        quantity: "rotor speed",
        range: Range::NonNegative,
        plausible: (0.0, 1e4),
        meaning: "mean rotor speed (0 = stalled)",
        aliases: &["speed", "rotor_speed", "rotational_speed", "angular_speed", "angular_velocity", "omega"],
        access: required!(speed_rpm),
    },
    ColumnSpec {
        column: Column::InputPowerW,
        name: "input_power_w",
        required: false,
        unit: "W",
        unit_name: "watts",
        quantity: "input power",
        range: Range::NonNegative,
        plausible: (0.0, 1e5),
        meaning: "electrical input power, both phases together",
        aliases: &["input_power", "power_input", "power_in", "electrical_power"],
        access: optional!(input_power_w),
    },
    ColumnSpec {
        column: Column::CurrentA,
        name: "current_a",
        required: false,
        unit: "A",
        unit_name: "amperes, amplitude per phase",
        quantity: "drive current",
        range: Range::NonNegative,
        plausible: (0.0, 1e3),
        meaning: "drive current amplitude per phase",
        aliases: &["current", "drive_current", "phase_current"],
        access: optional!(current_a),
    },
    ColumnSpec {
        column: Column::Efficiency,
        name: "efficiency",
        required: false,
        unit: "",
        unit_name: "a fraction from 0 to 1",
        quantity: "efficiency",
        range: Range::Fraction,
        plausible: (0.0, 1.0),
        meaning: "output mechanical power / input electrical power",
        aliases: &["efficiency", "eta", "eff"],
        access: optional!(efficiency),
    },
    ColumnSpec {
        column: Column::FeedbackV,
        name: "feedback_v",
        required: false,
        unit: "V",
        unit_name: "volts",
        quantity: "feedback voltage",
        range: Range::NonNegative,
        plausible: (0.0, 1e4),
        meaning: "amplitude of the isolated (feedback) electrode voltage",
        aliases: &["feedback", "feedback_voltage"],
        access: optional!(feedback_v),
    },
    ColumnSpec {
        column: Column::TemperatureC,
        name: "temperature_c",
        required: false,
        unit: "°C",
        unit_name: "degrees Celsius",
        quantity: "stator temperature",
        range: Range::Celsius,
        plausible: (-200.0, 500.0),
        meaning: "near-interface (stator) temperature",
        aliases: &["temperature", "temp", "stator_temperature", "stator_temp"],
        access: optional!(temperature_c),
    },
    ColumnSpec {
        column: Column::AmbientC,
        name: "ambient_c",
        required: false,
        unit: "°C",
        unit_name: "degrees Celsius",
        quantity: "ambient temperature",
        range: Range::Celsius,
        plausible: (-100.0, 200.0),
        meaning: "ambient temperature",
        aliases: &["ambient", "ambient_temperature", "ambient_temp", "room_temperature"],
        access: optional!(ambient_c),
    },
    ColumnSpec {
        column: Column::ElapsedS,
        name: "elapsed_s",
        required: false,
        unit: "s",
        unit_name: "seconds",
        quantity: "elapsed time",
        range: Range::NonNegative,
        plausible: (0.0, 1e8),
        meaning: "time since the drive was switched on (time-series rows)",
        aliases: &["elapsed", "elapsed_time", "time_elapsed"],
        access: optional!(elapsed_s),
    },
    ColumnSpec {
        column: Column::SpeedStdRpm,
        name: "speed_std_rpm",
        required: false,
        unit: "rpm",
        unit_name: "revolutions per minute",
        quantity: "speed standard deviation",
        range: Range::NonNegative,
        plausible: (0.0, 1e4),
        meaning: "standard deviation of speed over at least one revolution",
        aliases: &["speed_std", "speed_sd", "speed_stdev", "speed_stddev", "std_speed"],
        access: optional!(speed_std_rpm),
    },
    ColumnSpec {
        column: Column::RunId,
        name: "run_id",
        required: false,
        unit: "",
        unit_name: "text",
        quantity: "run id",
        range: Range::Text,
        plausible: (f64::NEG_INFINITY, f64::INFINITY),
        meaning: "groups the rows of one run (one sweep, one time series)",
        aliases: &["run", "runid", "run_name"],
        access: Access::Text,
    },
];

impl Column {
    /// All columns, in the order of docs/MEASUREMENTS.md and of written files.
    pub const ALL: [Column; 14] = [
        Column::PreloadN,
        Column::VoltageV,
        Column::FrequencyHz,
        Column::TorqueNm,
        Column::SpeedRpm,
        Column::InputPowerW,
        Column::CurrentA,
        Column::Efficiency,
        Column::FeedbackV,
        Column::TemperatureC,
        Column::AmbientC,
        Column::ElapsedS,
        Column::SpeedStdRpm,
        Column::RunId,
    ];

    /// The required columns.
    pub const REQUIRED: [Column; 5] =
        [Column::PreloadN, Column::VoltageV, Column::FrequencyHz, Column::TorqueNm, Column::SpeedRpm];

    /// This column's row of the column table.
    pub fn spec(self) -> &'static ColumnSpec {
        &COLUMNS[self as usize]
    }

    /// Column name as written in the header (`torque_nm`).
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// Whether the column is required.
    pub fn is_required(self) -> bool {
        self.spec().required
    }

    /// Whether the column holds numbers (every column but `run_id`).
    pub fn is_numeric(self) -> bool {
        self.spec().range != Range::Text
    }

    /// The column with exactly this header name, if any.
    pub fn from_name(name: &str) -> Option<Column> {
        Column::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Checks a value against the column's range; `Err` holds why it is rejected
    /// (`is negative`). Non-finite values are rejected for every numeric column.
    pub(super) fn check(self, value: f64) -> Result<(), &'static str> {
        if !value.is_finite() {
            return Err("is not a finite number");
        }
        match self.spec().range {
            Range::Positive if value == 0.0 => Err("is zero"),
            Range::Positive | Range::NonNegative | Range::Fraction if value < 0.0 => Err("is negative"),
            Range::Fraction if value > 1.0 => Err("is greater than 1"),
            Range::Celsius if value < ABSOLUTE_ZERO_C => Err("is below absolute zero"),
            _ => Ok(()),
        }
    }

    /// The requirement as printed in messages (`load torque must be >= 0 N·m`).
    pub(super) fn requirement(self) -> String {
        let s = self.spec();
        let unit = if s.unit.is_empty() { String::new() } else { format!(" {}", s.unit) };
        match s.range {
            Range::Positive => format!("{} must be > 0{unit}", s.quantity),
            Range::NonNegative => format!("{} must be >= 0{unit}", s.quantity),
            Range::Fraction => format!("{} must be between 0 and 1", s.quantity),
            Range::Celsius => format!("{} must be >= {ABSOLUTE_ZERO_C}{unit}", s.quantity),
            Range::Text => format!("{} is text", s.quantity),
        }
    }
}

impl fmt::Display for Column {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

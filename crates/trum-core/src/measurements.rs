//! Measurement files: the CSV layout of `shared/spec/measurements.md`, read and written.
//!
//! The layout is a public interface. [`parse_measurements`] reads it to the letter and
//! rejects anything that does not fit with a [`MeasurementError`] naming the source, the
//! 1-based line, the column and the reason, for example
//!
//! ```text
//! data.csv: line 7, column 'torque_nm': "-0.1" is negative; load torque must be >= 0 N·m
//! ```
//!
//! [`Measurements::to_csv_string`] writes the same layout, so `trum synth` output reads
//! back identically. The table of columns ([`COLUMNS`], [`Column`]) is the single source
//! of truth for names, units and ranges, used by both directions.
//!
//! The reader is a small hand-written RFC 4180 tokenizer rather than the `csv` crate:
//! it must report an unterminated quote (the `csv` crate silently closes it at end of
//! input), keep whitespace inside quoted cells while trimming unquoted ones, and know
//! the line of every cell for the error messages.

use std::fmt;

/// Where a column's values must lie (the spec's "unit / range" column).
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
    /// Meaning, as in the spec.
    pub meaning: &'static str,
    /// Other spellings of the quantity (without unit), recognised in headers to suggest
    /// the right column name instead of ignoring the column as unknown.
    pub aliases: &'static [&'static str],
}

/// Every column of the layout, in the order of the spec (and of written files).
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

/// The column table, indexed by `Column as usize`.
pub const COLUMNS: [ColumnSpec; 14] = [
    ColumnSpec {
        column: Column::PreloadN,
        name: "preload_n",
        required: true,
        unit: "N",
        unit_name: "newtons",
        quantity: "preload",
        range: Range::Positive,
        meaning: "axial preload pressing rotor on stator",
        aliases: &["preload", "pre_load", "axial_preload", "preload_force", "axial_force"],
    },
    ColumnSpec {
        column: Column::VoltageV,
        name: "voltage_v",
        required: true,
        unit: "V",
        unit_name: "volts, zero-to-peak amplitude per phase",
        quantity: "drive voltage",
        range: Range::Positive,
        meaning: "drive voltage amplitude, zero-to-peak, per phase",
        aliases: &["voltage", "drive_voltage", "voltage_amplitude", "volt"],
    },
    ColumnSpec {
        column: Column::FrequencyHz,
        name: "frequency_hz",
        required: true,
        unit: "Hz",
        unit_name: "hertz",
        quantity: "drive frequency",
        range: Range::Positive,
        meaning: "drive frequency",
        aliases: &["frequency", "freq", "drive_frequency"],
    },
    ColumnSpec {
        column: Column::TorqueNm,
        name: "torque_nm",
        required: true,
        unit: "N·m",
        unit_name: "newton-metres",
        quantity: "load torque",
        range: Range::NonNegative,
        meaning: "load torque applied to the rotor",
        aliases: &["torque", "load_torque"],
    },
    ColumnSpec {
        column: Column::SpeedRpm,
        name: "speed_rpm",
        required: true,
        unit: "rev/min",
        unit_name: "revolutions per minute",
        quantity: "rotor speed",
        range: Range::NonNegative,
        meaning: "mean rotor speed (0 = stalled)",
        aliases: &["speed", "rotor_speed", "rotational_speed", "angular_speed", "angular_velocity", "omega"],
    },
    ColumnSpec {
        column: Column::InputPowerW,
        name: "input_power_w",
        required: false,
        unit: "W",
        unit_name: "watts",
        quantity: "input power",
        range: Range::NonNegative,
        meaning: "electrical input power, both phases together",
        aliases: &["input_power", "power_input", "power_in", "electrical_power"],
    },
    ColumnSpec {
        column: Column::CurrentA,
        name: "current_a",
        required: false,
        unit: "A",
        unit_name: "amperes, amplitude per phase",
        quantity: "drive current",
        range: Range::NonNegative,
        meaning: "drive current amplitude per phase",
        aliases: &["current", "drive_current", "phase_current"],
    },
    ColumnSpec {
        column: Column::Efficiency,
        name: "efficiency",
        required: false,
        unit: "",
        unit_name: "a fraction from 0 to 1",
        quantity: "efficiency",
        range: Range::Fraction,
        meaning: "output mechanical power / input electrical power",
        aliases: &["efficiency", "eta", "eff"],
    },
    ColumnSpec {
        column: Column::FeedbackV,
        name: "feedback_v",
        required: false,
        unit: "V",
        unit_name: "volts",
        quantity: "feedback voltage",
        range: Range::NonNegative,
        meaning: "amplitude of the isolated (feedback) electrode voltage",
        aliases: &["feedback", "feedback_voltage"],
    },
    ColumnSpec {
        column: Column::TemperatureC,
        name: "temperature_c",
        required: false,
        unit: "°C",
        unit_name: "degrees Celsius",
        quantity: "stator temperature",
        range: Range::Celsius,
        meaning: "near-interface (stator) temperature",
        aliases: &["temperature", "temp", "stator_temperature", "stator_temp"],
    },
    ColumnSpec {
        column: Column::AmbientC,
        name: "ambient_c",
        required: false,
        unit: "°C",
        unit_name: "degrees Celsius",
        quantity: "ambient temperature",
        range: Range::Celsius,
        meaning: "ambient temperature",
        aliases: &["ambient", "ambient_temperature", "ambient_temp", "room_temperature"],
    },
    ColumnSpec {
        column: Column::ElapsedS,
        name: "elapsed_s",
        required: false,
        unit: "s",
        unit_name: "seconds",
        quantity: "elapsed time",
        range: Range::NonNegative,
        meaning: "time since the drive was switched on (time-series rows)",
        aliases: &["elapsed", "elapsed_time", "time_elapsed"],
    },
    ColumnSpec {
        column: Column::SpeedStdRpm,
        name: "speed_std_rpm",
        required: false,
        unit: "rev/min",
        unit_name: "revolutions per minute",
        quantity: "speed standard deviation",
        range: Range::NonNegative,
        meaning: "standard deviation of speed over at least one revolution",
        aliases: &["speed_std", "speed_sd", "speed_stdev", "speed_stddev", "std_speed"],
    },
    ColumnSpec {
        column: Column::RunId,
        name: "run_id",
        required: false,
        unit: "",
        unit_name: "text",
        quantity: "run id",
        range: Range::Text,
        meaning: "groups the rows of one run (one sweep, one time series)",
        aliases: &["run", "runid", "run_name"],
    },
];

impl Column {
    /// All columns, in the order of the spec and of written files.
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
    fn check(self, value: f64) -> Result<(), &'static str> {
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
    fn requirement(self) -> String {
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

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

/// A measurement file (or synthetic data) that does not fit the layout.
///
/// Displays as `SOURCE: line N, column 'NAME': WHY`; the line part is left out only when
/// no line applies, the column part when the problem is not one column (a ragged row, an
/// empty file, missing columns, which the reason then names).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{source_name}{}: {kind}", location(*.line, .column.as_deref()))]
pub struct MeasurementError {
    /// Where the data came from (file name, or `synthetic data` for the builder).
    pub source_name: String,
    /// 1-based line in the source text.
    pub line: Option<usize>,
    /// Column name as written in the header, when the problem is one column.
    pub column: Option<String>,
    /// What is wrong.
    pub kind: MeasurementErrorKind,
}

fn location(line: Option<usize>, column: Option<&str>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!(": line {l}, column '{c}'"),
        (Some(l), None) => format!(": line {l}"),
        (None, Some(c)) => format!(": column '{c}'"),
        (None, None) => String::new(),
    }
}

/// Why a number cell was rejected before its range was checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NumberIssue {
    /// Text that is not a decimal number.
    NotANumber,
    /// `nan`, `inf`, `infinity` (any case, any sign).
    NotFinite,
    /// `0x…` hexadecimal.
    Hexadecimal,
    /// An exponent marker without digits (`1.5e`, `2e+`), typically a truncated line.
    IncompleteExponent,
    /// A number followed by a unit (`12 N`).
    UnitInCell,
    /// A well-formed number too large for a 64-bit float (`1e400`).
    Overflow,
}

/// Why a header name that is not a column of the layout was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MisnameReason {
    /// The quantity with a unit suffix other than the layout's (`preload_kn`).
    WrongUnit,
    /// The quantity without any unit suffix (`torque`).
    NoUnit,
    /// The right quantity and unit spelled differently (`Preload_N`, `temp_c`).
    Spelling,
}

/// What is wrong, with the structured details.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasurementErrorKind {
    /// The bytes are not UTF-8.
    #[error("byte 0x{byte:02X} at offset {byte_offset} is not valid UTF-8; save the file as UTF-8")]
    NotUtf8 {
        /// 0-based byte offset of the first invalid byte.
        byte_offset: usize,
        /// The invalid byte.
        byte: u8,
    },
    /// Nothing but blank lines (or nothing at all).
    #[error("no data rows: the file is empty; expected a header row and at least one measurement row")]
    EmptyFile,
    /// A header and no rows.
    #[error("no data rows: the header is not followed by any measurement row")]
    NoDataRows,
    /// The first row holds numbers only.
    #[error(
        "the first row looks like data, not a header; the file must start with a header row such as \
         preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm"
    )]
    NoHeader,
    /// A header field is empty.
    #[error("header field {field} is empty; every column needs a name")]
    EmptyColumnName {
        /// 1-based field position in the header.
        field: usize,
    },
    /// A name appears twice in the header.
    #[error("appears twice in the header (fields {first} and {second}); column names must be unique")]
    DuplicateColumn {
        /// 1-based position of the first occurrence.
        first: usize,
        /// 1-based position of the second occurrence.
        second: usize,
    },
    /// A header name that looks like a known quantity in the wrong unit or spelling.
    #[error("{}", misnamed_message(*.expected, *.reason))]
    Misnamed {
        /// The column the name most likely means.
        expected: Column,
        /// How it differs.
        reason: MisnameReason,
    },
    /// Required columns absent from the header.
    #[error("{}", missing_message(.columns))]
    MissingColumns {
        /// The missing required columns, in layout order.
        columns: Vec<Column>,
    },
    /// A quoted cell never closed before the end of the file.
    #[error("a quoted cell opens on this line and is never closed")]
    UnterminatedQuote,
    /// Text between a closing quote and the next comma.
    #[error("unexpected text after the closing quote of a quoted cell")]
    TextAfterQuote,
    /// A row with fewer fields than the header has columns.
    #[error("the row has {found} fields but the header has {expected} columns; this column and the ones after it have no cell")]
    TooFewFields {
        /// Fields in the row.
        found: usize,
        /// Columns in the header.
        expected: usize,
    },
    /// A row with more fields than the header has columns.
    #[error("the row has {found} fields but the header has {expected} columns")]
    TooManyFields {
        /// Fields in the row.
        found: usize,
        /// Columns in the header.
        expected: usize,
    },
    /// An empty cell in a required column.
    #[error("empty cell in a required column; every row needs a {} in {}", .column.spec().quantity, .column.spec().unit)]
    EmptyRequiredCell {
        /// The required column.
        column: Column,
    },
    /// A cell that is not a plain decimal number.
    #[error("{}", number_message(*.column, .text, *.issue))]
    BadNumber {
        /// The numeric column.
        column: Column,
        /// The cell text (trimmed).
        text: String,
        /// What is wrong with it.
        issue: NumberIssue,
    },
    /// A number outside the column's range.
    #[error("\"{text}\" {}; {}", .column.check(*.value).err().unwrap_or("is out of range"), .column.requirement())]
    OutOfRange {
        /// The column.
        column: Column,
        /// The cell text as written (for the builder, the value formatted as it would be written).
        text: String,
        /// The parsed value.
        value: f64,
    },
    /// A `run_id` given to the builder that contains a line break.
    #[error("contains a line break; run ids must be one line")]
    LineBreakInText,
}

fn misnamed_message(expected: Column, reason: MisnameReason) -> String {
    let s = expected.spec();
    let how = match reason {
        MisnameReason::WrongUnit => " in the wrong unit",
        MisnameReason::NoUnit => " without a unit",
        MisnameReason::Spelling => "",
    };
    let exactly = if reason == MisnameReason::Spelling { "exactly " } else { "" };
    format!("looks like {}{how}; trum expects {exactly}'{}' ({})", s.quantity, s.name, s.unit_name)
}

fn missing_message(columns: &[Column]) -> String {
    let list: Vec<String> = columns
        .iter()
        .map(|c| {
            let s = c.spec();
            format!("'{}' ({}, {})", s.name, s.quantity, s.unit)
        })
        .collect();
    let plural = if columns.len() == 1 { "" } else { "s" };
    format!("missing required column{plural} {}", list.join(", "))
}

const NUMBER_FORM: &str = "numbers must be plain decimals such as 12.5 or 1.5e-3";

fn number_message(column: Column, text: &str, issue: NumberIssue) -> String {
    match issue {
        NumberIssue::NotANumber => format!("\"{text}\" is not a number; {NUMBER_FORM}"),
        NumberIssue::NotFinite if column.is_required() => {
            format!(
                "\"{text}\" is not a finite number; {NUMBER_FORM}, and this required column needs a value in every row"
            )
        }
        NumberIssue::NotFinite => {
            format!("\"{text}\" is not a finite number; {NUMBER_FORM}; leave the cell empty if it was not measured")
        }
        NumberIssue::Hexadecimal => format!("\"{text}\" is a hexadecimal number; {NUMBER_FORM}"),
        NumberIssue::IncompleteExponent => {
            format!("\"{text}\" has an exponent without digits (truncated line?); {NUMBER_FORM}")
        }
        NumberIssue::UnitInCell => {
            let unit = column.spec().unit;
            let unit = if unit.is_empty() { String::new() } else { format!(" (in {unit})") };
            format!("\"{text}\" has a unit in the cell; the unit belongs in the column name, the cell holds only the number{unit}")
        }
        NumberIssue::Overflow => format!("\"{text}\" is too large for a 64-bit float"),
    }
}

// ---------------------------------------------------------------------------------------
// Data
// ---------------------------------------------------------------------------------------

/// A header column that is not part of the layout, kept with its raw cells and otherwise
/// ignored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExtraColumn {
    /// Header name as written.
    pub name: String,
    /// Raw (trimmed) cell text of every row.
    pub cells: Vec<String>,
}

/// Measured data, column by column: every `Vec` has one entry per row.
///
/// Optional columns are `None` when the file has no such column ("not measured") and
/// hold `None` cells where the file's cell is empty ("not measured at this row").
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Measurements {
    /// Axial preload pressing rotor on stator, N (> 0).
    pub preload_n: Vec<f64>,
    /// Drive voltage amplitude, zero-to-peak, per phase, V (> 0).
    pub voltage_v: Vec<f64>,
    /// Drive frequency, Hz (> 0).
    pub frequency_hz: Vec<f64>,
    /// Load torque applied to the rotor, N·m (>= 0).
    pub torque_nm: Vec<f64>,
    /// Mean rotor speed, rev/min (>= 0; 0 = stalled).
    pub speed_rpm: Vec<f64>,
    /// Electrical input power, both phases together, W (>= 0).
    pub input_power_w: Option<Vec<Option<f64>>>,
    /// Drive current amplitude per phase, A (>= 0).
    pub current_a: Option<Vec<Option<f64>>>,
    /// Output mechanical power / input electrical power (0..1).
    pub efficiency: Option<Vec<Option<f64>>>,
    /// Amplitude of the isolated (feedback) electrode voltage, V (>= 0).
    pub feedback_v: Option<Vec<Option<f64>>>,
    /// Near-interface (stator) temperature, °C.
    pub temperature_c: Option<Vec<Option<f64>>>,
    /// Ambient temperature, °C.
    pub ambient_c: Option<Vec<Option<f64>>>,
    /// Time since the drive was switched on, s (>= 0).
    pub elapsed_s: Option<Vec<Option<f64>>>,
    /// Standard deviation of speed over at least one revolution, rev/min (>= 0).
    pub speed_std_rpm: Option<Vec<Option<f64>>>,
    /// Text grouping the rows of one run.
    pub run_id: Option<Vec<Option<String>>>,
    /// 1-based line of every row in the source text (for data built in code, the line
    /// the row occupies in [`Measurements::to_csv_string`]'s output).
    pub lines: Vec<usize>,
    /// Columns not in the layout, kept and ignored.
    pub extra_columns: Vec<ExtraColumn>,
    /// Warnings (for example the one naming ignored unknown columns).
    pub warnings: Vec<String>,
}

impl Measurements {
    /// A builder for data made in code (synthetic data, tests).
    pub fn builder() -> MeasurementsBuilder {
        MeasurementsBuilder::new()
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.preload_n.len()
    }

    /// Whether there are no rows (never the case for parsed data).
    pub fn is_empty(&self) -> bool {
        self.preload_n.is_empty()
    }

    /// Whether the column is present (required columns always are).
    pub fn has(&self, column: Column) -> bool {
        match column {
            Column::RunId => self.run_id.is_some(),
            c => c.is_required() || self.optional(c).is_some_and(|v| v.is_some()),
        }
    }

    /// The present columns, in layout order.
    pub fn columns(&self) -> Vec<Column> {
        Column::ALL.into_iter().filter(|&c| self.has(c)).collect()
    }

    /// The value of a numeric column at a row; `None` when the column is absent, the cell
    /// is empty, the row does not exist, or the column is `run_id`.
    pub fn value(&self, column: Column, row: usize) -> Option<f64> {
        match self.required(column) {
            Some(v) => v.get(row).copied(),
            None => self.optional(column)?.as_ref()?.get(row).copied().flatten(),
        }
    }

    /// The `run_id` of a row, if the column is present and the cell is not empty.
    pub fn run_id_at(&self, row: usize) -> Option<&str> {
        self.run_id.as_ref()?.get(row)?.as_deref()
    }

    /// One row as a [`Row`] (the builder's input form), if it exists.
    pub fn row(&self, row: usize) -> Option<Row> {
        if row >= self.len() {
            return None;
        }
        let mut r = Row::new(
            self.value(Column::PreloadN, row)?,
            self.value(Column::VoltageV, row)?,
            self.value(Column::FrequencyHz, row)?,
            self.value(Column::TorqueNm, row)?,
            self.value(Column::SpeedRpm, row)?,
        );
        for c in Column::ALL {
            if !c.is_required() && c.is_numeric() {
                if let Some(slot) = r.optional_mut(c) {
                    *slot = self.value(c, row);
                }
            }
        }
        r.run_id = self.run_id_at(row).map(str::to_string);
        Some(r)
    }

    /// The file's 1-based line of a row.
    pub fn line_of(&self, row: usize) -> Option<usize> {
        self.lines.get(row).copied()
    }

    /// The data in the layout of the spec: a header of the present columns in layout
    /// order, one line per row, `\n` line ends. Numbers are written in their shortest
    /// form that reads back to the same `f64`; empty optional cells stay empty; `run_id`
    /// is quoted when it holds a comma, a quote or surrounding whitespace. Extra columns
    /// are not written. Cells missing from a column shorter than `preload_n` are written
    /// empty.
    pub fn to_csv_string(&self) -> String {
        let cols = self.columns();
        let mut out = String::new();
        let names: Vec<&str> = cols.iter().map(|c| c.name()).collect();
        out.push_str(&names.join(","));
        out.push('\n');
        for row in 0..self.len() {
            for (i, &c) in cols.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                if c == Column::RunId {
                    if let Some(t) = self.run_id_at(row) {
                        out.push_str(&quote_text(t));
                    }
                } else if let Some(v) = self.value(c, row) {
                    out.push_str(&format_number(v));
                }
            }
            out.push('\n');
        }
        out
    }

    fn required(&self, column: Column) -> Option<&Vec<f64>> {
        match column {
            Column::PreloadN => Some(&self.preload_n),
            Column::VoltageV => Some(&self.voltage_v),
            Column::FrequencyHz => Some(&self.frequency_hz),
            Column::TorqueNm => Some(&self.torque_nm),
            Column::SpeedRpm => Some(&self.speed_rpm),
            _ => None,
        }
    }

    fn optional(&self, column: Column) -> Option<&Option<Vec<Option<f64>>>> {
        match column {
            Column::InputPowerW => Some(&self.input_power_w),
            Column::CurrentA => Some(&self.current_a),
            Column::Efficiency => Some(&self.efficiency),
            Column::FeedbackV => Some(&self.feedback_v),
            Column::TemperatureC => Some(&self.temperature_c),
            Column::AmbientC => Some(&self.ambient_c),
            Column::ElapsedS => Some(&self.elapsed_s),
            Column::SpeedStdRpm => Some(&self.speed_std_rpm),
            _ => None,
        }
    }

    fn required_mut(&mut self, column: Column) -> Option<&mut Vec<f64>> {
        match column {
            Column::PreloadN => Some(&mut self.preload_n),
            Column::VoltageV => Some(&mut self.voltage_v),
            Column::FrequencyHz => Some(&mut self.frequency_hz),
            Column::TorqueNm => Some(&mut self.torque_nm),
            Column::SpeedRpm => Some(&mut self.speed_rpm),
            _ => None,
        }
    }

    fn optional_mut(&mut self, column: Column) -> Option<&mut Option<Vec<Option<f64>>>> {
        match column {
            Column::InputPowerW => Some(&mut self.input_power_w),
            Column::CurrentA => Some(&mut self.current_a),
            Column::Efficiency => Some(&mut self.efficiency),
            Column::FeedbackV => Some(&mut self.feedback_v),
            Column::TemperatureC => Some(&mut self.temperature_c),
            Column::AmbientC => Some(&mut self.ambient_c),
            Column::ElapsedS => Some(&mut self.elapsed_s),
            Column::SpeedStdRpm => Some(&mut self.speed_std_rpm),
            _ => None,
        }
    }

    /// Appends one cell to a numeric column (creating an optional column on first use).
    fn push_value(&mut self, column: Column, value: Option<f64>) {
        if let Some(v) = self.required_mut(column) {
            v.push(value.unwrap_or(f64::NAN));
        } else if let Some(slot) = self.optional_mut(column) {
            slot.get_or_insert_with(Vec::new).push(value);
        }
    }
}

/// Shortest text that reads back to the same `f64`: positional for ordinary magnitudes,
/// exponent form (`1.5e-7`) for very small or very large ones.
fn format_number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A text cell, quoted (with doubled quotes) when it would not read back as written.
fn quote_text(t: &str) -> String {
    let needs = t.contains([',', '"', '\r', '\n']) || t.trim() != t || t.is_empty();
    if needs {
        format!("\"{}\"", t.replace('"', "\"\""))
    } else {
        t.to_string()
    }
}

// ---------------------------------------------------------------------------------------
// Builder
// ---------------------------------------------------------------------------------------

/// One row for [`MeasurementsBuilder`]: the required values plus any optional ones.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Row {
    /// Axial preload, N.
    pub preload_n: f64,
    /// Drive voltage amplitude, zero-to-peak, per phase, V.
    pub voltage_v: f64,
    /// Drive frequency, Hz.
    pub frequency_hz: f64,
    /// Load torque, N·m.
    pub torque_nm: f64,
    /// Mean rotor speed, rev/min.
    pub speed_rpm: f64,
    /// Electrical input power, W.
    pub input_power_w: Option<f64>,
    /// Drive current amplitude per phase, A.
    pub current_a: Option<f64>,
    /// Efficiency, 0..1.
    pub efficiency: Option<f64>,
    /// Feedback electrode voltage amplitude, V.
    pub feedback_v: Option<f64>,
    /// Stator temperature, °C.
    pub temperature_c: Option<f64>,
    /// Ambient temperature, °C.
    pub ambient_c: Option<f64>,
    /// Time since drive on, s.
    pub elapsed_s: Option<f64>,
    /// Speed standard deviation, rev/min.
    pub speed_std_rpm: Option<f64>,
    /// Run id (an empty string counts as no run id).
    pub run_id: Option<String>,
}

macro_rules! row_setters {
    ($($fn_name:ident => $field:ident),* $(,)?) => {
        $(
            #[doc = concat!("Sets `", stringify!($field), "`.")]
            pub fn $fn_name(mut self, value: f64) -> Self {
                self.$field = Some(value);
                self
            }
        )*
    };
}

impl Row {
    /// A row with the required values and no optional ones.
    pub fn new(preload_n: f64, voltage_v: f64, frequency_hz: f64, torque_nm: f64, speed_rpm: f64) -> Self {
        Row { preload_n, voltage_v, frequency_hz, torque_nm, speed_rpm, ..Row::default() }
    }

    row_setters!(
        with_input_power_w => input_power_w,
        with_current_a => current_a,
        with_efficiency => efficiency,
        with_feedback_v => feedback_v,
        with_temperature_c => temperature_c,
        with_ambient_c => ambient_c,
        with_elapsed_s => elapsed_s,
        with_speed_std_rpm => speed_std_rpm,
    );

    /// Sets `run_id`.
    pub fn with_run_id(mut self, run_id: impl Into<String>) -> Self {
        self.run_id = Some(run_id.into());
        self
    }

    /// The value of a numeric column (`None` for an unset optional column or `run_id`).
    pub fn value(&self, column: Column) -> Option<f64> {
        match column {
            Column::PreloadN => Some(self.preload_n),
            Column::VoltageV => Some(self.voltage_v),
            Column::FrequencyHz => Some(self.frequency_hz),
            Column::TorqueNm => Some(self.torque_nm),
            Column::SpeedRpm => Some(self.speed_rpm),
            Column::InputPowerW => self.input_power_w,
            Column::CurrentA => self.current_a,
            Column::Efficiency => self.efficiency,
            Column::FeedbackV => self.feedback_v,
            Column::TemperatureC => self.temperature_c,
            Column::AmbientC => self.ambient_c,
            Column::ElapsedS => self.elapsed_s,
            Column::SpeedStdRpm => self.speed_std_rpm,
            Column::RunId => None,
        }
    }

    fn optional_mut(&mut self, column: Column) -> Option<&mut Option<f64>> {
        match column {
            Column::InputPowerW => Some(&mut self.input_power_w),
            Column::CurrentA => Some(&mut self.current_a),
            Column::Efficiency => Some(&mut self.efficiency),
            Column::FeedbackV => Some(&mut self.feedback_v),
            Column::TemperatureC => Some(&mut self.temperature_c),
            Column::AmbientC => Some(&mut self.ambient_c),
            Column::ElapsedS => Some(&mut self.elapsed_s),
            Column::SpeedStdRpm => Some(&mut self.speed_std_rpm),
            _ => None,
        }
    }
}

/// Builds [`Measurements`] in code (for `trum synth` and tests), checking every value
/// against the same ranges as the reader.
///
/// ```
/// use trum_core::measurements::{Column, Measurements, Row};
/// let m = Measurements::builder()
///     .column(Column::FeedbackV)
///     .row(Row::new(100.0, 150.0, 42e3, 0.0, 106.0).with_feedback_v(38.0))
///     .row(Row::new(200.0, 150.0, 42e3, 0.0, 144.0))
///     .build()
///     .unwrap();
/// assert_eq!(m.to_csv_string(), "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,feedback_v\n\
///     100,150,42000,0,106,38\n200,150,42000,0,144,\n");
/// ```
#[derive(Debug, Clone, Default)]
pub struct MeasurementsBuilder {
    columns: Vec<Column>,
    rows: Vec<Row>,
}

impl MeasurementsBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares an optional column present even if no row sets it (all cells empty).
    /// Columns that some row sets are present anyway.
    pub fn column(mut self, column: Column) -> Self {
        self.columns.push(column);
        self
    }

    /// Adds a row.
    pub fn row(mut self, row: Row) -> Self {
        self.rows.push(row);
        self
    }

    /// Adds a row (by reference, for loops).
    pub fn push(&mut self, row: Row) {
        self.rows.push(row);
    }

    /// The checked data. Errors (source `synthetic data`, line = the row's line in the
    /// written file) for a value out of its column's range, a `run_id` with a line break,
    /// or no rows at all.
    pub fn build(self) -> Result<Measurements, MeasurementError> {
        let source = "synthetic data";
        let err = |line: Option<usize>, column: Option<Column>, kind| MeasurementError {
            source_name: source.to_string(),
            line,
            column: column.map(|c| c.name().to_string()),
            kind,
        };
        if self.rows.is_empty() {
            return Err(err(None, None, MeasurementErrorKind::NoDataRows));
        }
        let present: Vec<Column> = Column::ALL
            .into_iter()
            .filter(|&c| {
                c.is_required()
                    || self.columns.contains(&c)
                    || self.rows.iter().any(|r| match c {
                        Column::RunId => r.run_id.as_deref().is_some_and(|t| !t.is_empty()),
                        _ => r.value(c).is_some(),
                    })
            })
            .collect();
        let mut m = Measurements::default();
        for (i, r) in self.rows.iter().enumerate() {
            let line = i + 2;
            for &c in &present {
                if c == Column::RunId {
                    let t = r.run_id.clone().filter(|t| !t.is_empty());
                    if t.as_deref().is_some_and(|t| t.contains(['\r', '\n'])) {
                        return Err(err(Some(line), Some(c), MeasurementErrorKind::LineBreakInText));
                    }
                    m.run_id.get_or_insert_with(Vec::new).push(t);
                    continue;
                }
                let v = r.value(c);
                if let Some(v) = v {
                    if c.check(v).is_err() {
                        let kind = MeasurementErrorKind::OutOfRange { column: c, text: format_number(v), value: v };
                        return Err(err(Some(line), Some(c), kind));
                    }
                }
                m.push_value(c, v);
            }
            m.lines.push(line);
        }
        Ok(m)
    }
}

// ---------------------------------------------------------------------------------------
// Reader
// ---------------------------------------------------------------------------------------

/// One cell as tokenized: text (trimmed unless quoted) and whether it was quoted.
#[derive(Debug)]
struct Field {
    text: String,
    quoted: bool,
}

/// One record: its first line and its fields.
#[derive(Debug)]
struct Record {
    line: usize,
    fields: Vec<Field>,
}

/// A tokenizer error: line, 0-based field index, kind.
type LexError = (usize, usize, MeasurementErrorKind);

/// RFC 4180 tokenizer over validated UTF-8 text. Line ends are `\n`, `\r\n` or `\r`.
/// Works on bytes: every delimiter is ASCII, so slice positions are char boundaries.
struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        Lexer { text, pos: 0, line: 1 }
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    fn slice(&self, from: usize, to: usize) -> &'a str {
        self.text.get(from..to).unwrap_or("")
    }

    /// The next non-blank record, or `None` at the end of the text.
    fn next_record(&mut self) -> Result<Option<Record>, LexError> {
        loop {
            if self.pos >= self.text.len() {
                return Ok(None);
            }
            let line = self.line;
            let mut fields = Vec::new();
            loop {
                let field = self.field(fields.len())?;
                fields.push(field);
                match self.peek() {
                    Some(b',') => self.pos += 1,
                    Some(b'\r') => {
                        self.pos += 1;
                        if self.peek() == Some(b'\n') {
                            self.pos += 1;
                        }
                        self.line += 1;
                        break;
                    }
                    Some(b'\n') => {
                        self.pos += 1;
                        self.line += 1;
                        break;
                    }
                    _ => break,
                }
            }
            let blank = fields.len() == 1 && fields.iter().all(|f| !f.quoted && f.text.is_empty());
            if !blank {
                return Ok(Some(Record { line, fields }));
            }
        }
    }

    /// One field, leaving `pos` on the delimiter (`,`, a line end) or at the end.
    fn field(&mut self, index: usize) -> Result<Field, LexError> {
        let start = self.pos;
        while matches!(self.peek(), Some(b' ' | b'\t')) {
            self.pos += 1;
        }
        if self.peek() != Some(b'"') {
            self.pos = start;
            while !matches!(self.peek(), None | Some(b',' | b'\r' | b'\n')) {
                self.pos += 1;
            }
            return Ok(Field { text: self.slice(start, self.pos).trim().to_string(), quoted: false });
        }
        let open_line = self.line;
        self.pos += 1;
        let mut text = String::new();
        let mut seg = self.pos;
        loop {
            match self.peek() {
                None => return Err((open_line, index, MeasurementErrorKind::UnterminatedQuote)),
                Some(b'"') => {
                    text.push_str(self.slice(seg, self.pos));
                    self.pos += 1;
                    if self.peek() == Some(b'"') {
                        text.push('"');
                        self.pos += 1;
                        seg = self.pos;
                    } else {
                        break;
                    }
                }
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(b'\r') => {
                    self.pos += 1;
                    if self.peek() != Some(b'\n') {
                        self.line += 1;
                    }
                }
                Some(_) => self.pos += 1,
            }
        }
        while matches!(self.peek(), Some(b' ' | b'\t')) {
            self.pos += 1;
        }
        match self.peek() {
            None | Some(b',' | b'\r' | b'\n') => Ok(Field { text, quoted: true }),
            Some(_) => Err((self.line, index, MeasurementErrorKind::TextAfterQuote)),
        }
    }
}

/// Parses a cell of a numeric column: plain decimal or exponent form, optional sign.
fn parse_number(text: &str) -> Result<f64, NumberIssue> {
    let b = text.as_bytes();
    let mut i = 0;
    if matches!(b.first(), Some(b'+' | b'-')) {
        i = 1;
    }
    let digits = |i: &mut usize| {
        let s = *i;
        while b.get(*i).is_some_and(u8::is_ascii_digit) {
            *i += 1;
        }
        *i - s
    };
    let int_digits = digits(&mut i);
    let mut frac_digits = 0;
    if b.get(i) == Some(&b'.') {
        i += 1;
        frac_digits = digits(&mut i);
    }
    let mantissa_ok = int_digits + frac_digits > 0;
    let mut exp_ok = true;
    let mut exp_start = None;
    if mantissa_ok && matches!(b.get(i), Some(b'e' | b'E')) {
        exp_start = Some(i);
        i += 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        exp_ok = digits(&mut i) > 0;
    }
    if mantissa_ok && exp_ok && i == b.len() {
        let v: f64 = text.parse().map_err(|_| NumberIssue::NotANumber)?;
        return if v.is_finite() { Ok(v) } else { Err(NumberIssue::Overflow) };
    }
    // Classify the failure for a helpful message.
    let unsigned = text.trim_start_matches(['+', '-']).to_ascii_lowercase();
    if matches!(unsigned.as_str(), "nan" | "inf" | "infinity") {
        return Err(NumberIssue::NotFinite);
    }
    if unsigned.starts_with("0x") {
        return Err(NumberIssue::Hexadecimal);
    }
    if mantissa_ok && !exp_ok && exp_start.is_some() && i == b.len() {
        return Err(NumberIssue::IncompleteExponent);
    }
    if mantissa_ok && exp_ok {
        let rest = text.get(i..).unwrap_or("").trim();
        let is_unit = !rest.is_empty()
            && rest.len() <= 8
            && rest.chars().all(|c| c.is_alphabetic() || matches!(c, '/' | '·' | '°' | '%' | ' ' | '.' | '*'))
            && text.get(i..).is_some_and(|r| r.starts_with(' ') || rest.starts_with(char::is_alphabetic));
        if is_unit {
            return Err(NumberIssue::UnitInCell);
        }
    }
    Err(NumberIssue::NotANumber)
}

/// Unit spellings recognised after a quantity name in a header (lower case, separators
/// normalised to `_`), used only to suggest the right column name.
#[rustfmt::skip]
const UNIT_TOKENS: &[&str] = &[
    // force
    "n", "kn", "mn", "un", "newton", "newtons", "kgf", "gf", "lbf",
    // voltage
    "v", "kv", "mv", "vpp", "v_pp", "vp", "v_p", "vpk", "vrms", "v_rms", "rms", "volt", "volts",
    // frequency
    "hz", "khz", "mhz",
    // torque
    "nm", "n_m", "mnm", "mn_m", "m_nm", "knm", "nmm", "n_mm", "ncm", "n_cm", "ozin",
    // speed
    "rpm", "r_min", "rev_min", "1_min", "rad_s", "rad_per_s", "rads", "rps", "rev_s", "deg_s",
    // power, current, fraction
    "w", "mw", "kw", "watt", "watts", "a", "ma", "ua", "amp", "amps", "pct", "percent", "frac", "fraction",
    // temperature, time
    "c", "degc", "deg_c", "celsius", "k", "kelvin", "f", "degf", "deg_f",
    "s", "ms", "us", "sec", "secs", "seconds", "min", "h", "hr", "hours",
];

/// Header name normalised for suggestions: lower case, units in brackets joined with `_`,
/// separators (space, `-`, `/`, `.`, `·`, `*`) turned into single `_`, `°` dropped.
fn normalise_name(name: &str) -> String {
    let mut s = String::new();
    for ch in name.chars().flat_map(char::to_lowercase) {
        match ch {
            '°' => {}
            'µ' | 'μ' => s.push('u'),
            c if c.is_alphanumeric() => s.push(c),
            _ => {
                if !s.ends_with('_') {
                    s.push('_');
                }
            }
        }
    }
    s.trim_matches('_').to_string()
}

/// If a header name that is not a column looks like one in the wrong unit or spelling,
/// the column it means and how it differs.
fn misnamed(name: &str) -> Option<(Column, MisnameReason)> {
    let norm = normalise_name(name);
    if norm.is_empty() {
        return None;
    }
    let mut best: Option<(usize, Column, MisnameReason)> = None;
    for spec in &COLUMNS {
        let canonical_stem = spec.name.strip_suffix(unit_suffix(spec)).unwrap_or(spec.name);
        let canonical_stem = canonical_stem.trim_end_matches('_');
        let stems = std::iter::once(canonical_stem).chain(spec.aliases.iter().copied());
        for stem in stems {
            let reason = if norm == stem {
                if spec.unit.is_empty() {
                    MisnameReason::Spelling
                } else {
                    MisnameReason::NoUnit
                }
            } else if let Some(rest) = norm.strip_prefix(stem).and_then(|r| r.strip_prefix('_')) {
                if !UNIT_TOKENS.contains(&rest) {
                    continue;
                }
                if !spec.unit.is_empty() && same_unit(rest, unit_suffix(spec)) {
                    MisnameReason::Spelling
                } else {
                    MisnameReason::WrongUnit
                }
            } else {
                continue;
            };
            // The longest matching stem wins (`speed_std` over `speed`).
            match best {
                Some((len, _, _)) if len >= stem.len() => {}
                _ => best = Some((stem.len(), spec.column, reason)),
            }
        }
    }
    best.map(|(_, c, r)| (c, r))
}

/// Whether a unit token (from [`UNIT_TOKENS`]) spells the layout's unit `suffix`.
fn same_unit(token: &str, suffix: &str) -> bool {
    let same: &[&str] = match suffix {
        "n" => &["n", "newton", "newtons"],
        "v" => &["v", "volt", "volts", "vp", "v_p", "vpk"],
        "hz" => &["hz"],
        "nm" => &["nm", "n_m"],
        "rpm" => &["rpm", "r_min", "rev_min", "1_min"],
        "w" => &["w", "watt", "watts"],
        "a" => &["a", "amp", "amps"],
        "c" => &["c", "degc", "deg_c", "celsius"],
        "s" => &["s", "sec", "secs", "seconds"],
        _ => &[],
    };
    same.contains(&token)
}

/// The unit suffix of a column name (`nm` for `torque_nm`), empty for unitless columns.
fn unit_suffix(spec: &ColumnSpec) -> &'static str {
    if spec.unit.is_empty() {
        return "";
    }
    spec.name.rsplit('_').next().unwrap_or("")
}

/// Reads a measurement file in the layout of the spec.
///
/// `bytes` is the file's content; `source` names it in messages (usually the file name).
/// Follows the spec to the letter: UTF-8 (a leading BOM is skipped), comma-separated,
/// one header row, column order free, blank lines skipped, `\n`, `\r\n` or `\r` line
/// ends, cells trimmed of surrounding whitespace (inside quotes, kept), unknown columns
/// kept in [`Measurements::extra_columns`] with one warning naming them. Errors for:
/// non-UTF-8 bytes, an empty or header-only file, a missing required column, a duplicate
/// or empty column name, a column name that is a known quantity in the wrong unit or
/// spelling (unless the right column is present too), a ragged row, an unterminated
/// quote, an empty required cell, a numeric cell that is not a plain decimal (`nan`,
/// `inf`, hex, text), and a value outside its column's range. The first problem in file
/// order is reported. Never panics.
pub fn parse_measurements(bytes: &[u8], source: &str) -> Result<Measurements, MeasurementError> {
    let err = |line: Option<usize>, column: Option<String>, kind| MeasurementError {
        source_name: source.to_string(),
        line,
        column,
        kind,
    };
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let (line, column) = locate_utf8_error(bytes, e.valid_up_to());
            let byte = bytes.get(e.valid_up_to()).copied().unwrap_or(0);
            return Err(err(Some(line), column, MeasurementErrorKind::NotUtf8 { byte_offset: e.valid_up_to(), byte }));
        }
    };
    let text = text.strip_prefix('\u{FEFF}').unwrap_or(text);
    let mut lexer = Lexer::new(text);
    let header = match lexer.next_record() {
        Ok(Some(h)) => h,
        Ok(None) => return Err(err(Some(1), None, MeasurementErrorKind::EmptyFile)),
        Err((line, _, kind)) => return Err(err(Some(line), None, kind)),
    };
    let header_line = header.line;
    let names: Vec<String> = header.fields.into_iter().map(|f| f.text).collect();
    let at_header = |column: Option<&str>, kind| err(Some(header_line), column.map(str::to_string), kind);

    // Header checks, in order: data instead of a header, empty names, duplicates,
    // misnamed quantities, missing required columns.
    if names.iter().all(|n| parse_number(n).is_ok()) {
        return Err(at_header(None, MeasurementErrorKind::NoHeader));
    }
    if let Some(i) = names.iter().position(String::is_empty) {
        return Err(at_header(None, MeasurementErrorKind::EmptyColumnName { field: i + 1 }));
    }
    for (j, n) in names.iter().enumerate() {
        if let Some(i) = names[..j].iter().position(|m| m == n) {
            return Err(at_header(Some(n), MeasurementErrorKind::DuplicateColumn { first: i + 1, second: j + 1 }));
        }
    }
    let known: Vec<Option<Column>> = names.iter().map(|n| Column::from_name(n)).collect();
    for (n, k) in names.iter().zip(&known) {
        if k.is_some() {
            continue;
        }
        if let Some((expected, reason)) = misnamed(n) {
            if !known.contains(&Some(expected)) {
                return Err(at_header(Some(n), MeasurementErrorKind::Misnamed { expected, reason }));
            }
        }
    }
    let missing: Vec<Column> = Column::REQUIRED.into_iter().filter(|c| !known.contains(&Some(*c))).collect();
    if !missing.is_empty() {
        return Err(at_header(None, MeasurementErrorKind::MissingColumns { columns: missing }));
    }

    let mut m = Measurements::default();
    let unknown: Vec<usize> = (0..names.len()).filter(|&i| known[i].is_none()).collect();
    for &i in &unknown {
        m.extra_columns.push(ExtraColumn { name: names[i].clone(), cells: Vec::new() });
    }
    for c in known.iter().flatten() {
        if *c == Column::RunId {
            m.run_id = Some(Vec::new());
        } else if let Some(slot) = m.optional_mut(*c) {
            *slot = Some(Vec::new());
        }
    }
    if !unknown.is_empty() {
        let list: Vec<String> = unknown.iter().map(|&i| format!("'{}'", names[i])).collect();
        let plural = if unknown.len() == 1 { "" } else { "s" };
        m.warnings.push(format!(
            "{source}: line {header_line}: ignoring unknown column{plural} {} (not part of the measurement layout)",
            list.join(", ")
        ));
    }

    loop {
        let record = match lexer.next_record() {
            Ok(Some(r)) => r,
            Ok(None) => break,
            Err((line, field, kind)) => return Err(err(Some(line), names.get(field).cloned(), kind)),
        };
        let line = record.line;
        let found = record.fields.len();
        if found > names.len() {
            return Err(err(Some(line), None, MeasurementErrorKind::TooManyFields { found, expected: names.len() }));
        }
        if found < names.len() {
            return Err(err(
                Some(line),
                names.get(found).cloned(),
                MeasurementErrorKind::TooFewFields { found, expected: names.len() },
            ));
        }
        for ((field, name), col) in record.fields.into_iter().zip(&names).zip(&known) {
            let cell_err = |kind| err(Some(line), Some(name.clone()), kind);
            let Some(c) = *col else {
                if let Some(x) = m.extra_columns.iter_mut().find(|x| &x.name == name) {
                    x.cells.push(field.text);
                }
                continue;
            };
            if c == Column::RunId {
                let t = Some(field.text).filter(|t| !t.is_empty());
                m.run_id.get_or_insert_with(Vec::new).push(t);
                continue;
            }
            if field.text.trim().is_empty() {
                if c.is_required() {
                    return Err(cell_err(MeasurementErrorKind::EmptyRequiredCell { column: c }));
                }
                m.push_value(c, None);
                continue;
            }
            let text = field.text.trim();
            let value = parse_number(text).map_err(|issue| {
                cell_err(MeasurementErrorKind::BadNumber { column: c, text: text.to_string(), issue })
            })?;
            if c.check(value).is_err() {
                return Err(cell_err(MeasurementErrorKind::OutOfRange { column: c, text: text.to_string(), value }));
            }
            m.push_value(c, Some(value));
        }
        m.lines.push(line);
    }
    if m.is_empty() {
        return Err(err(Some(header_line), None, MeasurementErrorKind::NoDataRows));
    }
    Ok(m)
}

/// Line (1-based) and, when the header before it is intact, column of the first invalid
/// UTF-8 byte at `offset`.
fn locate_utf8_error(bytes: &[u8], offset: usize) -> (usize, Option<String>) {
    let valid = std::str::from_utf8(bytes.get(..offset).unwrap_or(&[])).unwrap_or("");
    let mut line = 1;
    let mut line_start = 0;
    let vb = valid.as_bytes();
    for (i, &b) in vb.iter().enumerate() {
        if b == b'\n' || (b == b'\r' && vb.get(i + 1) != Some(&b'\n')) {
            line += 1;
            line_start = i + 1;
        }
    }
    let valid = valid.strip_prefix('\u{FEFF}').unwrap_or(valid);
    let mut lexer = Lexer::new(valid);
    let header = match lexer.next_record() {
        Ok(Some(h)) if lexer.line <= line && h.line < line => h,
        _ => return (line, None),
    };
    let mut in_quotes = false;
    let mut field = 0;
    for &b in vb.get(line_start..).unwrap_or(&[]) {
        match b {
            b'"' => in_quotes = !in_quotes,
            b',' if !in_quotes => field += 1,
            _ => {}
        }
    }
    (line, header.fields.get(field).map(|f| f.text.clone()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    const SUN2021: &str = include_str!("../../../tests/data/good/measurements/sun2021_table2.csv");

    fn corpus_dir(kind: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data").join(kind).join("measurements")
    }

    fn good(name: &str) -> Measurements {
        let path = corpus_dir("good").join(name);
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        parse_measurements(&bytes, name).unwrap_or_else(|e| panic!("{e}"))
    }

    fn parse_str(text: &str) -> Result<Measurements, MeasurementError> {
        parse_measurements(text.as_bytes(), "t.csv")
    }

    fn message(text: &[u8]) -> String {
        match parse_measurements(text, "t.csv") {
            Ok(m) => format!("parsed {} rows", m.len()),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn column_table_matches_enum() {
        for (i, c) in Column::ALL.into_iter().enumerate() {
            assert_eq!(c as usize, i);
            assert_eq!(COLUMNS[i].column, c);
            assert_eq!(Column::from_name(c.name()), Some(c));
            // The table is self-consistent: each name reads as its own column, correctly spelled.
            assert_eq!(misnamed(c.name()), Some((c, MisnameReason::Spelling)), "{c}");
        }
        let required: Vec<Column> = Column::ALL.into_iter().filter(|c| c.is_required()).collect();
        assert_eq!(required, Column::REQUIRED);
    }

    #[test]
    fn sun2021_table2_parses() {
        let m = parse_measurements(SUN2021.as_bytes(), "sun2021_table2.csv").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.len(), 4);
        assert_eq!(m.preload_n, [100.0, 200.0, 300.0, 400.0]);
        assert_eq!(m.speed_rpm, [106.0, 144.0, 138.0, 89.0]);
        assert_eq!(m.voltage_v, [150.0; 4]);
        assert_eq!(m.frequency_hz, [42000.0; 4]);
        assert_eq!(m.torque_nm, [0.0; 4]);
        assert_eq!(m.feedback_v, Some(vec![Some(38.0), Some(46.0), Some(40.0), Some(34.0)]));
        assert_eq!(m.run_id, Some(vec![Some("sun2021-table2".to_string()); 4]));
        assert!(m.has(Column::FeedbackV) && m.has(Column::RunId) && !m.has(Column::CurrentA));
        assert_eq!(m.lines, [2, 3, 4, 5]);
        assert!(m.warnings.is_empty());
        assert_eq!(m.to_csv_string(), SUN2021.replace("\r\n", "\n"));
    }

    fn synthetic() -> Measurements {
        let b = Measurements::builder()
            .column(Column::Efficiency)
            .row(
                Row::new(100.0, 150.0, 42e3, 0.0, 106.0)
                    .with_input_power_w(12.345678901234567)
                    .with_feedback_v(38.0)
                    .with_temperature_c(-12.5)
                    .with_run_id("sweep, \"A\""),
            )
            .row(
                Row::new(250.5, 1e-300, 41_999.999_999_999_99, 1.5e-3, 0.1 + 0.2)
                    .with_elapsed_s(1e20)
                    .with_run_id(" lead"),
            )
            .row(Row::new(f64::MIN_POSITIVE, f64::MAX, 5e-324, 0.0, 0.0).with_current_a(0.6).with_speed_std_rpm(0.75))
            .row(Row::new(400.0, 150.0, 42e3, 0.3, 12.0).with_ambient_c(ABSOLUTE_ZERO_C).with_run_id(""));
        b.build().unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn round_trip_write_parse_identity() {
        let m = synthetic();
        assert_eq!(m.len(), 4);
        assert!(m.has(Column::Efficiency) && m.efficiency == Some(vec![None; 4]));
        assert!(!m.has(Column::ElapsedS) || m.elapsed_s.as_ref().is_some_and(|v| v[0].is_none()));
        let text = m.to_csv_string();
        let back = parse_measurements(text.as_bytes(), "synth.csv").unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back, m, "{text}");
        assert_eq!(back.to_csv_string(), text);
        assert_eq!(back.run_id_at(0), Some("sweep, \"A\""));
        assert_eq!(back.run_id_at(1), Some(" lead"));
        assert_eq!(back.run_id_at(3), None);
        for row in 0..m.len() {
            assert_eq!(back.row(row), m.row(row));
        }
    }

    #[test]
    fn rows_rebuild_identically() {
        let m = synthetic();
        let mut b = MeasurementsBuilder::new().column(Column::Efficiency);
        for row in 0..m.len() {
            b.push(m.row(row).unwrap_or_default());
        }
        assert_eq!(b.build(), Ok(m));
    }

    #[test]
    fn builder_checks_ranges() {
        let e = Measurements::builder().row(Row::new(100.0, 150.0, 42e3, -0.1, 10.0)).build().err();
        assert_eq!(
            e.map(|e| e.to_string()).as_deref(),
            Some("synthetic data: line 2, column 'torque_nm': \"-0.1\" is negative; load torque must be >= 0 N·m")
        );
        let e = Measurements::builder()
            .row(Row::new(100.0, 150.0, 42e3, 0.0, 10.0))
            .row(Row::new(100.0, 150.0, 42e3, 0.0, f64::NAN))
            .build()
            .err();
        assert_eq!(
            e.map(|e| e.to_string()).as_deref(),
            Some("synthetic data: line 3, column 'speed_rpm': \"NaN\" is not a finite number; rotor speed must be >= 0 rev/min")
        );
        let e = Measurements::builder().row(Row::new(1.0, 1.0, 1.0, 0.0, 0.0).with_run_id("a\nb")).build().err();
        assert_eq!(e.map(|e| e.kind), Some(MeasurementErrorKind::LineBreakInText));
        assert_eq!(Measurements::builder().build().err().map(|e| e.kind), Some(MeasurementErrorKind::NoDataRows));
    }

    #[test]
    fn bad_corpus_gives_exact_messages() {
        let dir = corpus_dir("bad");
        let mut entries: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "csv"))
            .collect();
        entries.sort();
        assert!(entries.len() >= 20, "only {} bad files", entries.len());
        let mut failures = Vec::new();
        for path in &entries {
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
            let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{name}: {e}"));
            let expected_path = path.with_extension("expected");
            let expected = std::fs::read_to_string(&expected_path)
                .unwrap_or_else(|e| panic!("{}: {e}", expected_path.display()))
                .trim_end()
                .replace("{source}", &name);
            let got = match parse_measurements(&bytes, &name) {
                Ok(m) => format!("parsed {} rows without error", m.len()),
                Err(e) => {
                    // Structured fields agree with the message.
                    assert_eq!(e.source_name, name);
                    assert!(e.line.is_some(), "{name}: no line");
                    e.to_string()
                }
            };
            if got != expected {
                failures.push(format!("{name}:\n  expected: {expected}\n  got:      {got}"));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    #[test]
    fn every_expected_file_has_a_csv() {
        let dir = corpus_dir("bad");
        for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{e}")).flatten() {
            let p = e.path();
            let ext = p.extension().and_then(|x| x.to_str()).unwrap_or_default();
            assert!(ext == "csv" || ext == "expected", "stray file {}", p.display());
            assert!(p.with_extension("csv").exists() && p.with_extension("expected").exists(), "{}", p.display());
        }
    }

    #[test]
    fn good_corpus_parses_and_round_trips() {
        let dir = corpus_dir("good");
        let mut n = 0;
        for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{e}")).flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            let m = good(&name);
            let back = parse_str(&m.to_csv_string()).unwrap_or_else(|e| panic!("{name}: {e}"));
            for c in Column::ALL {
                assert_eq!(back.has(c), m.has(c), "{name}: {c}");
                for row in 0..m.len() {
                    assert_eq!(back.value(c, row), m.value(c, row), "{name}: {c} row {row}");
                }
            }
            assert_eq!(back.run_id, m.run_id, "{name}");
            n += 1;
        }
        assert!(n >= 7);
    }

    #[test]
    fn bom_and_crlf() {
        let m = good("bom_crlf.csv");
        assert_eq!(m.len(), 4);
        assert_eq!(m.lines, [2, 3, 4, 5]);
        assert_eq!(m.run_id_at(3), Some("bench-a"));
        assert!(m.warnings.is_empty());
    }

    #[test]
    fn blank_lines_skipped_and_lines_counted() {
        let m = good("blank_lines.csv");
        assert_eq!(m.len(), 3);
        assert_eq!(m.lines, [4, 6, 9]);
        assert_eq!(m.speed_rpm, [106.0, 144.0, 138.0]);
    }

    #[test]
    fn reordered_columns() {
        let m = good("reordered_columns.csv");
        assert_eq!(m.preload_n, [100.0, 200.0]);
        assert_eq!(m.voltage_v, [150.0, 150.0]);
        assert_eq!(m.speed_rpm, [106.0, 144.0]);
        assert_eq!(m.feedback_v, Some(vec![Some(38.0), Some(46.0)]));
        assert_eq!(
            m.to_csv_string().lines().next(),
            Some("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,feedback_v,run_id")
        );
    }

    #[test]
    fn unknown_columns_one_warning() {
        let m = good("unknown_columns.csv");
        assert_eq!(m.len(), 2);
        assert_eq!(
            m.warnings,
            ["unknown_columns.csv: line 1: ignoring unknown columns 'operator', 'notes' (not part of the measurement layout)"]
        );
        assert_eq!(m.extra_columns.len(), 2);
        assert_eq!(
            m.extra_columns[1],
            ExtraColumn { name: "notes".into(), cells: vec!["first point".into(), String::new()] }
        );
        assert!(!m.to_csv_string().contains("operator"));
    }

    #[test]
    fn misnamed_column_beside_the_right_one_is_ignored_with_warning() {
        let m = good("misnamed_beside_correct.csv");
        assert_eq!(m.preload_n, [100.0]);
        assert_eq!(m.warnings.len(), 1);
        assert!(m.warnings[0].contains("'preload_kn'"));
    }

    #[test]
    fn optional_cells_quotes_and_whitespace() {
        let m = good("optional_cells.csv");
        assert_eq!(m.len(), 3);
        assert_eq!(m.frequency_hz, [42000.0; 3]);
        assert_eq!(m.torque_nm, [0.05, 0.1, 0.2]);
        assert_eq!(m.speed_rpm, [90.0, 80.0, 60.0]);
        assert_eq!(m.input_power_w, Some(vec![Some(12.5), None, Some(13.75)]));
        assert_eq!(m.current_a, Some(vec![Some(0.22), None, Some(0.6)]));
        assert_eq!(m.efficiency, Some(vec![None, Some(0.31), Some(0.4)]));
        assert_eq!(m.speed_std_rpm, Some(vec![Some(1.5), None, Some(0.8)]));
        assert_eq!(m.run_id, Some(vec![Some("sweep, \"A\"".into()), Some("plain text".into()), None]));
        assert!(!m.has(Column::FeedbackV) && m.feedback_v.is_none());
        assert_eq!(m.value(Column::Efficiency, 0), None);
        assert_eq!(m.value(Column::RunId, 0), None);
        assert_eq!(m.value(Column::PreloadN, 9), None);
    }

    #[test]
    fn time_series() {
        let m = good("time_series.csv");
        assert_eq!(m.elapsed_s, Some(vec![Some(0.0), Some(60.0), Some(120.0), Some(180.0)]));
        assert_eq!(m.temperature_c, Some(vec![Some(22.5), Some(27.25), Some(31.0), Some(-1.5)]));
        assert_eq!(m.ambient_c.as_ref().map(Vec::len), Some(4));
    }

    #[test]
    fn number_grammar() {
        for ok in ["0", "1", "-0", "+2.5", "1.", ".5", "1e3", "1E-3", "1.5e+2", "007", "4.2e4"] {
            assert!(parse_number(ok).is_ok(), "{ok}");
        }
        for (bad, issue) in [
            ("nan", NumberIssue::NotFinite),
            ("NaN", NumberIssue::NotFinite),
            ("-inf", NumberIssue::NotFinite),
            ("Infinity", NumberIssue::NotFinite),
            ("0x10", NumberIssue::Hexadecimal),
            ("1e", NumberIssue::IncompleteExponent),
            ("1.5e-", NumberIssue::IncompleteExponent),
            ("12 N", NumberIssue::UnitInCell),
            ("0.3rpm", NumberIssue::UnitInCell),
            ("1e999", NumberIssue::Overflow),
            ("", NumberIssue::NotANumber),
            (".", NumberIssue::NotANumber),
            ("-", NumberIssue::NotANumber),
            ("e5", NumberIssue::NotANumber),
            ("1_000", NumberIssue::NotANumber),
            ("1 000", NumberIssue::NotANumber),
            ("1..2", NumberIssue::NotANumber),
            ("--1", NumberIssue::NotANumber),
            ("１", NumberIssue::NotANumber),
        ] {
            assert_eq!(parse_number(bad), Err(issue), "{bad}");
        }
    }

    #[test]
    fn misnamed_headers() {
        use MisnameReason::*;
        for (name, expect) in [
            ("preload_kn", Some((Column::PreloadN, WrongUnit))),
            ("Preload (N)", Some((Column::PreloadN, Spelling))),
            ("speed_rad_s", Some((Column::SpeedRpm, WrongUnit))),
            ("speed [rad/s]", Some((Column::SpeedRpm, WrongUnit))),
            ("speed_std_rad_s", Some((Column::SpeedStdRpm, WrongUnit))),
            ("torque_mnm", Some((Column::TorqueNm, WrongUnit))),
            ("Torque (N·m)", Some((Column::TorqueNm, Spelling))),
            ("speed (rev/min)", Some((Column::SpeedRpm, Spelling))),
            ("voltage_vpp", Some((Column::VoltageV, WrongUnit))),
            ("Temperature [°C]", Some((Column::TemperatureC, Spelling))),
            ("input_power_mw", Some((Column::InputPowerW, WrongUnit))),
            ("elapsed_min", Some((Column::ElapsedS, WrongUnit))),
            ("torque", Some((Column::TorqueNm, NoUnit))),
            ("voltage_vrms", Some((Column::VoltageV, WrongUnit))),
            ("temperature_k", Some((Column::TemperatureC, WrongUnit))),
            ("temp_c", Some((Column::TemperatureC, Spelling))),
            ("ambient_temperature_c", Some((Column::AmbientC, Spelling))),
            ("Run ID", Some((Column::RunId, Spelling))),
            ("efficiency_pct", Some((Column::Efficiency, WrongUnit))),
            ("torque_sensor_id", None),
            ("operator", None),
            ("time", None),
            ("notes", None),
        ] {
            assert_eq!(misnamed(name), expect, "{name}");
        }
    }

    #[test]
    fn utf8_error_positions() {
        assert_eq!(
            message(b"preload_\xffn,voltage_v\n"),
            "t.csv: line 1: byte 0xFF at offset 8 is not valid UTF-8; save the file as UTF-8"
        );
        // Truncated multi-byte sequence at the very end.
        assert_eq!(
            message(b"preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n1,2,3,4,\xc3"),
            "t.csv: line 2, column 'speed_rpm': byte 0xC3 at offset 61 is not valid UTF-8; save the file as UTF-8"
        );
        // A quoted comma does not shift the column.
        assert_eq!(
            message(b"run_id,preload_n\r\n\"a,b\",\x80\r\n"),
            "t.csv: line 2, column 'preload_n': byte 0x80 at offset 24 is not valid UTF-8; save the file as UTF-8"
        );
    }

    #[test]
    fn quoted_cells_keep_whitespace_and_line_breaks() {
        let m = parse_str(
            "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,run_id\n1,2,3,0,0,\"a\nb\"\n2,2,3,0,0, \"  x \" \n",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.run_id, Some(vec![Some("a\nb".into()), Some("  x ".into())]));
        assert_eq!(m.lines, [2, 4]);
        // Numbers may be quoted too.
        let m = parse_str("\"preload_n\",voltage_v,frequency_hz,torque_nm,speed_rpm\n\"1.5\",2,3,0,0\r")
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.preload_n, [1.5]);
    }

    #[test]
    fn errors_are_structured() {
        let e = parse_str("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n1,2,3,-1,0\n").err();
        let e = e.unwrap_or_else(|| panic!("accepted"));
        assert_eq!(e.source_name, "t.csv");
        assert_eq!(e.line, Some(2));
        assert_eq!(e.column.as_deref(), Some("torque_nm"));
        assert_eq!(
            e.kind,
            MeasurementErrorKind::OutOfRange { column: Column::TorqueNm, text: "-1".into(), value: -1.0 }
        );
    }

    #[test]
    fn first_error_in_file_order_wins() {
        // The bad cell on line 2 comes before the ragged row on line 3.
        assert_eq!(
            message(b"preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n1,2,3,0,x\n1,2\n"),
            "t.csv: line 2, column 'speed_rpm': \"x\" is not a number; numbers must be plain decimals such as 12.5 or 1.5e-3"
        );
    }

    /// Tiny deterministic generator (no dependency) for the no-panic sweep.
    fn lcg(state: &mut u64) -> u64 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        *state >> 33
    }

    #[test]
    fn never_panics_on_mutated_input() {
        let seeds: Vec<Vec<u8>> = std::fs::read_dir(corpus_dir("good"))
            .into_iter()
            .flatten()
            .chain(std::fs::read_dir(corpus_dir("bad")).into_iter().flatten())
            .flatten()
            .filter_map(|e| std::fs::read(e.path()).ok())
            .collect();
        assert!(!seeds.is_empty());
        let alphabet = b",\"\r\n \t0.e-+x\xef\xbb\xbf\xff\xc3";
        let mut s = 42_u64;
        for i in 0..20_000 {
            let mut b = seeds[i % seeds.len()].clone();
            for _ in 0..=(lcg(&mut s) % 4) {
                let pos = if b.is_empty() { 0 } else { (lcg(&mut s) as usize) % (b.len() + 1) };
                let byte = alphabet[(lcg(&mut s) as usize) % alphabet.len()];
                match lcg(&mut s) % 3 {
                    0 => b.insert(pos, byte),
                    1 if pos < b.len() => {
                        b.remove(pos);
                    }
                    _ if pos < b.len() => b[pos] = byte,
                    _ => b.push(byte),
                }
            }
            match parse_measurements(&b, "fuzz.csv") {
                Ok(m) => {
                    let n = m.len();
                    assert!(n > 0 && m.lines.len() == n);
                    // Whatever parsed writes and reads back to the same values.
                    let back = parse_str(&m.to_csv_string()).unwrap_or_else(|e| panic!("{e}"));
                    assert_eq!(back.len(), n);
                }
                Err(e) => {
                    let msg = e.to_string();
                    assert!(msg.starts_with("fuzz.csv: line "), "{msg}");
                }
            }
        }
    }
}

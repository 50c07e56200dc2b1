//! Measurement files: the CSV layout of docs/MEASUREMENTS.md, read and written.
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
//!
//! Files: `columns` (the column table), `read` (the reader), `write` (the writer),
//! `builder` (data made in code, checked as the reader checks a file), `error` (the
//! errors and their messages).

mod builder;
mod columns;
mod error;
mod plausible;
mod read;
mod write;

pub use builder::MeasurementsBuilder;
use columns::Access;
pub use columns::{Column, ColumnSpec, Range, ABSOLUTE_ZERO_C, COLUMNS};
pub use error::{MeasurementError, MeasurementErrorKind, MisnameReason, NumberIssue};
pub use plausible::PlausibleRanges;
pub(crate) use plausible::PlausibleTable;
pub use read::{parse_measurements, parse_measurements_with};

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

    fn required(&self, column: Column) -> Option<&Vec<f64>> {
        match column.spec().access {
            Access::Required { cells, .. } => Some(cells(self)),
            _ => None,
        }
    }

    fn optional(&self, column: Column) -> Option<&Option<Vec<Option<f64>>>> {
        match column.spec().access {
            Access::Optional { cells, .. } => Some(cells(self)),
            _ => None,
        }
    }

    fn required_mut(&mut self, column: Column) -> Option<&mut Vec<f64>> {
        match column.spec().access {
            Access::Required { cells_mut, .. } => Some(cells_mut(self)),
            _ => None,
        }
    }

    fn optional_mut(&mut self, column: Column) -> Option<&mut Option<Vec<Option<f64>>>> {
        match column.spec().access {
            Access::Optional { cells_mut, .. } => Some(cells_mut(self)),
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
        match column.spec().access {
            Access::Required { value, .. } => Some(value(self)),
            Access::Optional { value, .. } => value(self),
            Access::Text => None,
        }
    }

    fn optional_mut(&mut self, column: Column) -> Option<&mut Option<f64>> {
        match column.spec().access {
            Access::Optional { value_mut, .. } => Some(value_mut(self)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests;

//! Measurement data made in code (`trum synth`, tests), checked against the same ranges
//! as the reader.

use super::write::format_number;
use super::{Column, MeasurementError, MeasurementErrorKind, Measurements, Row};

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

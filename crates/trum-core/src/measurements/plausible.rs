//! Plausible ranges of the measured columns: a second check after the layout's own ranges
//! (`> 0`, `>= 0`, a fraction), which every finite value of the right sign passes. A
//! speed of 10^5 rev/min, a preload of 1e308 N or 5e-324 N fits the layout but no bench of
//! a traveling-wave ultrasonic motor; fitted anyway, one such row dominates every sum of
//! squares and the diagnosis names an effect with confidence from nothing. The defaults
//! are [`super::ColumnSpec::plausible`]; each can be replaced or lifted.

use super::{Column, COLUMNS};

/// A plausible range, inclusive, per numeric column.
#[derive(Debug, Clone, PartialEq)]
pub struct PlausibleRanges {
    ranges: [(f64, f64); COLUMNS.len()],
}

impl Default for PlausibleRanges {
    fn default() -> Self {
        let mut ranges = [(f64::NEG_INFINITY, f64::INFINITY); COLUMNS.len()];
        for (r, c) in ranges.iter_mut().zip(COLUMNS.iter()) {
            *r = c.plausible;
        }
        PlausibleRanges { ranges }
    }
}

impl PlausibleRanges {
    /// No plausibility check at all (the layout's ranges still apply).
    pub fn unlimited() -> Self {
        PlausibleRanges { ranges: [(f64::NEG_INFINITY, f64::INFINITY); COLUMNS.len()] }
    }

    /// The range of `column`, in its unit.
    pub fn get(&self, column: Column) -> (f64, f64) {
        self.ranges[column as usize]
    }

    /// Replaces the range of `column` (either end may be infinite: no bound there).
    pub fn set(&mut self, column: Column, low: f64, high: f64) {
        self.ranges[column as usize] = (low, high);
    }

    /// Whether `value` of `column` is plausible.
    pub fn contains(&self, column: Column, value: f64) -> bool {
        let (lo, hi) = self.get(column);
        value >= lo && value <= hi
    }

    /// Applies `COLUMN=LOW:HIGH` (either end may be left empty: no bound there) or
    /// `COLUMN=any` (no bound at all). The error says what is wrong, naming the column.
    pub fn parse_assignment(&mut self, spec: &str) -> Result<(), String> {
        let (name, range) =
            spec.split_once('=').ok_or_else(|| "expected COLUMN=LOW:HIGH (or COLUMN=any)".to_string())?;
        let name = name.trim();
        let column = Column::from_name(name).filter(|c| c.is_numeric()).ok_or_else(|| {
            let names: Vec<&str> = COLUMNS.iter().filter(|c| c.column.is_numeric()).map(|c| c.name).collect();
            format!("'{name}' is not a numeric measurement column; valid columns are: {}", names.join(", "))
        })?;
        let range = range.trim();
        if range.eq_ignore_ascii_case("any") {
            self.set(column, f64::NEG_INFINITY, f64::INFINITY);
            return Ok(());
        }
        let (lo, hi) = range.split_once(':').ok_or_else(|| format!("{name}: expected LOW:HIGH, got '{range}'"))?;
        let bound = |t: &str, open: f64| -> Result<f64, String> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(open);
            }
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(format!("{name}: '{t}' is not a finite number (leave an end empty for no bound)")),
            }
        };
        let (lo, hi) = (bound(lo, f64::NEG_INFINITY)?, bound(hi, f64::INFINITY)?);
        if lo > hi {
            return Err(format!("{name}: the low end {lo} is above the high end {hi}"));
        }
        self.set(column, lo, hi);
        Ok(())
    }
}

/// `0 to 10000 rev/min`, `at most 1000 N·m`, ...
pub(super) fn describe(column: Column, (lo, hi): (f64, f64)) -> String {
    let unit = column.spec().unit;
    let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    match (lo.is_finite(), hi.is_finite()) {
        (true, true) => format!("{lo} to {hi}{unit}"),
        (true, false) => format!("at least {lo}{unit}"),
        (false, true) => format!("at most {hi}{unit}"),
        (false, false) => "any value".into(),
    }
}

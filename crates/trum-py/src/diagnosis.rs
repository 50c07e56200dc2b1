//! `trum.diagnose`: the sim-to-real diagnosis over a measurement CSV (docs/MEASUREMENTS.md),
//! the same document `trum diagnose --json` writes (docs/DIAGNOSIS_JSON.md; built by
//! trum_core::diagnose::json).

use crate::{detached, input_err, PyMotor};
use pyo3::prelude::*;
use trum_core::bench::observations;
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::{diagnose, DiagnoseOptions};
use trum_core::measurements::{parse_measurements_with, PlausibleRanges};

/// Diagnoses the measurement CSV `data` (its bytes; `source` names it in messages) against
/// `motor`. Returns the JSON document as text and the reader's warnings. Bad files raise
/// `trum.InputError` naming the file, line and column; data that cannot support a
/// held-out test raise `trum.InputError` too. `plausible` replaces columns' plausible
/// ranges (`COLUMN=LOW:HIGH` or `COLUMN=any`, as the CLI's `--plausible`). The work runs
/// with the GIL released.
#[pyfunction]
#[pyo3(signature = (motor, data, source, motor_source, exact_cv = false, plausible = Vec::new()))]
pub fn diagnose_csv(
    py: Python<'_>,
    motor: &Bound<'_, PyMotor>,
    data: Vec<u8>,
    source: String,
    motor_source: String,
    exact_cv: bool,
    plausible: Vec<String>,
) -> PyResult<(String, Vec<String>)> {
    let m = motor.get().inner.clone();
    let mut ranges = PlausibleRanges::default();
    for spec in &plausible {
        ranges.parse_assignment(spec).map_err(|e| input_err(py, format!("plausible '{spec}': {e}")))?;
    }
    let out = detached(py, move || -> Result<(String, Vec<String>), String> {
        let meas = parse_measurements_with(&data, &source, &ranges).map_err(|e| e.to_string())?;
        let bench = observations(&meas, &m);
        let opts = DiagnoseOptions { exact_cv, ..DiagnoseOptions::default() };
        let d =
            diagnose(&m, &bench.rows, &bench.groups, &opts).map_err(|e| format!("cannot diagnose '{source}': {e}"))?;
        let src = Provenance { motor_name: &m.name, motor_source: &motor_source, data: &source, lines: &bench.lines };
        Ok((to_json(&d, &src).to_string(), meas.warnings.clone()))
    })?;
    out.map_err(|e| input_err(py, e))
}

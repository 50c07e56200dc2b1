//! `trum.diagnose`: the sim-to-real diagnosis over a measurement CSV (docs/MEASUREMENTS.md),
//! the same document `trum diagnose --json` writes (docs/DIAGNOSIS_JSON.md; built by
//! trum_core::diagnose::json).

use crate::{detached, input_err, PyMotor};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use trum_core::bench::{observations, BenchData};
use trum_core::calibrate::{rescale_uncertainties, Calibration, FitOptions};
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::{diagnose, stated_noise_from_texts, DiagnoseOptions};
use trum_core::measurements::{parse_measurements_with, Measurements, PlausibleRanges};

/// Diagnoses the measurement CSV `data` (its bytes; `source` names it in messages) against
/// `motor`. Returns the JSON document as text and the reader's warnings. Bad files raise
/// `trum.InputError` naming the file, line and column; data that cannot support a
/// held-out test raise `trum.InputError` too. `plausible` replaces columns' plausible
/// ranges (`COLUMN=LOW:HIGH` or `COLUMN=any`, as the CLI's `--plausible`), after the
/// `[plausible]` table of `plausible_toml` (a TOML file's text and name). The priors of
/// the calibration are the `[tolerances]` table of `tolerances_toml` (text, name), then the
/// `(key, value)` pairs of `tolerances` ([`tolerances_in_force`]). `sensor_noise`: the
/// sensors' stated noise levels, `COLUMN=SD[,REL]` as the CLI's `--sensor-noise`. The work
/// runs with the GIL released.
#[pyfunction]
#[pyo3(signature = (motor, data, source, motor_source, exact_cv = false, plausible = Vec::new(), plausible_toml = None, tolerances = Vec::new(), tolerances_toml = None, sensor_noise = Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose_csv(
    py: Python<'_>,
    motor: &Bound<'_, PyMotor>,
    data: Vec<u8>,
    source: String,
    motor_source: String,
    exact_cv: bool,
    plausible: Vec<String>,
    plausible_toml: Option<(String, String)>,
    tolerances: Vec<(String, f64)>,
    tolerances_toml: Option<(String, String)>,
    sensor_noise: Vec<String>,
) -> PyResult<(String, Vec<String>)> {
    let m = motor.get().inner.clone();
    let ranges = plausible_ranges(py, &plausible, plausible_toml.as_ref())?;
    let tolerances = tolerances_in_force(py, &tolerances, tolerances_toml.as_ref())?;
    let stated_noise =
        stated_noise_from_texts(&sensor_noise, "sensor_noise").map_err(|e| input_err(py, e.to_string()))?;
    let out = detached(py, move || -> Result<(String, Vec<String>), String> {
        let meas = parse_measurements_with(&data, &source, &ranges).map_err(|e| e.to_string())?;
        let bench = observations(&meas, &m);
        let opts = DiagnoseOptions { exact_cv, tolerances, stated_noise, ..DiagnoseOptions::default() };
        let d =
            diagnose(&m, &bench.rows, &bench.groups, &opts).map_err(|e| format!("cannot diagnose '{source}': {e}"))?;
        let src = Provenance { motor_name: &m.name, motor_source: &motor_source, data: &source, lines: &bench.lines };
        Ok((to_json(&d, &src).to_string(), reader_warnings(&meas, &bench, &source)))
    })?;
    out.map_err(|e| input_err(py, e))
}

/// The reader's warnings, then the conversion's (rows dropped as repeats), each naming
/// `source`.
fn reader_warnings(meas: &Measurements, bench: &BenchData, source: &str) -> Vec<String> {
    meas.warnings.iter().cloned().chain(bench.warnings.iter().map(|w| format!("{source}: {w}"))).collect()
}

/// The plausible ranges in force: the defaults, then the `[plausible]` table of the TOML
/// text `toml` (text, source name) when given, then every `COLUMN=LOW:HIGH` spec. A bad
/// table or spec raises `trum.InputError` naming the file, line and key (or the spec).
fn plausible_ranges(py: Python<'_>, specs: &[String], toml: Option<&(String, String)>) -> PyResult<PlausibleRanges> {
    let mut ranges = match toml {
        Some((text, source)) => {
            trum_core::params::plausible_from_toml_str(text, source).map_err(|e| input_err(py, e.to_string()))?
        }
        None => PlausibleRanges::default(),
    };
    for spec in specs {
        ranges.parse_assignment(spec).map_err(|e| input_err(py, format!("plausible '{spec}': {e}")))?;
    }
    Ok(ranges)
}

/// The calibration's priors (docs/MOTOR_FILE.md, `[tolerances]`): the `[tolerances]` table
/// of the TOML text `toml` (text, source name) when given, then the `(key, value)` pairs,
/// which win for the keys they name. A bad table or pair raises `trum.InputError` naming the
/// file, line and key (or the key), with the valid keys for an unknown one.
fn tolerances_in_force(
    py: Python<'_>,
    pairs: &[(String, f64)],
    toml: Option<&(String, String)>,
) -> PyResult<std::collections::BTreeMap<String, f64>> {
    let mut out = match toml {
        Some((text, source)) => {
            trum_core::params::tolerances_from_toml_str(text, source).map_err(|e| input_err(py, e.to_string()))?
        }
        None => Default::default(),
    };
    out.extend(
        trum_core::params::tolerances_from_pairs(pairs, "tolerances").map_err(|e| input_err(py, e.to_string()))?,
    );
    Ok(out)
}

/// Calibrates the uncertain baseline parameters of `motor` to the measurement CSV `data`
/// (its bytes; `source` names it in messages), as `trum calibrate` does: a maximum a
/// posteriori fit with each parameter's tolerance as its prior, bounds refitted once, and
/// standard errors against relative parameter changes. Returns a dict: `motor` (the
/// calibrated motor), `params` (rows of name, nominal, value, std_error, at_bound,
/// identifiable), `chi2`, `chi2_per_reading`, `n_rows`, `n_readings`, `evaluations`,
/// `warnings` (the fit's) and `notes` (the reader's). `plausible` and `plausible_toml` set
/// the plausible ranges, `tolerances` and `tolerances_toml` the priors, as for
/// [`diagnose_csv`]. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (motor, data, source, plausible = Vec::new(), plausible_toml = None, tolerances = Vec::new(), tolerances_toml = None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_csv<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    data: Vec<u8>,
    source: String,
    plausible: Vec<String>,
    plausible_toml: Option<(String, String)>,
    tolerances: Vec<(String, f64)>,
    tolerances_toml: Option<(String, String)>,
) -> PyResult<Bound<'py, PyDict>> {
    let pm = motor.get().clone();
    let m = pm.inner.clone();
    let ranges = plausible_ranges(py, &plausible, plausible_toml.as_ref())?;
    let tolerances = tolerances_in_force(py, &tolerances, tolerances_toml.as_ref())?;
    let out = detached(py, move || -> Result<_, String> {
        let meas = parse_measurements_with(&data, &source, &ranges).map_err(|e| e.to_string())?;
        let bench = observations(&meas, &m);
        let mut cal = Calibration::builder(&m, &bench.rows)
            .options(&FitOptions::default())
            .tolerances(&tolerances)
            .refit_bounds(true)
            .search_starts(true)
            .run()
            .map_err(|e| format!("{source}: {e}"))?;
        rescale_uncertainties(&mut cal, &bench.rows);
        Ok((cal, bench.rows.len(), reader_warnings(&meas, &bench, &source)))
    })?;
    let (cal, n_rows, notes) = out.map_err(|e| input_err(py, e))?;
    let d = PyDict::new(py);
    let rows: Vec<(String, f64, f64, f64, bool, bool)> = cal
        .params
        .iter()
        .map(|p| {
            let nominal = pm.inner.param(&p.name).unwrap_or(f64::NAN);
            (p.name.clone(), nominal, p.value, p.std_error, p.at_bound, p.identifiable)
        })
        .collect();
    d.set_item("params", rows)?;
    d.set_item("chi2", cal.chi2)?;
    d.set_item("chi2_per_reading", cal.chi2 / cal.n_readings.max(1) as f64)?;
    d.set_item("n_rows", n_rows)?;
    d.set_item("n_readings", cal.n_readings)?;
    d.set_item("evaluations", cal.evaluations)?;
    d.set_item("warnings", cal.warnings.clone())?;
    d.set_item("notes", notes)?;
    d.set_item("motor", Bound::new(py, PyMotor { inner: cal.motor, drive: pm.drive })?)?;
    Ok(d)
}

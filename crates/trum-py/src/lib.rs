//! `trum._trum`: the native layer of the `trum` Python package. The public API (broadcasting
//! rules, the `Result` object, pandas helpers) lives in `python/trum/`; this module wraps
//! trum-core: motors, vectorised solves with the GIL released, maps and the criterion.
//! Errors are raised as `trum.ParameterError` / `trum.InputError` with the core's message.

pub mod diagnosis;
pub mod dynamics;
pub mod vector;

use numpy::ndarray::{Array, IxDyn};
use numpy::{PyArray, PyArrayDyn, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::panic::{catch_unwind, AssertUnwindSafe};
use trum_core::criterion::{self as core_criterion, CriterionConfig};
use trum_core::effects::EFFECTS;
use trum_core::layout::STATUS_NAMES;
use trum_core::params::Drive;
use trum_core::quantities::QUANTITIES;
use trum_core::sweep::{Axis, Grid, AXES};
use trum_core::{presets, Motor, ParamError, TrumError};
use vector::Column;

// ---------------------------------------------------------------------------- errors

/// Builds an exception of `trum._errors.<class>` with the message and keyword attributes.
fn raise(py: Python<'_>, class: &str, msg: String, kw: &[(&str, Py<PyAny>)]) -> PyErr {
    let make = || -> PyResult<PyErr> {
        let cls = py.import("trum._errors")?.getattr(class)?;
        let kwargs = PyDict::new(py);
        for (k, v) in kw {
            kwargs.set_item(k, v)?;
        }
        Ok(PyErr::from_value(cls.call((msg.clone(),), Some(&kwargs))?))
    };
    make().unwrap_or_else(|_| PyValueError::new_err(msg.clone()))
}

fn param_err(py: Python<'_>, e: &ParamError) -> PyErr {
    let kw = [
        ("source", e.source_name.clone().into_pyobject(py).map(|o| o.into_any().unbind())),
        ("line", e.line.into_pyobject(py).map(|o| o.into_any().unbind())),
        ("key", e.key.clone().into_pyobject(py).map(|o| o.into_any().unbind())),
        ("reason", e.reason.clone().into_pyobject(py).map(|o| o.into_any().unbind())),
    ];
    let kw: Vec<(&str, Py<PyAny>)> = kw.into_iter().filter_map(|(k, v)| v.ok().map(|v| (k, v))).collect();
    raise(py, "ParameterError", e.to_string(), &kw)
}

fn input_err(py: Python<'_>, msg: impl Into<String>) -> PyErr {
    raise(py, "InputError", msg.into(), &[])
}

fn no_memory(n: usize) -> PyErr {
    PyMemoryError::new_err(format!("not enough memory for the outputs of {n} operating points; solve in chunks"))
}

fn trum_err(py: Python<'_>, e: TrumError) -> PyErr {
    match e {
        TrumError::Param(p) => param_err(py, &p),
        TrumError::Input(m) => input_err(py, m),
    }
}

/// Runs `f` with the GIL released; a panic (a bug) becomes `trum.TrumError`, never a
/// `PanicException`.
fn detached<T: Send, F: FnOnce() -> T + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f))).map_err(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        raise(py, "TrumError", format!("internal error in trum-core (please report): {what}"), &[])
    })
}

// ---------------------------------------------------------------------------- motor

/// A motor definition (immutable; the `with_*` methods return new motors).
#[pyclass(frozen, eq, name = "Motor", module = "trum._trum")]
#[derive(Clone, PartialEq)]
pub struct PyMotor {
    pub(crate) inner: Motor,
    /// `(voltage_v, frequency_hz)` of the motor file's `[drive]` table, or of its preset's:
    /// what `solve` uses when the caller gives no drive, as the CLI's commands do.
    pub(crate) drive: Option<(f64, f64)>,
}

/// The `[drive]` of a preset, as `(voltage_v, frequency_hz)`.
fn preset_drive(name: &str) -> Option<(f64, f64)> {
    presets::find(name).ok().and_then(|p| p.drive()).map(|d| (d.voltage_v, d.frequency_hz))
}

fn dotted_keys() -> Vec<String> {
    Motor::all_keys().iter().map(|k| format!("{}.{}", k.section, k.key)).collect()
}

/// Unknown-key error exactly as the core words it.
fn unknown_key(motor: &Motor, key: &str, source: &str) -> ParamError {
    match motor.clone().set_param(key, f64::NAN, source) {
        Err(e) => e,
        Ok(()) => ParamError { source_name: source.into(), line: None, key: key.into(), reason: "unknown key".into() },
    }
}

fn apply_params(motor: &mut Motor, params: &[(String, f64)], source: &str) -> Result<(), ParamError> {
    for (k, v) in params {
        match motor.param_mut(k) {
            Some(slot) => *slot = *v,
            None => return Err(unknown_key(motor, k, source)),
        }
    }
    Ok(())
}

fn apply_effects(motor: &mut Motor, specs: &[String], source: &str) -> Result<(), ParamError> {
    for s in specs {
        motor.effects.parse_assignment(s).map_err(|reason| ParamError {
            source_name: source.into(),
            line: None,
            key: format!("effects.{}", s.split([':', '=']).next().unwrap_or("").trim()),
            reason,
        })?;
    }
    Ok(())
}

#[pymethods]
impl PyMotor {
    /// The motor of a preset (`trum60a`, `generic60`, ...).
    #[new]
    fn new(py: Python<'_>, preset: &str) -> PyResult<Self> {
        presets::preset(preset)
            .map(|inner| PyMotor { inner, drive: preset_drive(preset) })
            .map_err(|e| param_err(py, &e))
    }

    /// Reads a TOML motor file's text; `source` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, source = "<string>"))]
    fn from_toml_str(py: Python<'_>, text: &str, source: &str) -> PyResult<Self> {
        let inner = Motor::from_toml_str(text, source).map_err(|e| param_err(py, &e))?;
        let drive = Drive::from_toml_str(text, source).map_err(|e| param_err(py, &e))?;
        Ok(PyMotor { inner, drive: drive.map(|d| (d.voltage_v, d.frequency_hz)) })
    }

    /// Builds a motor from a preset (or, without one, from every key), numeric overrides
    /// `(dotted_key, value)` and effect assignments (`radial_friction=0.5`).
    #[staticmethod]
    #[pyo3(signature = (preset, name, params, effects, source = "dict"))]
    fn from_parts(
        py: Python<'_>,
        preset: Option<&str>,
        name: Option<String>,
        params: Vec<(String, f64)>,
        effects: Vec<String>,
        source: &str,
    ) -> PyResult<Self> {
        let build = || -> Result<Motor, ParamError> {
            let mut m = match preset {
                Some(p) => presets::preset(p).map_err(|mut e| {
                    e.source_name = source.into();
                    e
                })?,
                None => {
                    // Without a preset every key is required (as in a motor file).
                    let mut m = presets::PRESETS[0].motor();
                    for k in dotted_keys() {
                        if !params.iter().any(|(p, _)| *p == k) {
                            return Err(ParamError {
                                source_name: source.into(),
                                line: None,
                                key: k,
                                reason: "missing key (without a \"preset\" entry every key is required)".into(),
                            });
                        }
                    }
                    m.preset = None;
                    m.name = source.into();
                    m
                }
            };
            apply_params(&mut m, &params, source)?;
            apply_effects(&mut m, &effects, source)?;
            if let Some(n) = &name {
                m.name = n.clone();
            }
            m.validate(source, None)?;
            Ok(m)
        };
        build().map(|inner| PyMotor { inner, drive: preset.and_then(preset_drive) }).map_err(|e| param_err(py, &e))
    }

    /// A copy with numeric parameters replaced.
    #[pyo3(signature = (params, source = "with_params"))]
    fn with_params(&self, py: Python<'_>, params: Vec<(String, f64)>, source: &str) -> PyResult<Self> {
        let mut m = self.inner.clone();
        apply_params(&mut m, &params, source)
            .and_then(|_| m.validate(source, None))
            .map(|_| PyMotor { inner: m, drive: self.drive })
            .map_err(|e| param_err(py, &e))
    }

    /// A copy with effects switched on (`NAME=STRENGTH`, `NAME:param=v,...`, or `none`).
    #[pyo3(signature = (specs, source = "with_effects"))]
    fn with_effects(&self, py: Python<'_>, specs: Vec<String>, source: &str) -> PyResult<Self> {
        let mut m = self.inner.clone();
        apply_effects(&mut m, &specs, source)
            .and_then(|_| m.validate(source, None))
            .map(|_| PyMotor { inner: m, drive: self.drive })
            .map_err(|e| param_err(py, &e))
    }

    /// Value of a numeric parameter by dotted key.
    fn get(&self, py: Python<'_>, key: &str) -> PyResult<f64> {
        self.inner.param(key).ok_or_else(|| param_err(py, &unknown_key(&self.inner, key, "Motor")))
    }

    /// All numeric parameters, `{dotted_key: value}` in file order.
    fn params(&self) -> Vec<(String, f64)> {
        dotted_keys().into_iter().filter_map(|k| self.inner.param(&k).map(|v| (k, v))).collect()
    }

    /// Parameters that differ from the preset: `(key, value, preset_value)`.
    fn overrides(&self) -> Vec<(String, f64, f64)> {
        let Some(base) = self.inner.preset.as_deref().and_then(|p| presets::preset(p).ok()) else {
            return vec![];
        };
        dotted_keys()
            .into_iter()
            .filter_map(|k| {
                let (v, b) = (self.inner.param(&k)?, base.param(&k)?);
                (v.to_bits() != b.to_bits()).then_some((k, v, b))
            })
            .collect()
    }

    /// Display name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The preset this motor started from.
    #[getter]
    fn preset(&self) -> Option<String> {
        self.inner.preset.clone()
    }

    /// Active effects as `(name, [(param, value), ...])`.
    #[getter]
    fn active_effects(&self) -> Vec<(String, Vec<(String, f64)>)> {
        self.inner
            .effects
            .active()
            .into_iter()
            .map(|e| {
                let vals = self.inner.effects.get(e).unwrap_or(&[]);
                (
                    e.name().to_string(),
                    e.info().params.iter().zip(vals).map(|(p, v)| (p.name.to_string(), *v)).collect(),
                )
            })
            .collect()
    }

    /// Effects in the core's display form (`none`, `radial_friction(radial_velocity_ratio=0.5)`).
    #[getter]
    fn effects(&self) -> String {
        self.inner.effects.to_string()
    }

    /// The drive `(voltage_v, frequency_hz)` of the motor file's `[drive]` table or of its
    /// preset; `None` when neither gives one.
    #[getter]
    fn drive(&self) -> Option<(f64, f64)> {
        self.drive
    }

    /// A complete TOML motor file that reads back to an identical motor (its `[drive]`
    /// included).
    fn to_toml(&self) -> String {
        self.toml_text()
    }

    fn __repr__(&self) -> String {
        format!(
            "<trum._trum.Motor {:?} preset={:?} effects={}>",
            self.inner.name, self.inner.preset, self.inner.effects
        )
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((py.import("trum._trum")?.getattr("_motor_from_toml")?, (self.toml_text(),)))
    }
}

impl PyMotor {
    fn toml_text(&self) -> String {
        let mut s = self.inner.to_toml();
        if let Some((v, f)) = self.drive {
            // `{:?}` is the shortest text that reads back to the same f64
            s.push_str(&format!("\n[drive]\nvoltage_v = {v:?}\nfrequency_hz = {f:?}\n"));
        }
        s
    }
}

/// Unpickling helper.
#[pyfunction]
fn _motor_from_toml(py: Python<'_>, text: &str) -> PyResult<PyMotor> {
    PyMotor::from_toml_str(py, text, "pickle")
}

// ---------------------------------------------------------------------------- solve

/// Input column `a` broadcast to `shape`: zero-copy for C-contiguous input of that shape,
/// a scalar for stride-0 views, else gathered (`None` when memory runs out).
fn column<'a>(a: &'a PyReadonlyArrayDyn<'_, f64>, shape: &[usize]) -> Option<Column<'a>> {
    let v = a.as_array();
    let b = v.broadcast(IxDyn(shape))?; // the shape was checked, so this succeeds
    if b.is_empty() || b.strides().iter().all(|&s| s == 0) {
        return Some(Column::Scalar(b.iter().next().copied().unwrap_or(0.0)));
    }
    // Zero-copy only for C order (NumPy's `as_slice` also accepts Fortran order).
    if let (true, Some(s)) = (v.shape() == shape, v.to_slice()) {
        return Some(Column::Slice(s));
    }
    let mut g = Vec::new();
    g.try_reserve_exact(b.len()).ok()?;
    g.extend(b.iter().copied());
    Some(Column::Owned(g))
}

fn shaped<'py>(py: Python<'py>, shape: &[usize], v: Vec<f64>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    Array::from_shape_vec(IxDyn(shape), v)
        .map(|a| PyArray::from_owned_array(py, a))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Solves every point of the broadcast inputs. Returns a dict: `shape`, one float64 array
/// per quantity, `status_code` (uint8, see `STATUS_NAMES`) and `reasons` (flat index,
/// why) for the points that are not valid. `parallel=None`: parallel from 4096 points.
#[pyfunction]
#[pyo3(signature = (motor, preload_n, torque_nm, voltage_v, frequency_hz, elapsed_s, parallel = None))]
#[allow(clippy::too_many_arguments)]
fn solve_arrays<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    preload_n: PyReadonlyArrayDyn<'py, f64>,
    torque_nm: PyReadonlyArrayDyn<'py, f64>,
    voltage_v: PyReadonlyArrayDyn<'py, f64>,
    frequency_hz: PyReadonlyArrayDyn<'py, f64>,
    elapsed_s: PyReadonlyArrayDyn<'py, f64>,
    parallel: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let arrays = [&preload_n, &torque_nm, &voltage_v, &frequency_hz, &elapsed_s];
    let shapes: Vec<&[usize]> = arrays.iter().map(|a| a.shape()).collect();
    let shape = vector::broadcast_shape(&vector::INPUTS, &shapes).map_err(|m| input_err(py, m))?;
    let n =
        shape.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d)).ok_or_else(|| input_err(py, "too many points"))?;
    let cols: Vec<Column<'_>> =
        arrays.iter().map(|a| column(a, &shape)).collect::<Option<_>>().ok_or_else(|| no_memory(n))?;
    let cols: [Column<'_>; 5] = cols.try_into().map_err(|_| PyValueError::new_err("five inputs expected"))?;
    let par = parallel.unwrap_or(n >= vector::PARALLEL_MIN_POINTS);
    let m = &motor.get().inner;
    let (out, reasons) = detached(py, || {
        let out = vector::solve_points(m, &cols, n, par)?;
        let r = vector::reasons(&cols, &out);
        Some((out, r))
    })?
    .ok_or_else(|| no_memory(n))?;
    let d = PyDict::new(py);
    d.set_item("shape", PyTuple::new(py, &shape)?)?;
    for (q, v) in QUANTITIES.iter().zip(out.values) {
        d.set_item(q.name, shaped(py, &shape, v)?)?;
    }
    let codes = Array::from_shape_vec(IxDyn(&shape), out.status).map_err(|e| PyValueError::new_err(e.to_string()))?;
    d.set_item("status_code", PyArray::from_owned_array(py, codes))?;
    let warn = Array::from_shape_vec(IxDyn(&shape), out.warnings).map_err(|e| PyValueError::new_err(e.to_string()))?;
    d.set_item("warning_code", PyArray::from_owned_array(py, warn))?;
    d.set_item("reasons", reasons)?;
    Ok(d)
}

fn axis(py: Python<'_>, name: &str, spec: (f64, f64, i64)) -> PyResult<Axis> {
    let (a, b, n) = spec;
    if n < 1 {
        return Err(input_err(py, format!("{name}: an axis needs at least one point")));
    }
    Ok(Axis::linspace(a, b, n as usize))
}

/// Full-factorial map over the grid axes `AXES` (preload, torque, voltage, frequency;
/// points run torque fastest, then frequency, voltage, preload), solved as `trum map`
/// solves it. Each axis is `(start, stop, n)`; the grid is checked as the CLI checks it.
/// Returns a dict of flat columns: the four inputs, every quantity, `status_code`,
/// `warning_code` (bit i: `LIMIT_KEYS[i]` exceeded) and `reasons`.
#[pyfunction]
#[pyo3(signature = (motor, preload_n, torque_nm, voltage_v, frequency_hz, max_points = 20_000_000, parallel = None))]
#[allow(clippy::too_many_arguments)]
fn map_grid<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    preload_n: (f64, f64, i64),
    torque_nm: (f64, f64, i64),
    voltage_v: (f64, f64, i64),
    frequency_hz: (f64, f64, i64),
    max_points: u64,
    parallel: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let grid = Grid {
        preload_n: axis(py, "preload_n", preload_n)?,
        torque_nm: axis(py, "torque_nm", torque_nm)?,
        voltage_v: axis(py, "voltage_v", voltage_v)?,
        frequency_hz: axis(py, "frequency_hz", frequency_hz)?,
    };
    grid.validate().map_err(|e| trum_err(py, e))?;
    let len = grid.len();
    if len > max_points {
        return Err(input_err(
            py,
            format!("the map has {len} points, more than max_points = {max_points}; split it or raise max_points"),
        ));
    }
    let n = len as usize;
    let par = parallel.unwrap_or(n >= vector::PARALLEL_MIN_POINTS);
    let m = &motor.get().inner;
    let (inputs, out) = detached(py, || (vector::grid_inputs(&grid, n), vector::solve_grid(m, &grid, n, par)))?;
    let out = out.ok_or_else(|| no_memory(n))?;
    let reasons: Vec<(usize, String)> = out
        .status
        .iter()
        .enumerate()
        .filter(|(_, &s)| !vector::is_valid_code(s))
        .filter_map(|(i, &s)| vector::reason(s, &grid.point(i as u64), out.work_bound[i]).map(|r| (i, r)))
        .collect();
    let d = PyDict::new(py);
    for (name, col) in AXES.iter().zip(inputs) {
        d.set_item(*name, PyArray::from_vec(py, col))?;
    }
    for (q, v) in QUANTITIES.iter().zip(out.values) {
        d.set_item(q.name, PyArray::from_vec(py, v))?;
    }
    d.set_item("status_code", PyArray::from_vec(py, out.status))?;
    d.set_item("warning_code", PyArray::from_vec(py, out.warnings))?;
    d.set_item("reasons", reasons)?;
    Ok(d)
}

/// The load torque at which the loaded motor stops [N·m] on each torque line (preload,
/// voltage, frequency) given by three equal-length 1-D arrays
/// (`trum_core::criterion::loaded_stall_torque_nm`: a bisection of about 30 cold solves on
/// the status, to a relative 1e-9); NaN where the rotor does not run at no load.
/// `parallel=None`: parallel from 64 lines.
#[pyfunction]
#[pyo3(signature = (motor, preload_n, voltage_v, frequency_hz, parallel = None))]
fn loaded_stall_lines<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    preload_n: PyReadonlyArrayDyn<'py, f64>,
    voltage_v: PyReadonlyArrayDyn<'py, f64>,
    frequency_hz: PyReadonlyArrayDyn<'py, f64>,
    parallel: Option<bool>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let flat = |a: &PyReadonlyArrayDyn<'py, f64>| a.as_array().iter().copied().collect::<Vec<f64>>();
    let (p, v, f) = (flat(&preload_n), flat(&voltage_v), flat(&frequency_hz));
    if p.len() != v.len() || p.len() != f.len() {
        return Err(input_err(
            py,
            format!("preload_n, voltage_v and frequency_hz have {}, {} and {} values", p.len(), v.len(), f.len()),
        ));
    }
    let m = &motor.get().inner;
    let par = parallel.unwrap_or(p.len() >= 64);
    let out = detached(py, || {
        let prep = trum_core::solve::Prepared::new(m);
        let one = |i: usize| trum_core::criterion::loaded_stall_torque_nm(&prep, m, p[i], v[i], f[i]);
        if par {
            use rayon::prelude::*;
            (0..p.len()).into_par_iter().map(one).collect::<Vec<f64>>()
        } else {
            (0..p.len()).map(one).collect()
        }
    })?;
    let n = out.len();
    Array::from_shape_vec(IxDyn(&[n]), out)
        .map(|a| PyArray::from_owned_array(py, a))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The preload criterion (Chen et al. 2020, section 5). Unset settings take the core's defaults
/// (`CriterionConfig::seed000`). Returns a dict: `table` (columns), `optimum_preload_n`,
/// `region_n`.
#[pyfunction]
#[pyo3(signature = (motor, voltage_v = None, frequency_hz = None, preload_n = None, weights = None,
    run_time_s = None, run_torque_nm = None, runout_m = None, region_tolerance = None, torque_samples = None))]
#[allow(clippy::too_many_arguments)]
fn criterion<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    voltage_v: Option<f64>,
    frequency_hz: Option<f64>,
    preload_n: Option<(f64, f64, i64)>,
    weights: Option<[f64; 4]>,
    run_time_s: Option<f64>,
    run_torque_nm: Option<f64>,
    runout_m: Option<f64>,
    region_tolerance: Option<f64>,
    torque_samples: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut cfg = CriterionConfig::seed000();
    if let Some(p) = preload_n {
        cfg.preload_n = axis(py, "preload_n", p)?;
    }
    cfg.voltage_v = voltage_v.unwrap_or(cfg.voltage_v);
    cfg.frequency_hz = frequency_hz.unwrap_or(cfg.frequency_hz);
    cfg.weights = weights.unwrap_or(cfg.weights);
    cfg.run_time_s = run_time_s.unwrap_or(cfg.run_time_s);
    cfg.run_torque_nm = run_torque_nm.unwrap_or(cfg.run_torque_nm);
    cfg.runout_m = runout_m.unwrap_or(cfg.runout_m);
    cfg.region_tolerance = region_tolerance.unwrap_or(cfg.region_tolerance);
    if let Some(t) = torque_samples {
        cfg.torque_samples = usize::try_from(t).unwrap_or(0);
    }
    if cfg.preload_n.n > 100_000 || cfg.torque_samples > 100_000 {
        return Err(input_err(py, "preload_n and torque_samples are limited to 100000 points"));
    }
    let m = &motor.get().inner;
    let r = detached(py, || core_criterion::evaluate(m, &cfg, &mut |_, _| {}))?.map_err(|e| trum_err(py, e))?;
    let table = PyDict::new(py);
    let col = |f: fn(&core_criterion::CriterionRow) -> f64| r.rows.iter().map(f).collect::<Vec<f64>>();
    table.set_item("preload_n", PyArray::from_vec(py, col(|r| r.preload_n)))?;
    let status: Vec<&str> = r.rows.iter().map(|r| r.status.as_str()).collect();
    table.set_item("status", status)?;
    table.set_item("stall_torque_nm", PyArray::from_vec(py, col(|r| r.stall_torque_nm)))?;
    table.set_item("max_efficiency", PyArray::from_vec(py, col(|r| r.max_efficiency)))?;
    table.set_item("torque_at_max_efficiency_nm", PyArray::from_vec(py, col(|r| r.torque_at_max_efficiency_nm)))?;
    table.set_item("temperature_rise_after_run_k", PyArray::from_vec(py, col(|r| r.temperature_rise_after_run_k)))?;
    table.set_item("speed_std_rpm", PyArray::from_vec(py, col(|r| r.speed_std_rpm)))?;
    table.set_item("no_load_speed_rpm", PyArray::from_vec(py, col(|r| r.no_load_speed_rpm)))?;
    table.set_item("score", PyArray::from_vec(py, col(|r| r.score)))?;
    table.set_item("in_region", PyArray::from_vec(py, r.rows.iter().map(|r| r.in_region).collect::<Vec<bool>>()))?;
    table.set_item("warnings", r.rows.iter().map(|r| r.warnings.to_string()).collect::<Vec<String>>())?;
    let d = PyDict::new(py);
    d.set_item("table", table)?;
    d.set_item("within_limits", r.within_limits)?;
    d.set_item("optimum_preload_n", r.optimum_preload_n)?;
    d.set_item("region_n", r.region_n)?;
    let c = PyDict::new(py);
    c.set_item("voltage_v", cfg.voltage_v)?;
    c.set_item("frequency_hz", cfg.frequency_hz)?;
    c.set_item("preload_n", (cfg.preload_n.start, cfg.preload_n.stop, cfg.preload_n.n))?;
    c.set_item("weights", cfg.weights.to_vec())?;
    c.set_item("run_time_s", cfg.run_time_s)?;
    c.set_item("run_torque_nm", cfg.run_torque_nm)?;
    c.set_item("runout_m", cfg.runout_m)?;
    c.set_item("region_tolerance", cfg.region_tolerance)?;
    c.set_item("torque_samples", cfg.torque_samples)?;
    d.set_item("config", c)?;
    Ok(d)
}

/// The measured-input estimator (`trum_core::estimate`) over rows given as 1-D columns of
/// equal length: `feedback_v` NaN where not measured, `speed_rpm` NaN or `None`. Returns a
/// dict: every `ESTIMATE_COLUMNS` name, `status_code` (into `ESTIMATE_STATUS_NAMES`) and
/// `warning_code` (bits into `LIMIT_KEYS`).
#[pyfunction]
#[pyo3(signature = (motor, preload_n, voltage_v, frequency_hz, torque_nm, feedback_v, speed_rpm = None))]
#[allow(clippy::too_many_arguments)]
fn estimate_rows<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    preload_n: Vec<f64>,
    voltage_v: Vec<f64>,
    frequency_hz: Vec<f64>,
    torque_nm: Vec<f64>,
    feedback_v: Vec<f64>,
    speed_rpm: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    use trum_core::estimate::{Estimator, MeasuredPoint, ESTIMATE_COLUMNS};
    let n = preload_n.len();
    let lens = [voltage_v.len(), frequency_hz.len(), torque_nm.len(), feedback_v.len()];
    if lens.iter().any(|&l| l != n) || speed_rpm.as_ref().is_some_and(|s| s.len() != n) {
        return Err(input_err(py, "estimate: every column must have the same number of rows"));
    }
    let est = Estimator::new(&motor.get().inner).map_err(|e| trum_err(py, e))?;
    let out = detached(py, || {
        (0..n)
            .map(|i| {
                est.estimate(&MeasuredPoint {
                    preload_n: preload_n[i],
                    voltage_v: voltage_v[i],
                    frequency_hz: frequency_hz[i],
                    torque_nm: torque_nm[i],
                    feedback_v: Some(feedback_v[i]).filter(|v| !v.is_nan()),
                    speed_rpm: speed_rpm.as_ref().map(|s| s[i]).filter(|v| !v.is_nan()),
                })
            })
            .collect::<Vec<_>>()
    })?;
    let d = PyDict::new(py);
    for c in ESTIMATE_COLUMNS {
        d.set_item(c.name, PyArray::from_vec(py, out.iter().map(c.get).collect::<Vec<f64>>()))?;
    }
    d.set_item("status_code", PyArray::from_vec(py, out.iter().map(|e| e.status.code()).collect::<Vec<u8>>()))?;
    d.set_item("warning_code", PyArray::from_vec(py, out.iter().map(|e| e.warnings.bits()).collect::<Vec<u8>>()))?;
    d.set_item("full_contact", PyArray::from_vec(py, out.iter().map(|e| e.full_contact).collect::<Vec<bool>>()))?;
    Ok(d)
}

// ---------------------------------------------------------------------------- registries

/// `(name, summary, sources)` of every preset.
#[pyfunction]
fn presets_list() -> Vec<(&'static str, &'static str, &'static str)> {
    presets::PRESETS.iter().map(|p| (p.name, p.summary, p.sources)).collect()
}

/// The commented TOML of a preset (with each value's provenance).
#[pyfunction]
fn preset_toml(py: Python<'_>, name: &str) -> PyResult<String> {
    presets::find(name).map(|p| p.to_toml()).map_err(|e| param_err(py, &e))
}

type EffectRow =
    (&'static str, &'static str, &'static str, Vec<(&'static str, &'static str, f64, f64, f64, bool, bool)>);

/// `(name, summary, source, [(param, doc, typical, min, max, shape, held)])` of every effect.
#[pyfunction]
fn effects_list() -> Vec<EffectRow> {
    EFFECTS
        .iter()
        .map(|e| {
            (
                e.name,
                e.summary,
                e.source,
                e.params.iter().map(|p| (p.name, p.doc, p.typical, p.min, p.max, p.shape, p.held)).collect(),
            )
        })
        .collect()
}

/// `(name, unit, doc)` of every output quantity, in column order.
#[pyfunction]
fn quantities_list() -> Vec<(&'static str, &'static str, &'static str)> {
    QUANTITIES.iter().map(|q| (q.name, q.unit, q.doc)).collect()
}

/// `(dotted_key, doc)` of every motor parameter, in file order.
#[pyfunction]
fn parameter_keys() -> Vec<(String, &'static str)> {
    Motor::all_keys().iter().map(|k| (format!("{}.{}", k.section, k.key), k.doc)).collect()
}

#[pymodule]
fn _trum(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMotor>()?;
    m.add_function(wrap_pyfunction!(_motor_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(solve_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(map_grid, m)?)?;
    m.add_function(wrap_pyfunction!(loaded_stall_lines, m)?)?;
    m.add_function(wrap_pyfunction!(criterion, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_rows, m)?)?;
    m.add_function(wrap_pyfunction!(presets_list, m)?)?;
    m.add_function(wrap_pyfunction!(preset_toml, m)?)?;
    m.add_function(wrap_pyfunction!(effects_list, m)?)?;
    m.add_function(wrap_pyfunction!(quantities_list, m)?)?;
    m.add_function(wrap_pyfunction!(parameter_keys, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::hertz_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::hertz_motor_params, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::hertz_response, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::hertz_identify, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::step, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::bar_step, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::is_bar_motor, m)?)?;
    m.add_function(wrap_pyfunction!(dynamics::bar_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(diagnosis::diagnose_csv, m)?)?;
    m.add_function(wrap_pyfunction!(diagnosis::calibrate_csv, m)?)?;
    m.add("STATUS_NAMES", STATUS_NAMES.to_vec())?;
    m.add("LIMIT_KEYS", trum_core::limits::LIMIT_KEYS.to_vec())?;
    m.add("ESTIMATE_STATUS_NAMES", trum_core::estimate::EstimateStatus::NAMES.to_vec())?;
    m.add(
        "ESTIMATE_COLUMNS",
        trum_core::estimate::ESTIMATE_COLUMNS.iter().map(|c| (c.name, c.unit, c.doc)).collect::<Vec<_>>(),
    )?;
    m.add("INPUTS", vector::INPUTS.to_vec())?;
    m.add("AXES", AXES.to_vec())?;
    m.add("PARALLEL_MIN_POINTS", vector::PARALLEL_MIN_POINTS)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

//! Nonlinear and transient dynamics for Python: the Hertzian oscillator's response curves
//! and β identification ([Hertz2022]), and the stick-slip step response ([BarTransient];
//! keys of docs/REFERENCES.md). The
//! numbers are trum-core's; the work runs with the GIL released.

use crate::{detached, input_err, raise, PyMotor};
use numpy::{PyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use trum_core::dynamics::bar_type::{bar_step_response, BarMotor, BarStepConfig};
use trum_core::dynamics::hertz::{
    identify_beta, BetaIdentificationInput, HertzError, HertzOscillator, OperatingPoint, ResponseMethod,
};
use trum_core::dynamics::transient::{
    steady_comparison, step_response, SteadyComparison, SteadyGap, StepResponse, TransientConfig, TransientError,
};
use trum_core::layout::{
    response_rows, response_status, response_summary, ResponseCell, ResponseRow, RESPONSE_COLUMNS,
};

/// The oscillator: defaults with `params` (name, value) applied; a bad name or value is a
/// `ParameterError` naming the key.
fn oscillator(py: Python<'_>, params: &[(String, f64)]) -> PyResult<HertzOscillator> {
    let mut o = HertzOscillator::default();
    for (k, v) in params {
        let reason = match o.set_param(k, *v) {
            Ok(true) => continue,
            Ok(false) => format!("unknown key; valid keys are: {}", HertzOscillator::PARAM_KEYS.join(", ")),
            Err(HertzError::InvalidParameter { reason, .. }) => format!("{v} {reason}"),
            Err(e) => e.to_string(),
        };
        let kw = [
            ("source", "oscillator".into_pyobject(py)?.into_any().unbind()),
            ("key", k.clone().into_pyobject(py)?.into_any().unbind()),
            ("reason", reason.clone().into_pyobject(py)?.into_any().unbind()),
        ];
        return Err(raise(py, "ParameterError", format!("oscillator, key '{k}': {reason}"), &kw));
    }
    Ok(o)
}

fn method(py: Python<'_>, name: &str) -> PyResult<ResponseMethod> {
    match name {
        "multiple_scales" => Ok(ResponseMethod::MultipleScales),
        "harmonic_balance" => Ok(ResponseMethod::HarmonicBalance),
        _ => Err(input_err(py, format!("method '{name}': expected 'multiple_scales' or 'harmonic_balance'"))),
    }
}

/// The default oscillator's parameters `{name: value}`.
#[pyfunction]
pub fn hertz_defaults() -> Vec<(&'static str, f64)> {
    let mut o = HertzOscillator::default();
    HertzOscillator::PARAM_KEYS.iter().map(|k| (*k, o.param_mut(k).map_or(f64::NAN, |v| *v))).collect()
}

/// The oscillator parameters `{name: value}` of a motor (`HertzOscillator::from_motor`:
/// modal mass, damping, stiffness of the free resonance, force factor, hertz_softening).
#[pyfunction]
pub fn hertz_motor_params(motor: &Bound<'_, PyMotor>) -> Vec<(&'static str, f64)> {
    let mut o = HertzOscillator::from_motor(&motor.get().inner);
    HertzOscillator::PARAM_KEYS.iter().map(|k| (*k, o.param_mut(k).map_or(f64::NAN, |v| *v))).collect()
}

/// Response curves of every (voltage, preload) pair, voltage slowest. `frequency_hz`
/// `None`: 401 points over the core's default band. Returns `{frequency_hz, curves}`;
/// each curve is a dict with the operating point, `status`, `reason`, the branch points
/// (`frequency_hz`, `amplitude_m`, `phase_lag_rad`, `stable`, `branch`), the backbone,
/// the saddle nodes (`None` when single valued), `linear_resonance_hz` and the
/// equivalent β; and `table`, the response table of `trum resonance -o` as columns
/// (`trum_core::layout::response_rows`, column order in `columns`).
#[pyfunction]
#[pyo3(signature = (params, voltage_v, preload_n, frequency_hz = None, method_name = "multiple_scales"))]
pub fn hertz_response<'py>(
    py: Python<'py>,
    params: Vec<(String, f64)>,
    voltage_v: Vec<f64>,
    preload_n: Vec<f64>,
    frequency_hz: Option<PyReadonlyArray1<'py, f64>>,
    method_name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let o = oscillator(py, &params)?;
    let m = method(py, method_name)?;
    let ops: Vec<OperatingPoint> = voltage_v
        .iter()
        .flat_map(|&v| preload_n.iter().map(move |&n| OperatingPoint { voltage_v: v, preload_n: n }))
        .collect();
    if ops.is_empty() || ops.len() > 100_000 {
        return Err(input_err(py, format!("{} operating points: give between 1 and 100000", ops.len())));
    }
    let freqs: Vec<f64> = match &frequency_hz {
        Some(a) => a.as_slice().map(<[f64]>::to_vec).unwrap_or_else(|_| a.as_array().to_vec()),
        None => {
            let (lo, hi) = o
                .response_band_hz(&ops, m)
                .ok_or_else(|| input_err(py, "no operating point has a static equilibrium; give frequency_hz"))?;
            (0..401).map(|i| lo + (hi - lo) * i as f64 / 400.0).collect()
        }
    };
    if freqs.is_empty() || freqs.len() > 1_000_000 {
        return Err(input_err(py, format!("frequency_hz: {} points; give between 1 and 1000000", freqs.len())));
    }
    let family = detached(py, || o.response_family(&ops, &freqs, m))?
        .map_err(|e| input_err(py, format!("frequency_hz: {e}")))?;
    let mut curves = Vec::with_capacity(family.len());
    for c in &family {
        let d = PyDict::new(py);
        d.set_item("voltage_v", c.operating_point.voltage_v)?;
        d.set_item("preload_n", c.operating_point.preload_n)?;
        d.set_item("status", response_status(c))?;
        d.set_item("reason", c.response.as_ref().err().map(ToString::to_string).unwrap_or_default())?;
        let empty = Vec::new();
        let pts = c.response.as_ref().map_or(&empty, |r| &r.points);
        let col = |f: fn(&trum_core::dynamics::hertz::ResponsePoint) -> f64| pts.iter().map(f).collect::<Vec<f64>>();
        d.set_item("frequency_hz", PyArray::from_vec(py, col(|p| p.frequency_hz)))?;
        d.set_item("amplitude_m", PyArray::from_vec(py, col(|p| p.amplitude_m)))?;
        d.set_item("phase_lag_rad", PyArray::from_vec(py, col(|p| p.phase_lag_rad)))?;
        d.set_item("stable", PyArray::from_vec(py, pts.iter().map(|p| p.stable).collect::<Vec<bool>>()))?;
        d.set_item("branch", pts.iter().map(|p| p.branch.as_str()).collect::<Vec<&str>>())?;
        let bb =
            |f: fn(&trum_core::dynamics::hertz::BackbonePoint) -> f64| c.backbone.iter().map(f).collect::<Vec<f64>>();
        d.set_item("backbone_frequency_hz", PyArray::from_vec(py, bb(|b| b.frequency_hz)))?;
        d.set_item("backbone_amplitude_m", PyArray::from_vec(py, bb(|b| b.amplitude_m)))?;
        let r = c.response.as_ref().ok();
        let jumps = r.and_then(|r| r.jumps);
        d.set_item("jump_up_hz", jumps.map(|j| j.jump_up_hz))?;
        d.set_item("jump_up_amplitude_m", jumps.map(|j| j.jump_up_amplitude_m))?;
        d.set_item("jump_down_hz", jumps.map(|j| j.jump_down_hz))?;
        d.set_item("jump_down_amplitude_m", jumps.map(|j| j.jump_down_amplitude_m))?;
        d.set_item("equivalent_beta_n_per_m3", r.map(|r| r.equivalent_beta_n_per_m3))?;
        let lin = response_summary(c).linear_resonance_hz;
        d.set_item("linear_resonance_hz", lin.is_finite().then_some(lin))?;
        curves.push(d);
    }
    // the table `trum resonance -o` writes, as columns
    let rows = response_rows(&family);
    let table = PyDict::new(py);
    // every column of the core's layout: the numbers as arrays, then the words and the
    // flags as lists (the kind of a column is that of its cell in any row)
    let cells: Vec<[ResponseCell; 8]> = rows.iter().map(ResponseRow::cells).collect();
    let kind = |j: usize| ResponseRow::default().cells()[j];
    for (j, name) in RESPONSE_COLUMNS.iter().enumerate() {
        if let ResponseCell::Number(_) = kind(j) {
            let col: Vec<f64> =
                cells.iter().map(|c| if let ResponseCell::Number(x) = c[j] { x } else { f64::NAN }).collect();
            table.set_item(*name, PyArray::from_vec(py, col))?;
        }
    }
    for (j, name) in RESPONSE_COLUMNS.iter().enumerate() {
        if let ResponseCell::Word(_) = kind(j) {
            let col: Vec<&str> = cells.iter().map(|c| if let ResponseCell::Word(w) = c[j] { w } else { "" }).collect();
            table.set_item(*name, col)?;
        }
    }
    for (j, name) in RESPONSE_COLUMNS.iter().enumerate() {
        if let ResponseCell::Flag(_) = kind(j) {
            let col: Vec<Option<bool>> =
                cells.iter().map(|c| if let ResponseCell::Flag(f) = c[j] { f } else { None }).collect();
            table.set_item(*name, col)?;
        }
    }
    let out = PyDict::new(py);
    out.set_item("frequency_hz", PyArray::from_vec(py, freqs))?;
    out.set_item("curves", curves)?;
    out.set_item("columns", RESPONSE_COLUMNS.to_vec())?;
    out.set_item("table", table)?;
    Ok(out)
}

/// β by harmonic balance from a sampled waveform ([Hertz2022] eq. 5-9, docs/REFERENCES.md). `signal` is the
/// feedback voltage [V] with `feedback_gain_v_per_m`, else the displacement [m]. The drive
/// force is `drive_force_n`, or A·V + k_c·N from `voltage_v` and `preload_n`.
#[pyfunction]
#[pyo3(signature = (time_s, signal, frequency_hz, params, voltage_v = None, preload_n = None,
    drive_force_n = None, feedback_gain_v_per_m = None, harmonics = 3))]
#[allow(clippy::too_many_arguments)]
pub fn hertz_identify<'py>(
    py: Python<'py>,
    time_s: PyReadonlyArray1<'py, f64>,
    signal: PyReadonlyArray1<'py, f64>,
    frequency_hz: f64,
    params: Vec<(String, f64)>,
    voltage_v: Option<f64>,
    preload_n: Option<f64>,
    drive_force_n: Option<f64>,
    feedback_gain_v_per_m: Option<f64>,
    harmonics: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let o = oscillator(py, &params)?;
    let force = match (drive_force_n, voltage_v) {
        (Some(_), Some(_)) => return Err(input_err(py, "give voltage_v or drive_force_n, not both")),
        (Some(f), None) => f,
        (None, Some(v)) => o
            .forcing_amplitude_n(&OperatingPoint { voltage_v: v, preload_n: preload_n.unwrap_or(0.0) })
            .map_err(|e| input_err(py, format!("voltage_v/preload_n: {e}")))?,
        (None, None) => return Err(input_err(py, "give voltage_v or drive_force_n")),
    };
    let t = time_s.as_array().to_vec();
    let s = signal.as_array().to_vec();
    let input = BetaIdentificationInput {
        sample_times_s: &t,
        samples_v: &s,
        drive_frequency_hz: frequency_hz,
        feedback_gain_v_per_m: feedback_gain_v_per_m.unwrap_or(1.0),
        drive_force_amplitude_n: force,
        static_force_n: preload_n,
        modal_mass_kg: o.modal_mass_kg,
        damping_ns_per_m: o.damping_ns_per_m,
        linear_stiffness_n_per_m: o.linear_stiffness_n_per_m,
        harmonics,
    };
    let id = detached(py, || identify_beta(&input))?.map_err(|e| input_err(py, e.to_string()))?;
    float_dict(
        py,
        &[
            ("beta_n_per_m3", id.beta_n_per_m3),
            ("one_term_beta_n_per_m3", id.one_term_beta_n_per_m3),
            ("harmonic_fit_r_squared", id.harmonic_fit_r_squared),
            ("waveform_residual_rms", id.waveform_residual_rms_v),
            ("balance_residual_rms_m", id.balance_residual_rms_m),
            ("balance_relative_residual", id.balance_relative_residual),
            ("displacement_amplitude_m", id.displacement_amplitude_m),
            ("periods_spanned", id.periods_spanned),
            ("drive_force_n", force),
        ],
    )
}

/// `{name: value}` of named numbers (`None` becomes Python's `None`).
fn float_dict<'py, T: IntoPyObject<'py> + Copy>(py: Python<'py>, items: &[(&str, T)]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in items {
        d.set_item(*k, *v)?;
    }
    Ok(d)
}

/// The Python argument a core config field comes from.
fn argument(name: &str) -> &str {
    match name {
        "phase_difference_rad" => "phase_difference_deg",
        "snapshot_times_s" => "snapshot_at_s",
        "load_torque_nm" => "torque_nm",
        "moment_amplitude_nm" => "moment_nm",
        "nodes" => "nodes_per_wavelength",
        n => n,
    }
}

/// Step response of the rotor speed ([BarTransient], docs/REFERENCES.md). Returns a dict: `series` (arrays),
/// `metrics` (`None` where undefined), `status`, `averages`, `steady` (the steady solver
/// at the same point), `snapshots` (per-node arrays and states), `time_step_s`, `steps`.
#[pyfunction]
#[pyo3(signature = (motor, voltage_v, frequency_hz, phase_difference_deg, preload_n, torque_nm, duration_s,
    steps_per_period, nodes_per_wavelength, tangential_stiffness_ratio, record_every, snapshot_at_s, auto_steps = false))]
#[allow(clippy::too_many_arguments)]
pub fn step<'py>(
    py: Python<'py>,
    motor: &Bound<'py, PyMotor>,
    voltage_v: f64,
    frequency_hz: f64,
    phase_difference_deg: f64,
    preload_n: f64,
    torque_nm: f64,
    duration_s: f64,
    steps_per_period: usize,
    nodes_per_wavelength: usize,
    tangential_stiffness_ratio: f64,
    record_every: usize,
    snapshot_at_s: Vec<f64>,
    auto_steps: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &motor.get().inner;
    if !m.effects.is_none() {
        return Err(input_err(
            py,
            "the transient model does not include unmodelled effects; use a motor without effects",
        ));
    }
    let cfg = TransientConfig {
        duration_s,
        steps_per_period,
        nodes_per_wavelength,
        phase_difference_rad: phase_difference_deg.to_radians(),
        load_torque_nm: torque_nm,
        voltage_v,
        frequency_hz,
        preload_n,
        record_every,
        snapshot_times_s: snapshot_at_s,
        tangential_stiffness_ratio,
        ..TransientConfig::default()
    };
    // (`auto_steps`: the caller left the step to the tool, which refines an unstable one)
    let run = || {
        if auto_steps {
            trum_core::dynamics::transient::step_response_stable(m, &cfg).map(|(r, _)| r)
        } else {
            step_response(m, &cfg)
        }
    };
    let (r, steady) = detached(py, || (run(), steady_comparison(m, &cfg)))?;
    let r = r.map_err(|e| transient_err(py, e, phase_difference_deg))?;
    response_dict(py, r, Some(steady), m.friction_layer.friction_coefficient)
}

/// A core error of a step run as the Python exception, naming the argument.
fn transient_err(py: Python<'_>, e: TransientError, phase_difference_deg: f64) -> PyErr {
    match e {
        TransientError::InvalidConfig { name, value, reason } => {
            let shown = if name == "phase_difference_rad" { phase_difference_deg } else { value };
            input_err(py, format!("{} = {shown}: {reason}", argument(name)))
        }
        TransientError::Diverged { .. } => raise(py, "TrumError", e.to_string(), &[]),
        e => input_err(py, e.to_string()),
    }
}

/// `spec` as a bar-type motor: a bar-type preset name, or a motor file with `kind = "bar"`
/// or a bar-type `preset`; `None` otherwise.
fn bar_motor(py: Python<'_>, spec: &str) -> PyResult<Option<BarMotor>> {
    if let Some(p) = trum_core::presets::find_bar(spec) {
        return Ok(Some(p.motor()));
    }
    let path = std::path::Path::new(spec);
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(path).map_err(|e| input_err(py, format!("cannot read '{spec}': {e}")))?;
    if !BarMotor::is_bar_file(&text) {
        return Ok(None);
    }
    BarMotor::from_toml_str(&text, spec).map(Some).map_err(|e| crate::param_err(py, &e))
}

/// True when `spec` names a bar-type motor (preset or file).
#[pyfunction]
pub fn is_bar_motor(py: Python<'_>, spec: &str) -> PyResult<bool> {
    Ok(bar_motor(py, spec)?.is_some())
}

/// The `[drive]` defaults of a bar-type motor: moment, frequency, phase, preload, duration.
#[pyfunction]
pub fn bar_defaults(py: Python<'_>, spec: &str) -> PyResult<Vec<(&'static str, f64)>> {
    let m = bar_motor(py, spec)?.ok_or_else(|| input_err(py, format!("'{spec}' is not a bar-type motor")))?;
    let c = m.step_config();
    Ok(vec![
        ("moment_nm", m.moment_amplitude_nm),
        ("frequency_hz", m.frequency_hz),
        ("phase_difference_deg", m.phase_difference_deg),
        ("preload_n", m.preload_n),
        ("duration_s", c.duration_s),
    ])
}

/// Step response of a bar-type motor ([BarTransient] eq. 1-5, docs/DYNAMICS.md), `spec` a
/// bar-type preset name or motor file. The same dict as [`step`], with `steady` `None`.
#[pyfunction]
#[pyo3(signature = (spec, moment_nm, frequency_hz, phase_difference_deg, preload_n, torque_nm, duration_s,
    steps_per_period, nodes_per_wavelength, record_every, snapshot_at_s))]
#[allow(clippy::too_many_arguments)]
pub fn bar_step<'py>(
    py: Python<'py>,
    spec: &str,
    moment_nm: f64,
    frequency_hz: f64,
    phase_difference_deg: f64,
    preload_n: f64,
    torque_nm: f64,
    duration_s: f64,
    steps_per_period: usize,
    nodes_per_wavelength: usize,
    record_every: usize,
    snapshot_at_s: Vec<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = bar_motor(py, spec)?.ok_or_else(|| input_err(py, format!("'{spec}' is not a bar-type motor")))?;
    let cfg = BarStepConfig {
        duration_s,
        steps_per_period,
        nodes: nodes_per_wavelength,
        phase_difference_rad: phase_difference_deg.to_radians(),
        load_torque_nm: torque_nm,
        moment_amplitude_nm: moment_nm,
        frequency_hz,
        preload_n,
        record_every,
        snapshot_times_s: snapshot_at_s,
    };
    let r = detached(py, || bar_step_response(&m, &cfg))?.map_err(|e| transient_err(py, e, phase_difference_deg))?;
    response_dict(py, r, None, m.static_friction_coefficient)
}

/// The dict of a step run; `mu` is the Coulomb limit written beside the friction force.
fn response_dict<'py>(
    py: Python<'py>,
    r: StepResponse,
    steady: Option<Result<SteadyComparison, SteadyGap>>,
    mu: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let series = PyDict::new(py);
    let t = r.series;
    for (k, v) in [
        ("time_s", t.time_s),
        ("speed_rpm", t.speed_rpm),
        ("speed_period_mean_rpm", t.speed_period_mean_rpm),
        ("amplitude_m", t.amplitude_m),
        ("axial_position_m", t.axial_position_m),
        ("contact_torque_nm", t.torque_nm),
        ("axial_force_n", t.axial_force_n),
    ] {
        series.set_item(k, PyArray::from_vec(py, v))?;
    }
    let mt = r.metrics;
    let metrics = float_dict(
        py,
        &[
            ("final_speed_rpm", Some(mt.final_speed_rpm)),
            ("peak_speed_rpm", Some(mt.peak_speed_rpm)),
            ("delay_s", mt.delay_s),
            ("rise_time_s", mt.rise_time_s),
            ("rise_to_final_s", mt.rise_to_final_s),
            ("peak_time_s", mt.peak_time_s),
            ("overshoot", mt.overshoot),
            ("settling_time_s", mt.settling_time_s),
        ],
    )?;
    let a = r.averages;
    let averages = float_dict(
        py,
        &[
            ("window_s", a.window_s),
            ("speed_rpm", a.speed_rpm),
            ("contact_torque_nm", a.contact_torque_nm),
            ("amplitude_m", a.amplitude_m),
            ("axial_force_n", a.axial_force_n),
            ("contact_fraction", a.contact_fraction),
            ("stick_fraction", a.stick_fraction),
        ],
    )?;
    // A point the steady model does not describe (a SteadyGap) keeps the dict's keys, with
    // NaN numbers, the status `not_comparable` and the reason in `note`.
    let st = match steady {
        Some(steady) => {
            let (nums, status, note) = match steady {
                Ok(s) => ([s.speed_rpm, s.contact_torque_nm, s.amplitude_m], s.status.as_str(), None),
                Err(g) => ([f64::NAN; 3], "not_comparable", Some(g.to_string())),
            };
            let st =
                float_dict(py, &[("speed_rpm", nums[0]), ("contact_torque_nm", nums[1]), ("amplitude_m", nums[2])])?;
            st.set_item("status", status)?;
            st.set_item("note", note)?;
            Some(st)
        }
        None => None,
    };
    let mut snaps = Vec::with_capacity(r.snapshots.len());
    for s in &r.snapshots {
        let d = PyDict::new(py);
        d.set_item("requested_time_s", s.requested_time_s)?;
        d.set_item("time_s", s.time_s)?;
        d.set_item("speed_rpm", s.speed_rpm)?;
        let col = |f: &dyn Fn(&trum_core::dynamics::transient::NodeSample) -> f64| {
            s.nodes.iter().map(f).collect::<Vec<f64>>()
        };
        d.set_item("position_m", PyArray::from_vec(py, col(&|n| n.position_m)))?;
        d.set_item("pressure_n_per_m", PyArray::from_vec(py, col(&|n| n.pressure_n_per_m)))?;
        d.set_item("tangential_force_n_per_m", PyArray::from_vec(py, col(&|n| n.tangential_force_n_per_m)))?;
        d.set_item("friction_limit_n_per_m", PyArray::from_vec(py, col(&|n| mu * n.pressure_n_per_m)))?;
        d.set_item("slip_speed_m_s", PyArray::from_vec(py, col(&|n| n.slip_speed_m_s)))?;
        d.set_item("state", s.nodes.iter().map(|n| n.state.as_str()).collect::<Vec<&str>>())?;
        snaps.push(d);
    }
    let d = PyDict::new(py);
    d.set_item("series", series)?;
    d.set_item("metrics", metrics)?;
    d.set_item("status", mt.status())?;
    d.set_item("averages", averages)?;
    d.set_item("steady", st)?;
    d.set_item("snapshots", snaps)?;
    d.set_item("time_step_s", r.time_step_s)?;
    d.set_item("steps", r.steps)?;
    Ok(d)
}

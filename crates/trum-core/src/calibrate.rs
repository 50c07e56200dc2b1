//! Calibration of the uncertain model parameters to measured data: bounded nonlinear
//! least squares (Levenberg–Marquardt from the `levenberg-marquardt` crate, with a
//! logistic bound transform), residuals scaled per observation by its noise level, a
//! Huber loss applied by iteratively reweighted least squares so single outliers do not
//! decide, central finite-difference Jacobians in the transformed coordinates, and
//! parameter uncertainties from the Jacobian at the optimum.

use crate::effects::Effect;
use crate::error::TrumError;
use crate::params::Motor;
use crate::solve::{solve_prepared, OperatingPoint, Prepared, Solution};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

/// A measured quantity the model predicts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Observable {
    /// Mean rotor speed [rev/min].
    SpeedRpm,
    /// Electrical input power, both phases [W].
    InputPowerW,
    /// Drive current amplitude per phase [A].
    CurrentA,
    /// Efficiency [-].
    Efficiency,
    /// Feedback electrode voltage amplitude [V].
    FeedbackV,
    /// Stator temperature [°C].
    TemperatureC,
    /// Speed standard deviation over a revolution [rev/min].
    SpeedStdRpm,
}

impl Observable {
    /// All observables, in column order.
    pub const ALL: [Observable; 7] = [
        Observable::SpeedRpm,
        Observable::InputPowerW,
        Observable::CurrentA,
        Observable::Efficiency,
        Observable::FeedbackV,
        Observable::TemperatureC,
        Observable::SpeedStdRpm,
    ];

    /// The measurement-file column name.
    pub fn column(self) -> &'static str {
        match self {
            Observable::SpeedRpm => "speed_rpm",
            Observable::InputPowerW => "input_power_w",
            Observable::CurrentA => "current_a",
            Observable::Efficiency => "efficiency",
            Observable::FeedbackV => "feedback_v",
            Observable::TemperatureC => "temperature_c",
            Observable::SpeedStdRpm => "speed_std_rpm",
        }
    }

    /// The model's prediction from a solution (`ambient_c` for temperatures).
    pub fn predict(self, s: &Solution, ambient_c: f64) -> f64 {
        match self {
            Observable::SpeedRpm => s.speed_rpm,
            Observable::InputPowerW => s.input_power_w,
            Observable::CurrentA => s.current_a,
            Observable::Efficiency => s.efficiency,
            Observable::FeedbackV => s.feedback_v,
            Observable::TemperatureC => ambient_c + s.temperature_rise_at_elapsed_k,
            Observable::SpeedStdRpm => s.speed_std_rpm,
        }
    }

    /// Default noise level of one reading when the data do not say (documented in
    /// docs/DIAGNOSIS.md): an absolute floor plus a relative part.
    pub fn default_sigma(self, value: f64) -> f64 {
        let v = value.abs();
        match self {
            Observable::SpeedRpm => 0.5 + 0.01 * v,
            Observable::InputPowerW => 0.05 + 0.02 * v,
            Observable::CurrentA => 0.002 + 0.015 * v,
            Observable::Efficiency => 0.005 + 0.03 * v,
            Observable::FeedbackV => 0.2 + 0.01 * v,
            Observable::TemperatureC => 0.2,
            Observable::SpeedStdRpm => 0.05 + 0.1 * v,
        }
    }
}

/// One measured row: the operating point and the readings taken there.
#[derive(Clone, Debug, PartialEq)]
pub struct ObservedRow {
    /// Operating point (elapsed time included for time series).
    pub op: OperatingPoint,
    /// Readings: (what, value, noise level σ).
    pub readings: Vec<(Observable, f64, f64)>,
    /// Ambient temperature for temperature readings [°C].
    pub ambient_c: f64,
}

/// Which parameter a fit moves.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamRef {
    /// A motor parameter by dotted key.
    Motor(String),
    /// Parameter `i` of an effect.
    Effect(Effect, usize),
}

impl ParamRef {
    /// Display name.
    pub fn name(&self) -> String {
        match self {
            ParamRef::Motor(k) => k.clone(),
            ParamRef::Effect(e, i) => format!("effects.{}.{}", e.name(), e.info().params[*i].name),
        }
    }

    fn get(&self, m: &Motor) -> f64 {
        match self {
            ParamRef::Motor(k) => m.param(k).unwrap_or(f64::NAN),
            ParamRef::Effect(e, i) => m.effects.value(*e, *i),
        }
    }

    fn set(&self, m: &mut Motor, v: f64) {
        match self {
            ParamRef::Motor(k) => {
                if let Some(slot) = m.param_mut(k) {
                    *slot = v;
                }
            }
            ParamRef::Effect(e, i) => *m.effects.value_mut(*e, *i) = v,
        }
    }
}

/// A fitted parameter with its bounds; `log` fits it on a logarithmic scale.
#[derive(Clone, Debug, PartialEq)]
pub struct FitParam {
    /// The parameter.
    pub param: ParamRef,
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
    /// Transform through the logarithm (positive parameters spanning decades).
    pub log: bool,
}

impl FitParam {
    fn to_u(&self, p: f64) -> f64 {
        let (lo, hi, x) =
            if self.log { (self.lo.ln(), self.hi.ln(), p.max(1e-300).ln()) } else { (self.lo, self.hi, p) };
        let t = ((x - lo) / (hi - lo)).clamp(1e-9, 1.0 - 1e-9);
        (t / (1.0 - t)).ln()
    }
    fn from_u(&self, u: f64) -> f64 {
        let t = 1.0 / (1.0 + (-u).exp());
        if self.log {
            (self.lo.ln() + t * (self.hi.ln() - self.lo.ln())).exp()
        } else {
            self.lo + t * (self.hi - self.lo)
        }
    }
    /// dp/du at u.
    fn dp_du(&self, u: f64) -> f64 {
        let t = 1.0 / (1.0 + (-u).exp());
        let dt = t * (1.0 - t);
        if self.log {
            self.from_u(u) * (self.hi.ln() - self.lo.ln()) * dt
        } else {
            (self.hi - self.lo) * dt
        }
    }
}

/// The uncertain baseline parameters of a motor and their bounds (docs/DIAGNOSIS.md):
/// friction coefficient, friction-layer modulus, modal damping, force factor, free
/// resonance; the feedback gain, the clamped capacitance and the thermal network's heat
/// capacity and heat-transfer coefficient when the data can see them.
pub fn baseline_params(motor: &Motor, rows: &[ObservedRow]) -> Vec<FitParam> {
    let has = |o: Observable| rows.iter().any(|r| r.readings.iter().any(|x| x.0 == o));
    let mut v = vec![
        fit_rel(motor, "friction_layer.friction_coefficient", 0.3, 3.0),
        fit_rel(motor, "friction_layer.youngs_modulus_pa", 0.1, 10.0),
        fit_rel(motor, "stator.modal_damping_ns_per_m", 0.2, 5.0),
        fit_rel(motor, "stator.force_factor_n_per_v", 0.3, 3.0),
        fit_rel(motor, "stator.resonance_frequency_hz", 0.97, 1.03),
    ];
    if has(Observable::FeedbackV) {
        v.push(fit_rel(motor, "electrical.feedback_gain_v_per_m", 0.3, 3.0));
    }
    if has(Observable::InputPowerW) || has(Observable::CurrentA) {
        v.push(fit_rel(motor, "electrical.clamped_capacitance_f", 0.5, 2.0));
    }
    // A temperature time series sees the thermal network itself (seed 000 eq. 11: time
    // constant C/(αS), final rise P/(αS)), which the papers give only roughly.
    if has(Observable::TemperatureC) && rows.iter().any(|r| r.op.elapsed_s > 0.0) {
        v.push(fit_rel(motor, "thermal.heat_capacity_j_per_k", 0.3, 3.0));
        v.push(fit_rel(motor, "thermal.heat_transfer_coefficient_w_per_m2k", 0.3, 3.0));
    }
    v
}

fn fit_rel(motor: &Motor, key: &str, lo: f64, hi: f64) -> FitParam {
    let nominal = motor.param(key).unwrap_or(1.0);
    FitParam { param: ParamRef::Motor(key.into()), lo: nominal * lo, hi: nominal * hi, log: true }
}

/// The fit parameters of an effect: all its strength parameters, bounded to eight times
/// their typical magnitude inside the valid range (beyond that an effect would dominate
/// the motor's behaviour rather than perturb it, and the solves get needlessly hard).
pub fn effect_params(effect: Effect) -> Vec<FitParam> {
    effect
        .info()
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let span = 8.0 * p.typical.abs();
            FitParam { param: ParamRef::Effect(effect, i), lo: p.min.max(-span), hi: p.max.min(span), log: false }
        })
        .collect()
}

/// Options of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Huber threshold in units of σ.
    pub huber_k: f64,
    /// Reweighting passes.
    pub irls_passes: usize,
    /// Budget of model evaluations per LM run, Jacobian columns included (a forward-
    /// difference Jacobian costs n + 1 evaluations for n parameters).
    pub max_evaluations: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions { huber_k: 3.0, irls_passes: 2, max_evaluations: 400 }
    }
}

/// One fitted parameter in the result.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedParam {
    /// Parameter name.
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// Standard error from the Jacobian (NaN when not identifiable).
    pub std_error: f64,
    /// True when the value sits on (within 0.5 % of) a bound.
    pub at_bound: bool,
    /// False when the data cannot determine it (near-singular Jacobian column).
    pub identifiable: bool,
}

/// Result of a calibration.
#[derive(Clone, Debug)]
pub struct Calibration {
    /// The calibrated motor.
    pub motor: Motor,
    /// Fitted parameters.
    pub params: Vec<FittedParam>,
    /// Σ of squared normalised residuals (unweighted) at the optimum.
    pub chi2: f64,
    /// Number of readings used.
    pub n_readings: usize,
    /// Residual evaluations used.
    pub evaluations: usize,
    /// Warnings (bounds, identifiability, failed solves).
    pub warnings: Vec<String>,
    /// The fit linearised at its optimum (for approximate leave-block-out refits).
    pub(crate) lin: Linearisation,
}

/// A fit linearised at its optimum: the start motor the parameters are applied to, the
/// transformed parameters u, the final Huber weights, the weighted residuals and their
/// Jacobian with respect to u (one row per reading, rows in reading order).
#[derive(Clone, Debug)]
pub(crate) struct Linearisation {
    pub(crate) base: Motor,
    pub(crate) params: Vec<FitParam>,
    pub(crate) u: DVector<f64>,
    pub(crate) weights: Vec<f64>,
    pub(crate) residuals: DVector<f64>,
    pub(crate) jacobian: DMatrix<f64>,
}

impl Linearisation {
    /// The motor at transformed parameters `u`.
    pub(crate) fn motor_at(&self, u: &DVector<f64>) -> Motor {
        motor_at(&self.base, &self.params, u)
    }
}

fn motor_at(base: &Motor, params: &[FitParam], u: &DVector<f64>) -> Motor {
    let mut m = base.clone();
    for (fp, &ui) in params.iter().zip(u.iter()) {
        fp.param.set(&mut m, fp.from_u(ui));
    }
    m
}

/// Normalised residuals (prediction − measurement)/σ of every reading of `rows`, in
/// order; a point the model cannot solve contributes a large residual (50 σ).
pub fn residuals(motor: &Motor, rows: &[ObservedRow]) -> Vec<f64> {
    use rayon::prelude::*;
    let p = Prepared::new(motor);
    let one = |r: &ObservedRow| -> Vec<f64> {
        // Cold starts: a warm start from a neighbouring row could settle on another
        // fixed point where the amplitude map has several, and the fit must see one model.
        let s = solve_prepared(&p, motor, &r.op, None);
        r.readings
            .iter()
            .map(|&(o, v, sigma)| if s.status.is_valid() { (o.predict(&s, r.ambient_c) - v) / sigma } else { 50.0 })
            .collect()
    };
    // Large data sets in parallel chunks (the order of the result is kept): a diagnosis
    // fits its candidates in parallel too, and nested chunks let the idle core help the
    // slowest candidate.
    if rows.len() >= 128 {
        rows.par_chunks(32).flat_map_iter(|c| c.iter().flat_map(one).collect::<Vec<f64>>()).collect()
    } else {
        rows.iter().flat_map(one).collect()
    }
}

struct Problem<'a> {
    base: Motor,
    rows: &'a [ObservedRow],
    params: &'a [FitParam],
    u: DVector<f64>,
    weights: Vec<f64>,
    evals: std::cell::Cell<usize>,
    /// The last weighted residuals and where they were taken: the LM crate asks for the
    /// residuals at a point and then for the Jacobian there, whose forward differences
    /// start from the same residuals (one model pass saved per iteration). Cleared when
    /// the weights change.
    last: std::cell::RefCell<Option<(DVector<f64>, DVector<f64>)>>,
}

impl Problem<'_> {
    fn motor_at(&self, u: &DVector<f64>) -> Motor {
        motor_at(&self.base, self.params, u)
    }
    fn weighted(&self, u: &DVector<f64>) -> DVector<f64> {
        self.evals.set(self.evals.get() + 1);
        let r = residuals(&self.motor_at(u), self.rows);
        DVector::from_iterator(r.len(), r.iter().zip(&self.weights).map(|(x, w)| x * w))
    }
    /// `weighted(u)`, remembered as the latest point.
    fn weighted_at(&self, u: &DVector<f64>) -> DVector<f64> {
        if let Some((lu, lr)) = self.last.borrow().as_ref() {
            if lu == u {
                return lr.clone();
            }
        }
        let r = self.weighted(u);
        *self.last.borrow_mut() = Some((u.clone(), r.clone()));
        r
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.u.copy_from(x);
    }
    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.weighted_at(&self.u))
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        // Forward differences in the transformed coordinates (step 1e-6 in u, about 2.5e-7 of
        // the range; the solver's 1e-12 tolerance keeps the truncation and noise errors near
        // 1e-6 relative — checked against central differences in the tests).
        let n = self.u.len();
        let m = self.rows.iter().map(|r| r.readings.len()).sum();
        let mut j = DMatrix::zeros(m, n);
        let r0 = self.weighted_at(&self.u);
        for k in 0..n {
            let h = 1e-6 * (1.0 + self.u[k].abs());
            let mut up = self.u.clone();
            up[k] += h;
            let d = (self.weighted(&up) - &r0) / h;
            j.set_column(k, &d);
        }
        Some(j)
    }
}

/// Calibrates `params` of `motor` to `rows`. Errors when there are fewer readings than
/// parameters or a bound is invalid; a fit that does not converge still returns its best
/// point with a warning.
pub fn calibrate(
    motor: &Motor,
    rows: &[ObservedRow],
    params: &[FitParam],
    opts: &FitOptions,
) -> Result<Calibration, TrumError> {
    let n_read: usize = rows.iter().map(|r| r.readings.len()).sum();
    if n_read <= params.len() {
        return Err(TrumError::input(format!(
            "{n_read} readings cannot determine {} parameters; need more measured points",
            params.len()
        )));
    }
    for fp in params {
        if !(fp.lo < fp.hi) || (fp.log && fp.lo <= 0.0) || !fp.lo.is_finite() || !fp.hi.is_finite() {
            return Err(TrumError::input(format!("invalid bounds [{}, {}] for {}", fp.lo, fp.hi, fp.param.name())));
        }
    }
    let u0 =
        DVector::from_iterator(params.len(), params.iter().map(|fp| fp.to_u(fp.param.get(motor).clamp(fp.lo, fp.hi))));
    let mut problem = Problem {
        base: motor.clone(),
        rows,
        params,
        u: u0,
        weights: vec![1.0; n_read],
        evals: std::cell::Cell::new(0),
        last: std::cell::RefCell::new(None),
    };
    // The crate's patience bounds its own residual evaluations at patience·(n + 1), and each
    // accepted step costs a Jacobian of n + 1 more; so patience = budget/(n + 1)² keeps the
    // total near the budget. Tolerances 1e-12: looser ones (1e-9) stopped fits crawling
    // along a shallow valley early (seed 001 Table 2: preload_stiffening's evidence fell
    // from 172 to −1), which cost more in verdicts than they saved in time.
    let np1 = params.len() + 1;
    let lm = LevenbergMarquardt::new()
        .with_patience((opts.max_evaluations / (np1 * np1)).max(2))
        .with_ftol(1e-12)
        .with_xtol(1e-12)
        .with_gtol(1e-10);
    let mut warnings = Vec::new();
    let mut last = None;
    for pass in 0..=opts.irls_passes {
        let (p, report) = lm.minimize(problem);
        problem = p;
        last = Some(report.termination);
        if pass < opts.irls_passes {
            // Huber weights from the current unweighted residuals.
            let r = residuals(&problem.motor_at(&problem.u), rows);
            let w: Vec<f64> =
                r.iter().map(|x| if x.abs() <= opts.huber_k { 1.0 } else { (opts.huber_k / x.abs()).sqrt() }).collect();
            // unchanged weights: another pass would end where this one did
            if w.iter().zip(&problem.weights).all(|(a, b)| (a - b).abs() <= 1e-3 * b) {
                break;
            }
            problem.weights = w;
            *problem.last.borrow_mut() = None;
        }
    }
    if let Some(t) = last.filter(|t| !t.was_successful()) {
        warnings.push(format!("the fit stopped before converging ({t:?})"));
    }
    let fitted = problem.motor_at(&problem.u);
    let r = residuals(&fitted, rows);
    let chi2: f64 = r.iter().map(|x| x * x).sum();
    if r.iter().any(|x| *x == 50.0) {
        warnings.push("the model has no solution at some measured points (counted as 50-sigma misses)".into());
    }
    // Uncertainties: cov(p) = s²·(JᵀJ)⁻¹ with J in p-coordinates, computed on relative
    // parameters p/scale so that parameters of very different magnitude (E_f ~ 1e8 Pa,
    // C0 ~ 1e-9 F) do not make the matrix numerically singular.
    let j = problem.jacobian().unwrap_or_else(|| DMatrix::zeros(n_read, params.len()));
    let mut jp = j.clone();
    let mut scale = vec![1.0; params.len()];
    for (k, fp) in params.iter().enumerate() {
        let d = fp.dp_du(problem.u[k]);
        scale[k] = fp.param.get(&fitted).abs().max(1e-3 * (fp.hi - fp.lo));
        let col = jp.column(k) * (scale[k] / d);
        jp.set_column(k, &col);
    }
    let dof = (n_read - params.len()).max(1) as f64;
    let s2 = (chi2 / dof).max(1e-300);
    let jtj = jp.transpose() * &jp;
    // nalgebra's plain `svd` iterates without bound on non-finite input; `try_svd` with an
    // iteration cap returns None instead.
    let nan = || DMatrix::from_element(params.len(), params.len(), f64::NAN);
    let cov = if jtj.iter().all(|x| x.is_finite()) {
        match jtj.clone().try_svd(true, true, 1e-15, 500) {
            Some(svd) => {
                let smax = svd.singular_values.max();
                svd.pseudo_inverse(smax * 1e-14).unwrap_or_else(|_| nan())
            }
            None => nan(),
        }
    } else {
        nan()
    };
    let mut out = Vec::new();
    for (k, fp) in params.iter().enumerate() {
        let value = fp.param.get(&fitted);
        let var = cov[(k, k)] * s2 * scale[k] * scale[k];
        let se = if var.is_finite() && var >= 0.0 { var.sqrt() } else { f64::NAN };
        let span = if fp.log {
            (value / fp.lo).ln().min((fp.hi / value).ln()) / (fp.hi / fp.lo).ln()
        } else {
            ((value - fp.lo).min(fp.hi - value)) / (fp.hi - fp.lo)
        };
        let at_bound = span < 0.005;
        let rel = se / value.abs().max(1e-300);
        let identifiable = jtj[(k, k)] > 0.0 && se.is_finite() && rel < 1.0;
        if at_bound {
            warnings.push(format!(
                "{} sits on a bound ({:.4e} in [{:.4e}, {:.4e}])",
                fp.param.name(),
                value,
                fp.lo,
                fp.hi
            ));
        }
        if !identifiable {
            warnings.push(format!(
                "{} is not identifiable from these data (relative standard error {:.2})",
                fp.param.name(),
                rel
            ));
        }
        out.push(FittedParam { name: fp.param.name(), value, std_error: se, at_bound, identifiable });
    }
    let evaluations = problem.evals.get();
    let lin = Linearisation {
        residuals: DVector::from_iterator(r.len(), r.iter().zip(&problem.weights).map(|(x, w)| x * w)),
        base: problem.base,
        params: params.to_vec(),
        u: problem.u,
        weights: problem.weights,
        jacobian: j,
    };
    Ok(Calibration { motor: fitted, params: out, chi2, n_readings: n_read, evaluations, warnings, lin })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::presets::preset;

    /// Noise-free readings (speed, input power, feedback voltage at their default σ) of `m`
    /// over a preload × torque grid at 200 V, 43 kHz.
    pub(crate) fn rows_on_grid(m: &Motor, preloads: &[f64], torques: &[f64]) -> Vec<ObservedRow> {
        let mut rows = Vec::new();
        for &f in preloads {
            for &t in torques {
                let op = OperatingPoint::new(f, t, 200.0, 43e3);
                let s = crate::solve(m, &op);
                let readings = [Observable::SpeedRpm, Observable::InputPowerW, Observable::FeedbackV]
                    .iter()
                    .map(|&o| {
                        let v = o.predict(&s, 25.0);
                        (o, v, o.default_sigma(v))
                    })
                    .collect();
                rows.push(ObservedRow { op, readings, ambient_c: 25.0 });
            }
        }
        rows
    }

    fn rows_from(m: &Motor) -> Vec<ObservedRow> {
        rows_on_grid(m, &[100.0, 200.0, 300.0, 400.0], &[0.0, 0.2, 0.4])
    }

    #[test]
    fn recovers_perturbed_parameters_from_noise_free_data() {
        let truth = preset("trum60a").unwrap();
        let rows = rows_from(&truth);
        let mut start = truth.clone();
        start.friction_layer.friction_coefficient *= 1.3;
        start.stator.modal_damping_ns_per_m *= 0.7;
        let params = vec![
            fit_rel(&start, "friction_layer.friction_coefficient", 0.3, 3.0),
            fit_rel(&start, "stator.modal_damping_ns_per_m", 0.2, 5.0),
        ];
        let cal = calibrate(&start, &rows, &params, &FitOptions::default()).unwrap();
        let mu = cal.motor.friction_layer.friction_coefficient;
        let c = cal.motor.stator.modal_damping_ns_per_m;
        assert!((mu - 0.3).abs() < 1e-4, "mu {mu}");
        assert!((c - 10.0).abs() < 1e-3, "c {c}");
        assert!(cal.chi2 < 1e-6, "{}", cal.chi2);
    }

    #[test]
    fn bound_transform_round_trips() {
        let fp = FitParam { param: ParamRef::Motor("x".into()), lo: 0.1, hi: 10.0, log: true };
        for p in [0.11, 1.0, 9.0] {
            assert!((fp.from_u(fp.to_u(p)) - p).abs() < 1e-9 * p);
        }
        let fp = FitParam { param: ParamRef::Motor("x".into()), lo: -1.0, hi: 2.0, log: false };
        let u = 0.3;
        let h = 1e-6;
        let fd = (fp.from_u(u + h) - fp.from_u(u - h)) / (2.0 * h);
        assert!((fd - fp.dp_du(u)).abs() < 1e-8);
    }

    #[test]
    fn too_few_readings_is_an_error() {
        let m = preset("trum60a").unwrap();
        let rows = vec![ObservedRow {
            op: OperatingPoint::new(100.0, 0.0, 200.0, 43e3),
            readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
            ambient_c: 25.0,
        }];
        let err = calibrate(&m, &rows, &baseline_params(&m, &rows), &FitOptions::default()).unwrap_err();
        assert!(err.to_string().contains("cannot determine"), "{err}");
    }
}

//! Steady states of slightly changed motors by the implicit function theorem: the
//! columns of a calibration Jacobian without solving each changed motor from scratch.
//!
//! A converged solve is a fixed point z* = Φ(z*; q) of the steady-state map
//! ([`crate::solve::state_map`]: z = amplitude, temperature rise, electrode voltage; q the
//! motor's parameters and the operating point) and reports y(z*; q). For a small change of
//! q to q', the fixed point moves by dz = (I − Φ_z)⁻¹·[Φ(z*; q') − Φ(z*; q)] and the
//! solution to y(z*; q') + y_z·dz, both to first order in the change. Φ_z and y_z are
//! forward differences at z* (one map pass per iterated component, shared by every
//! parameter); each changed motor then costs one map pass — one trial amplitude with its
//! inner angle solves started at the base's roots — where solving it from scratch descends
//! the amplitude through 6-10 trials, each with its own inner solves. The eccentric
//! average is the same combination of such solves at the ripple's preloads.
//!
//! For a forward-difference step h the result differs from the from-scratch solve by
//! O(h²) (the neglected curvature in z) plus the inner solves' tolerances; the test below
//! checks whole Jacobian columns against central differences of from-scratch solves.
//!
//! A clamped base point (W = 0) stays clamped for the changed motor, whose clamped state
//! is a closed form: the descent that finds a stator clamped is not repeated per column
//! (it was 30 % of a 1000-row diagnosis, docs/PERFORMANCE.md).
//!
//! Where the base point has no steady state to carry over (no convergence, the rotor
//! sticking in a sector of an eccentric revolution, I − Φ_z singular), or the change
//! switches an iterated effect on or off, [`solve_near`] returns None and the caller
//! solves from scratch.

use crate::params::Motor;
use crate::solve::{
    eccentric_average_with, finite_or_unconverged, iterated, map_solution, solve_clamped, solve_effects,
    solve_prepared_with, state_map, OperatingPoint, Prepared, Solution, Status, Trial, Work,
};
use nalgebra::{Matrix3, Vector3};

/// One steady-state solve linearised at its fixed point.
struct Linear {
    /// The base motor and operating point, and the base trial at z* (reused for a motor
    /// whose trials are the same: one that differs only in output constants).
    p: Prepared,
    op: OperatingPoint,
    trial: Trial,
    z: [f64; 3],
    /// The components of z the solve iterates on (the amplitude always).
    active: [bool; 3],
    /// (θs, φ0) of the base solution: the start of every inner solve.
    guess: (f64, Option<f64>),
    /// Φ(z*; q) as this map pass computes it (the reference of the differences).
    g0: [f64; 3],
    /// (I − Φ_z)⁻¹ on the active components (identity elsewhere).
    inv: Matrix3<f64>,
    /// ∂y/∂z_j of every additive quantity, for the active j.
    dy: [Option<Solution>; 3],
}

impl Linear {
    /// Linearises the converged solve `s` of `p` at `op`; None when it has no smooth steady
    /// state there.
    fn at(p: &Prepared, op: &OperatingPoint, s: &Solution) -> Option<Linear> {
        if !matches!(s.status, Status::Ok | Status::Stall) || s.amplitude_m.is_nan() || s.amplitude_m <= 0.0 {
            return None;
        }
        let (thermal, sag) = iterated(p, op);
        let active = [true, thermal, sag];
        let z = [s.amplitude_m, s.temperature_rise_at_elapsed_k, s.electrode_voltage_v];
        let guess = (s.stick_half_angle_rad, Some(s.contact_half_angle_rad).filter(|_| !s.full_contact));
        let (g0, y0, trial) = state_map(p, op, z, guess, None);
        if y0.status != s.status {
            return None;
        }
        let mut m = Matrix3::<f64>::identity();
        let mut dy = [None, None, None];
        for j in (0..3).filter(|&j| active[j]) {
            // Steps of 1e-6 relative (a kelvin's millionth for the temperature rise): the
            // map's own noise (inner solves to ~1e-13) stays near 1e-7 of the derivative.
            let h = 1e-6 * if j == 1 { z[j].abs().max(1.0) } else { z[j].abs() };
            let mut zj = z;
            zj[j] += h;
            let (gj, yj, _) = state_map(p, op, zj, guess, None);
            if yj.status != y0.status {
                // a stall boundary between z* and z* + h: no derivative to take
                return None;
            }
            for i in (0..3).filter(|&i| active[i]) {
                m[(i, j)] -= (gj[i] - g0[i]) / h;
            }
            dy[j] = Some(map_solution(&yj, Some(&y0), |a, b| (a - b) / h));
        }
        // det(I − Φ_z) does not depend on the units of z; near zero the fixed point is at a
        // fold and moves without bound.
        let det = m.determinant();
        let inv = m.try_inverse().filter(|_| det.is_finite() && det.abs() > 1e-9)?;
        Some(Linear { p: p.clone(), op: *op, trial, z, active, guess, g0, inv, dy })
    }

    /// The steady state of `p` at `op` to first order from this base; None when `p`
    /// iterates on other components than the base.
    fn eval(&self, p: &Prepared, op: &OperatingPoint) -> Option<Solution> {
        let (thermal, sag) = iterated(p, op);
        if [true, thermal, sag] != self.active {
            return None;
        }
        let same = (*op == self.op && p.same_trials(&self.p, op)).then_some(&self.trial);
        let (g, y, _) = state_map(p, op, self.z, self.guess, same);
        let dz = self.inv * Vector3::from_fn(|i, _| if self.active[i] { g[i] - self.g0[i] } else { 0.0 });
        let mut out = y;
        for (j, d) in self.dy.iter().enumerate() {
            if let Some(d) = d {
                out = map_solution(&out, Some(d), |a, b| a + b * dz[j]);
            }
        }
        if out.status == Status::Ok && out.speed_rad_s < 0.0 {
            // The status is the changed motor's at the base state; the correction carried a
            // point within a step of stall across it (voltage_sag, μ × (1 + 1e-4): Ok at
            // −0.002 rpm where the whole solve stalls). Solve it whole.
            return None;
        }
        out.efficiency = crate::losses::efficiency(out.output_power_w, out.input_power_w);
        Some(out)
    }
}

/// One steady-state solve of a base point, carried over to nearby motors.
enum Part {
    /// A running or stalled state, linearised at its fixed point.
    Smooth(Box<Linear>),
    /// A clamped stator (W = 0, the only fixed point of the amplitude map): a slightly
    /// changed motor is clamped too, and its clamped state is a closed form (with the
    /// effects' fixed point on it, [`solve_clamped`]). Within a forward-difference step of
    /// the clamping edge the changed motor would run instead; the whole solve then jumps
    /// and has no derivative to give, and the clamped one-sided answer is kept. `active`:
    /// the components the base iterates on (thermal, sag), as for [`Linear`].
    Clamped { active: (bool, bool) },
}

impl Part {
    fn at(p: &Prepared, op: &OperatingPoint, s: &Solution) -> Option<Part> {
        if s.status == Status::Clamped {
            Some(Part::Clamped { active: iterated(p, op) })
        } else {
            Linear::at(p, op, s).map(|l| Part::Smooth(Box::new(l)))
        }
    }

    fn eval(&self, p: &Prepared, op: &OperatingPoint) -> Option<Solution> {
        match self {
            Part::Smooth(l) => l.eval(p, op),
            Part::Clamped { active } => (iterated(p, op) == *active).then(|| solve_clamped(p, op)),
        }
    }
}

/// A row's base steady state, linearised for nearby motors (see the module docs).
pub(crate) struct Base {
    parts: Vec<Part>,
    eccentric: bool,
}

/// A point's solution with the steady-state solves behind it: (operating point, solution)
/// of each in call order — one, or the nominal one and the ripple samples of an eccentric
/// motor.
pub(crate) struct Solved {
    pub(crate) solution: Solution,
    calls: Vec<(OperatingPoint, Solution)>,
}

/// `solve_prepared(p, motor, op, None)`, keeping the solves behind it for [`linearise`].
pub(crate) fn solve_kept(p: &Prepared, motor: &Motor, op: &OperatingPoint) -> Solved {
    let mut calls = Vec::new();
    let work = Work::of(p);
    let solution = solve_prepared_with(p, motor, op, None, &work, |o, g| {
        let s = solve_effects(p, o, g, &work);
        calls.push((*o, s.clone()));
        s
    });
    Solved { solution, calls }
}

/// Linearises a point solved by [`solve_kept`] with the motor prepared as `p`; None when
/// there is nothing smooth to linearise (the caller then solves changed motors from
/// scratch): no running or stalled state, or an eccentric revolution that stops in a
/// sector.
pub(crate) fn linearise(p: &Prepared, solved: &Solved) -> Option<Base> {
    let eccentric = p.runout_m > 0.0;
    // an eccentric motor clamped at the nominal preload is that one solve (no ripple samples)
    let ok = if eccentric {
        solved.solution.status == Status::Ok || (solved.solution.status == Status::Clamped && solved.calls.len() == 1)
    } else {
        solved.solution.status.is_valid()
    };
    if !ok || solved.calls.is_empty() {
        return None;
    }
    let parts = solved.calls.iter().map(|(o, s)| Part::at(p, o, s)).collect::<Option<Vec<_>>>()?;
    Some(Base { parts, eccentric })
}

/// The steady state of `motor` (prepared as `p`) at `op`, to first order from `base`: the
/// base's own motor gives the base solution exactly as every other motor's is computed, so
/// differences between them carry no solver tolerance. None when `motor` iterates on other
/// effects than the base (the caller solves it from scratch).
pub(crate) fn solve_near(base: &Base, p: &Prepared, motor: &Motor, op: &OperatingPoint) -> Option<Solution> {
    if (p.runout_m > 0.0) != base.eccentric {
        return None;
    }
    let s = if base.eccentric {
        let (mut next, mut ok) = (0, true);
        let s = eccentric_average_with(p, motor, op, None, |o, _| {
            let s = base.parts.get(next).and_then(|l| l.eval(p, o));
            next += 1;
            s.unwrap_or_else(|| {
                ok = false;
                Solution::invalid(Status::NoConvergence)
            })
        });
        if !ok {
            return None;
        }
        s
    } else {
        base.parts[0].eval(p, op)?
    };
    Some(finite_or_unconverged(p, s))
}

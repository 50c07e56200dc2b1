//! The fixed points of the effects that depend on the solution itself: the temperature
//! rise of `thermal_drift` (from the losses) and the electrode voltage of `voltage_sag`
//! (from the current), iterated around the amplitude solve, with the lower-branch and
//! single-scalar searches for a sagging drive whose passes do not settle.

use super::bracket::{bracketed_secant, dip_below_zero, SignBracket};
use super::descent::{amplitude_rtol, solve_drive, solve_drive_below, WarmTop};
use super::finish::{clamped_trial, finish, rest_torque_factor};
use super::trial::{sagged_voltage_at, sagged_voltage_v, trial, Drive, Trial};
use super::{OperatingPoint, Prepared, Solution, Status, Work};
use crate::effects::Effect;
use crate::stator;

/// Effects that depend on the solution itself (temperature from the losses, electrode
/// voltage from the current) are solved by fixed-point iteration around the amplitude
/// solve, starting from the set voltage and the cold motor as the bench does. Near
/// clamping the electrode voltage alternates between passes: a clamped stator draws
/// little current (with the truth form's reactive source the electrode voltage even
/// rises above the set one), a moving one more, so V ↦ G(V) falls with V. Plain passes
/// there either crawl (ratio ≈ −0.85) or cycle for ever between a clamped and a moving
/// state (trum60a-like truth motor, 400 N: 200 V → clamped → 217.9 V → moving → 204.0 V →
/// clamped …); the one consistent state lies between V and G(V) (210.1 V, moving). The
/// secant step is therefore kept inside that interval ([`bracketed_secant`]): unbounded,
/// it is faster but can leave it.
///
/// Every trial is charged to `work`, the budget of the solve this one belongs to.
pub(crate) fn solve_effects(p: &Prepared, op: &OperatingPoint, guess: Option<&Solution>, work: &Work) -> Solution {
    solve_effects_with(p, op, guess, true, work, |d, g, top| solve_drive_below(p, d, op, g, top, work))
}

/// The clamped state of `p` at `op` (W = 0) with the effects' fixed point solved on it,
/// without the amplitude descent that finds a stator clamped: what [`solve_effects`] returns
/// where the stator clamps. For crate::sensitivity, which carries a clamped base state over
/// to slightly changed motors (the descent to W = 0 is the costliest solve there is: 10-80
/// trials).
pub(crate) fn solve_clamped(p: &Prepared, op: &OperatingPoint) -> Solution {
    // (no trial: nothing is charged to the budget)
    let work = Work::of(p);
    solve_effects_with(p, op, None, false, &work, |d, _, _| finish(p, d, op, &clamped_trial(p, d), Status::Clamped, 0))
}

/// [`solve_effects`] with `drive(d, guess, top)` solving the amplitude under drive `d`
/// (`top`: a proven upper bound of its largest fixed point, [`settle_with`]);
/// `branches`: `drive` is the amplitude solve, whose lower (stalled) branch is searched
/// where the electrode voltage jumps ([`settle_lower_branch`]); `work`: the solve's budget.
fn solve_effects_with(
    p: &Prepared,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    branches: bool,
    work: &Work,
    drive: impl Fn(&Drive, Option<&Solution>, Option<WarmTop>) -> Solution,
) -> Solution {
    let (thermal, sag) = iterated(p, op);
    if !thermal && !sag {
        return drive(&Drive::at(p, op), guess, None);
    }
    let direct_warm = |d: &Drive, _: f64, g: Option<&Solution>, top: Option<WarmTop>| drive(d, g, top);
    let direct_cold = |d: &Drive, _: f64, g: Option<&Solution>| drive(d, g, None);
    let (mut s, mut rise, mut settled) =
        settle_with(p, op, guess, (thermal, sag), 0.0, work, PassState::Warm(&direct_warm));
    if branches && sag && !thermal && !settled {
        if let Some(stalled) =
            settle_lower_branch(p, op, &s, 0.0, work).or_else(|| settle_on_amplitude(p, op, 0.0, work))
        {
            (s, settled) = (stalled, true);
        }
    }
    if thermal && sag && !settled && s.status.is_valid() {
        // The joint passes can cycle (trum60a, sag 150 Ω, nominal thermal_drift, 439.7 N,
        // 1.0 N·m, 173.7 V, 39.9 kHz, 611 s: a 4-cycle between running and stalled states
        // over 100 passes), and with two scalars there is no sign change to bracket. Nested
        // as the physics is: the electrode voltage follows the temperature at once, the
        // temperature the losses slowly. So the temperature rise is solved as a scalar
        // fixed point (with its bracket), each of its states the electrode voltage's own
        // fixed point (with its bracket) at that rise. Only where the joint passes failed:
        // the points that settle keep their results to the bit.
        // An electrode voltage that does not settle at some rise on the way (it cycles
        // between a clamped and a moving stator there) does not end the search at once: its
        // last state's losses still point the rise on, and only the state at the final rise
        // must be settled. (Ending at the first such rise would end 3115 of 4078 failures
        // in a 150 × 150 map, some of which have a steady state.) But each such rise
        // costs 100 passes, and past a few of them the
        // search rarely ends settled: the third ends it. (Two 150 × 150 maps of
        // docs/RELIABILITY.md: 14-16 s and 2707 + 2658 failures of 45 000 so; unbounded
        // 72-82 s for 1-6 % fewer failures; ending at the first 11-14 s, 5-7 % more.) The
        // search starts from the joint passes' last rise and state.
        // Where that fails too, it is run again with the electrode voltage's lower branch
        // searched at every rise (`settle_lower_branch`); not in the first run, whose path
        // through the rises it would change where that run settles (two of 1152 points
        // that settle `ok` in the first run end `no_convergence` with it).
        const UNSETTLED_RISES: usize = 2;
        let (from, rise0) = (s.clone(), rise);
        let nested = |lower: bool| {
            let inner_settled = std::cell::Cell::new(true);
            let unsettled = std::cell::Cell::new(0);
            // (cold descents: warm-started, a nested settle under strong drift and sag can
            // end 1.2e-9 off its own set voltage, beyond the 1e-9 a fixed point keeps;
            // tests/solver_convergence.rs `stress_self_consistent_effects`)
            let inner = |_: &Drive, r: f64, g: Option<&Solution>| {
                let (mut s, _, mut ok) = settle(p, op, g, (false, true), r, work, &direct_cold);
                if lower && !ok {
                    if let Some(l) =
                        settle_lower_branch(p, op, &s, r, work).or_else(|| settle_on_amplitude(p, op, r, work))
                    {
                        (s, ok) = (l, true);
                    }
                }
                inner_settled.set(ok);
                if !ok {
                    unsettled.set(unsettled.get() + 1);
                    if unsettled.get() > UNSETTLED_RISES {
                        return Solution { status: Status::NoConvergence, ..s };
                    }
                }
                s
            };
            let (s, rise, settled) = settle(p, op, Some(&from), (true, false), rise0, work, &inner);
            (s, rise, settled && inner_settled.get())
        };
        (s, rise, settled) = nested(false);
        if branches && !(settled && s.status.is_valid()) {
            let again = nested(true);
            if again.2 && again.0.status.is_valid() {
                (s, rise, settled) = again;
            }
        }
    }
    if !settled && s.status.is_valid() {
        // the temperature or electrode voltage still moves after 100 passes: the numbers
        // belong to no consistent state, so the point says so instead of reporting them
        s.status = Status::NoConvergence;
    }
    if !thermal {
        rise = s.temperature_rise_at_elapsed_k;
    }
    s.temperature_rise_at_elapsed_k = rise;
    s
}

/// The fixed point of the effects that iterate ((`thermal`, `sag`): the temperature rise,
/// the electrode voltage) by passes: each pass solves the state (`state(d, rise, guess)`)
/// at the drive of the latest temperature rise and electrode voltage and recomputes both
/// from it. A temperature rise that does not iterate stays at `rise0`. Returns the last
/// state, the rise and whether the passes settled; a state without valid numbers (no
/// convergence) ends them, and so does the solve's budget `work` once it is spent.
pub(super) fn settle(
    p: &Prepared,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    flags: (bool, bool),
    rise0: f64,
    work: &Work,
    state: &dyn Fn(&Drive, f64, Option<&Solution>) -> Solution,
) -> (Solution, f64, bool) {
    settle_with(p, op, guess, flags, rise0, work, PassState::Cold(state))
}

/// Largest ratio of relative amplitude change to relative electrode-voltage change between
/// passes at which a pass starts from the previous amplitude ([`settle_with`]). The ratio
/// is 1/r'(W) at the fixed point: near a fold of the amplitude map r' is tiny, the
/// descent's tolerance 1e-13 on r leaves W uncertain to 1e-13/r', and a descent from
/// another top lands elsewhere in that band (1e-9 apart at trum60-qut, 150 Ω, 640 N,
/// 0.075 N·m, 194 V, 41.56 kHz). Below the ratio the band is under 1e-10 of W.
const MAX_WARM_ELASTICITY: f64 = 1e3;

/// The ratio of relative amplitude change to relative electrode-voltage change between two
/// states (W [m], V [V]) under the same temperature rise: 1/r'(W) at their fixed point
/// ([`MAX_WARM_ELASTICITY`]). NaN where the voltages are equal or an amplitude is not finite.
fn amplitude_elasticity((w0, v0): (f64, f64), (w1, v1): (f64, f64)) -> f64 {
    ((w1 - w0) / w0) / ((v1 - v0) / v0)
}

/// The amplitude [m] at electrode voltage `v` [V] extrapolated from the state at `v_prev`
/// (amplitude `w_prev` [m]) along the `elasticity` measured between the two states before
/// it: a first trial for the warm descent, kept only strictly between zero and `bound`
/// [m], the proven upper bound it starts from. Late passes move V by 1e-5 to 1e-9 of
/// itself, where the extrapolation is within the descent's tolerance or one Newton step of
/// it: one trial a pass fewer than a descent from the bound.
fn predicted_amplitude(w_prev: f64, elasticity: f64, (v_prev, v): (f64, f64), bound: f64) -> Option<f64> {
    let w = w_prev * (1.0 + elasticity * (v - v_prev) / v_prev);
    (w > 0.0 && w < bound).then_some(w)
}

/// States the electrode voltage's passes solved (at one temperature rise) kept as upper
/// bounds of the largest fixed point at other voltages: the amplitude W₁ solved at V₁
/// bounds the largest fixed point at any V ≤ V₁ ([`settle_with`]). A pass whose voltage
/// rises over the previous one's (the passes alternate about the fixed point) is bounded
/// by an earlier state at a voltage above it. The latest [`AmplitudeBounds::KEPT`] states.
#[derive(Default)]
struct AmplitudeBounds {
    /// (V [V], W [m]) of the states, the latest at `next - 1` (modulo the length).
    kept: [Option<(f64, f64)>; AmplitudeBounds::KEPT],
    next: usize,
}

impl AmplitudeBounds {
    const KEPT: usize = 4;

    /// Keeps state `s` solved at electrode voltage `v` [V] where its amplitude is a
    /// solved one (running or stalled, positive and finite).
    fn record(&mut self, v: f64, s: &Solution) {
        if matches!(s.status, Status::Ok | Status::Stall) && s.amplitude_m > 0.0 && s.amplitude_m.is_finite() {
            self.kept[self.next % Self::KEPT] = Some((v, s.amplitude_m));
            self.next += 1;
        }
    }

    /// The least kept amplitude [m] solved at a voltage at or above `v` [V]: a proven upper
    /// bound of the largest fixed point at `v`; `None` where every kept state is below it.
    fn at(&self, v: f64) -> Option<f64> {
        self.kept.iter().flatten().filter(|&&(vk, _)| vk >= v).map(|&(_, w)| w).reduce(f64::min)
    }
}

/// A pass's state solve `state(d, rise, guess, top)` ([`settle_with`]).
type WarmState<'a> = dyn Fn(&Drive, f64, Option<&Solution>, Option<WarmTop>) -> Solution + 'a;

/// The state solve of [`settle_with`]'s passes: one that may start its amplitude descent
/// from a warm top, or one that always starts cold (`state(d, rise, guess)`; the passes
/// then neither look for a top nor judge one).
#[derive(Clone, Copy)]
enum PassState<'a> {
    Warm(&'a WarmState<'a>),
    Cold(&'a dyn Fn(&Drive, f64, Option<&Solution>) -> Solution),
}

impl PassState<'_> {
    fn solve(&self, d: &Drive, rise: f64, guess: Option<&Solution>, top: Option<WarmTop>) -> Solution {
        match self {
            PassState::Warm(f) => f(d, rise, guess, top),
            PassState::Cold(f) => f(d, rise, guess),
        }
    }
}

/// [`settle`] whose state solve (`state`, [`PassState::Warm`]) may start its amplitude
/// descent from `top`, a proven upper bound of the largest fixed point under `d`, instead
/// of the cold bound Θ·V/(ω·c).
///
/// The electrode voltage enters a trial only through G(W) = Θ·V/|Z(W)|: the impedance Z
/// depends on W and the drive's other inputs, not on V. So a pass of the electrode voltage
/// alone (the temperature rise fixed) at V₂ ≤ V₁ has G₂ = (V₂/V₁)·G₁ ≤ G₁ at every W, and
/// the previous pass's amplitude W₁, the largest fixed point of G₁ (G₁(W) < W above it),
/// bounds the largest fixed point of G₂ from above. Late passes move V by a hair, so the
/// descent from W₁, first trying the amplitude extrapolated along the passes' elasticity
/// ([`predicted_amplitude`]), needs 1-3 trials instead of a descent from the cold bound
/// (about five). Where V rises over the previous pass's, the least amplitude of the
/// latest states solved at a voltage at or above it bounds it instead
/// ([`AmplitudeBounds`]). Where no such state is a solved amplitude (clamped, unconverged)
/// or the amplitude is ill-conditioned ([`MAX_WARM_ELASTICITY`]), the pass descends from
/// the cold bound; the first pass after the set voltage's, without two
/// states to tell the conditioning before it, is judged after its warm descent and solved
/// again from the cold bound where it is ill-conditioned.
///
/// The passes end at the first state that is its own fixed point to the tolerances (1e-10
/// of the temperature rise, 1e-12 of the set voltage), which is returned.
fn settle_with(
    p: &Prepared,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    (thermal, sag): (bool, bool),
    rise0: f64,
    work: &Work,
    state: PassState,
) -> (Solution, f64, bool) {
    let mut d = Drive::at(p, op);
    let mut rise = rise0;
    if rise != 0.0 {
        d.warm(p, rise);
    }
    let mut s = state.solve(&d, rise, guess, None);
    let mut older: Option<(f64, f64)> = None;
    let mut bounds = AmplitudeBounds::default();
    let mut settled = false;
    // (x, G(x)) of the previous pass, for the temperature rise and the electrode voltage
    let mut last_pass: Option<((f64, f64), (f64, f64))> = None;
    // With one of the two effects on, the residual x − G(x) of its scalar is watched for a
    // sign change; passes that have not settled after BRACKET_AFTER, or whose state has
    // changed kind (clamped, stalled, running) JUMP_SWINGS times, switch to regula falsi
    // (or bisection, below) inside the latest sign change.
    let mut bracket = SignBracket::default();
    // (the status of the state and its unhalved |x − G(x)| at the latest point on either
    // side of the sign change: below zero, above it)
    let mut ends: [Option<(Status, f64)>; 2] = [None, None];
    let scale = if thermal { 1.0 } else { op.voltage_v };
    let (mut swings, mut was) = (0usize, s.status);
    for pass in 0..100 {
        swings += usize::from(s.status != was);
        was = s.status;
        let (mut new_rise, mut new_v) = (rise, d.v);
        if thermal {
            new_rise = temperature_rise_for_drift(p, s.total_loss_w(), op.elapsed_s);
        }
        if sag {
            new_v = sagged_voltage_v(p, op, &s);
        }
        if (new_rise - rise).abs() <= 1e-10 * (1.0 + rise.abs()) && (new_v - d.v).abs() <= 1e-12 * op.voltage_v {
            // `s` is its own fixed point to the tolerances: the state it was solved at is
            // the answer (another solve at the pass's next iterate would move it by less
            // than the tolerance, at the cost of an amplitude solve)
            settled = true;
            break;
        }
        let mut next = (
            bracketed_secant(rise, new_rise, last_pass.map(|l| l.0)),
            bracketed_secant(d.v, new_v, last_pass.map(|l| l.1)),
        );
        if sag && !thermal {
            next.1 = monotone_secant(d.v, new_v, last_pass.map(|l| l.1)).unwrap_or(next.1);
        }
        last_pass = Some(((rise, new_rise), (d.v, new_v)));
        if thermal != sag {
            let (x, gx) = if thermal { (rise, new_rise) } else { (d.v, new_v) };
            let bracketing = pass >= BRACKET_AFTER || swings >= JUMP_SWINGS;
            bracket.record(x, x - gx, bracketing);
            if x.is_finite() && (x - gx).is_finite() && x != gx {
                ends[usize::from(x > gx)] = Some((s.status, (x - gx).abs()));
            }
            if bracketing {
                let tol = scale.max(x.abs());
                if bracket.width().is_some_and(|w| w <= JUMP_WIDTH * tol) && (x - gx).abs() >= JUMP_RESIDUAL * tol {
                    // A residual this large at one end of so narrow a sign change needs
                    // |G'| ≥ JUMP_RESIDUAL / JUMP_WIDTH there: G jumps (as below), unsettled.
                    break;
                }
                // States of different kinds (clamped, stalled, running) at the two ends of
                // the sign change, each with a large residual: the branch changes inside it,
                // where G jumps unless it is steep across the change. Bisection halves the
                // sign change every pass, where regula falsi, whose ends' residuals do not
                // shrink at a jump, narrows it more slowly, and a jump is proven at a
                // coarser width.
                let across = match ends {
                    [Some((a, ra)), Some((b, rb))] => a != b && ra.min(rb) >= JUMP_RESIDUAL * tol,
                    _ => false,
                };
                if across && bracket.width().is_some_and(|w| w <= KIND_JUMP_WIDTH * tol) {
                    break;
                }
                if bracket.width().is_some_and(|w| w <= 1e-12 * tol) {
                    // The sign change has shrunk to a point without the residual vanishing
                    // to the tolerance. Where the residual is still large, G jumps there
                    // (the stator clamps or the rotor stalls on one side and moves on the
                    // other): no steady state on the branch the amplitude solve takes, only
                    // an oscillation between the two (a lower branch may still have one:
                    // `settle_lower_branch`). Where it is within 1e-9
                    // the fixed point is pinned by the sign change and G is only resolved
                    // more coarsely than the tolerance: near a fold of the amplitude map
                    // r(W) has a tiny slope, so the amplitude solve's 1e-13 tolerance
                    // leaves W uncertain to ~1e-10 and G(x) to a few 1e-12 (trum60-qut
                    // with a 150 Ω sag at 640 N, 0.075 N·m, 194 V, 41.56 kHz), and where
                    // G is steep (|G'| ~ 1e4) the tolerance is below x's own rounding.
                    // Settled.
                    settled = (x - gx).abs() <= 1e-9 * tol;
                    break;
                }
                let step = if across { bracket.midpoint() } else { bracket.regula_falsi() };
                if let Some(x) = step {
                    if thermal {
                        next.0 = x;
                    } else {
                        next.1 = x;
                    }
                }
            }
        }
        let v_prev = d.v;
        (rise, d.v) = next;
        if thermal {
            d.warm(p, rise);
        }
        let prev = s.clone();
        // (W, V) of the state before `prev`: their ratio of relative changes is
        // 1/r'(W) at the fixed point (W = V·Θ/|Z(W)|), how far the descent's tolerance
        // on r leaves W uncertain
        let elasticity = older.map(|(w0, v0): (f64, f64)| amplitude_elasticity((w0, v0), (prev.amplitude_m, v_prev)));
        let well_conditioned = elasticity.is_some_and(|e| e.abs() <= MAX_WARM_ELASTICITY);
        // Without two states yet (the first pass after the set voltage's), the pass is
        // tried from the previous amplitude all the same and its conditioning judged
        // afterwards, from the two states it then has: the same ratio, measured one pass
        // later.
        let judged_after = older.is_none();
        let warm_tops = matches!(state, PassState::Warm(_)) && sag && !thermal;
        if warm_tops {
            bounds.record(v_prev, &prev);
        }
        let bound = (warm_tops && (well_conditioned || judged_after)).then(|| bounds.at(d.v)).flatten();
        let warm = bound.is_some();
        let top = bound.map(|bound| WarmTop {
            bound,
            predicted: elasticity.and_then(|e| predicted_amplitude(prev.amplitude_m, e, (v_prev, d.v), bound)),
            contact_rad: None,
            stick_rad: None,
        });
        older = Some((prev.amplitude_m, v_prev));
        let guess = Some(&prev).filter(|g| g.status.is_valid());
        s = state.solve(&d, rise, guess, top);
        if warm && judged_after {
            // (false for a NaN too)
            let conditioned =
                amplitude_elasticity((prev.amplitude_m, v_prev), (s.amplitude_m, d.v)).abs() <= MAX_WARM_ELASTICITY;
            if !conditioned {
                s = state.solve(&d, rise, guess, None);
            }
        }
        if !s.status.is_valid() || work.exhausted() {
            break;
        }
    }
    (s, rise, settled)
}

/// Largest slope of the electrode voltage's pass map V ↦ G(V) at which
/// [`monotone_secant`] extrapolates a monotone approach.
const MAX_MONOTONE_SLOPE: f64 = 0.5;

/// The secant root of x − G(x) through this pass (`x`, `gx`) and the last one, where the
/// passes approach the fixed point from one side (G rises with x, slope in (0,
/// [`MAX_MONOTONE_SLOPE`]]): the step goes on in the passes' own direction, at most twice
/// as far as the plain pass. A sagging drive's passes descend from the set voltage at a
/// ratio of about 0.02 (trum60a, 150 Ω): plain passes need seven or eight to reach the
/// 1e-12 tolerance, the secant four or five. An overshoot past the fixed point is at most
/// the secant's error, and the passes after it alternate ([`bracketed_secant`]). `None`
/// where the passes alternate or the slope is out of that range.
fn monotone_secant(x: f64, gx: f64, last: Option<(f64, f64)>) -> Option<f64> {
    let (x0, g0) = last?;
    let slope = (gx - g0) / (x - x0);
    let monotone = (gx - x) * (g0 - x0) > 0.0 && (x - x0) * (gx - x) > 0.0;
    let next = x + (gx - x) / (1.0 - slope);
    (monotone && slope > 0.0 && slope <= MAX_MONOTONE_SLOPE && next.is_finite()).then_some(next)
}

/// A consistent state on a lower branch of the amplitude map where the electrode
/// voltage's passes found none on the upper one. The typical case: the running state draws
/// so much current that the sagged voltage falls below the fold of the running branch, and
/// the stalled state so little that the voltage recovers above it (trum60a, 10 Ω sag,
/// 490 N, 1.2 N·m, 165 V, 41 kHz: stalled up to 161.3 V with G ≈ 162.6 V, running above
/// with G ≈ 160 V). At the voltage the stalled state sets, the stall is a lower fixed point
/// of the amplitude map, below the running one that the descent from the top finds; a
/// rotor at rest stays at rest there (its blocking torque is below the load), so it is the
/// motor's steady state, as on a bench that loses speed under load. Its amplitude is found
/// by descending from a cap just above the lower root instead of from the top: below the
/// unstable middle root, where r(W) ≥ 0. `rise` [K]: the temperature rise.
///
/// At the clamping edge the lower state is the clamped stator (W = 0), at the voltage its
/// capacitive current leaves, if the drive cannot start it there: a small amplitude falls
/// back (r(W) ≥ 0; near W = 0 the map is linear in W, its slope ∝ V/(μ·F)).
///
/// Where a clamped stator would start at its own voltage, a stall just above W = 0 is
/// looked for the same way.
///
/// `None` (the point stays `no_convergence`) where the lower state's passes do not settle,
/// or `s` is none of a stall, a clamped state or a running state. Such a point may still
/// have a steady state this does not look for: one on the middle root of the amplitude
/// map, unstable at a fixed voltage but possibly stable with the sag (docs/EFFECTS.md).
fn settle_lower_branch(p: &Prepared, op: &OperatingPoint, s: &Solution, rise: f64, work: &Work) -> Option<Solution> {
    let at = |v: f64| {
        let mut d = Drive::at(p, op);
        if rise != 0.0 {
            d.warm(p, rise);
        }
        d.v = v;
        d
    };
    // The first amplitude from `w` up (by `step`, at most `n` steps) where r(W) ≥ 0: a cap
    // above the lowest root at or below it, below the middle one.
    let cap_from = |d: &Drive, mut w: f64, step: f64, n: usize| {
        for _ in 0..n {
            let t = work.trial(p, d, w, None, None);
            if t.w >= t.w_next {
                return Some(w);
            }
            w *= step;
        }
        None
    };
    let low = match s.status {
        Status::Stall | Status::Clamped => s.clone(),
        Status::Ok => solve_drive(p, &at(sagged_voltage_v(p, op, s)), op, Some(s), work),
        _ => return None,
    };
    let per_volt = match low.status {
        Status::Clamped => {
            // The clamped stator at the voltage its own (capacitive) current leaves, where
            // it stays clamped if the drive cannot start it: a small amplitude falls back,
            // r(W) ≥ 0 (near W = 0 the map is linear, W' ∝ V·W/(μ·F), so one trial
            // decides).
            let rest =
                |d: &Drive, _: f64, _: Option<&Solution>| finish(p, d, op, &clamped_trial(p, d), Status::Clamped, 0);
            let (c, _, settled) = settle(p, op, Some(&low), (false, true), rise, work, &rest);
            let d = at(c.electrode_voltage_v);
            let tiny = d.clamp_floor(p.theta);
            let t = work.trial(p, &d, tiny, None, None);
            if t.w >= t.w_next {
                return (settled && c.status == Status::Clamped).then_some(c);
            }
            // It would start: a stall may sit just above W = 0 (e.g. 10 Ω, 490 N,
            // 0.95 N·m, 155 V, 41 kHz: W = 3.2e-8 m at 154.9 V). Its cap is the first
            // doubling up from there with r ≥ 0.
            cap_from(&d, tiny, 2.0, 40)? / d.v
        }
        Status::Stall | Status::Ok if low.amplitude_m > 0.0 => low.amplitude_m / low.electrode_voltage_v,
        _ => return None,
    };
    // The cap at each pass's voltage: the lower amplitude scaled with the voltage, stepped
    // up by 1.25× until r(W) ≥ 0 (the stalled branch steepens near clamping: 500 N,
    // 1.1 N·m above, 0.33 µm at 160 V, 0.8 µm at 162.7 V). r stays ≥ 0 from the stalled
    // root up to the middle one (0.8-3.5 µm there; 1.9-3.3 µm at 470 N, 1.4 N·m), so the
    // first such step is a cap; without one in 12 steps the pass ends unconverged.
    let below = |d: &Drive, _: f64, g: Option<&Solution>| match cap_from(d, per_volt * d.v, 1.25, 12) {
        Some(bound) => {
            let top = WarmTop { bound, predicted: None, contact_rad: None, stick_rad: None };
            solve_drive_below(p, d, op, g, Some(top), work)
        }
        None => Solution::invalid(Status::NoConvergence),
    };
    let (lower, _, settled) = settle(p, op, Some(&low), (false, true), rise, work, &below);
    (settled && matches!(lower.status, Status::Stall | Status::Ok)).then_some(lower)
}

/// The sagging drive's balance h(W) = W − Θ·V_e(W)/|Z(W)| at amplitude `w` [m] under the
/// drive `d` (its set voltage): (h [m], the trial at W, the electrode voltage V_e [V]). The
/// phase admittance Y = I/V depends on W only, through Z(W) ([`stator::phase_current_a`]),
/// so V_e(W) = V_set/|1 + Z_src·Y(W)| needs no passes, and each h(W) is one trial, charged
/// to `work`.
pub(super) fn sag_balance(p: &Prepared, d: &Drive, op: &OperatingPoint, w: f64, work: &Work) -> (f64, Trial, f64) {
    let t = work.trial(p, d, w, None, None);
    let (ire, iim) = stator::phase_current_a(d.v, d.omega, p.c0, p.tan_d, p.theta, t.z);
    let ve = sagged_voltage_at(p, op, (ire / d.v, iim / d.v));
    (w - t.w_next * ve / d.v, t, ve)
}

/// Ratio of the downward scan of [`settle_on_amplitude`]. On a trum60a map at 150 Ω and
/// 41 kHz (300-560 N × 0-1.4 N·m × 120-180 V) h dips below zero over 3-10 % of W between
/// samples ×0.8 apart: at 41 of 24 000 points that scan missed the largest root (a lower
/// one: 31.9 instead of 151.2 rpm at 458.6 N, 0 N·m, 166.7 V); ×0.9 missed 9, ×0.97 none
/// (against ×0.999), at the same map time. Below a thousandth of the bound the steps are
/// ×0.8 again.
const SAG_SCAN_RATIO: f64 = 0.97;

/// A sagging drive's steady state as the largest root of one scalar, h(W) = W −
/// Θ·V_e(W)/|Z(W)| ([`sag_balance`]), for the points whose electrode-voltage passes and
/// [`settle_lower_branch`] found none. A root satisfies both the amplitude map at its
/// voltage and the sag at its amplitude. The largest root is found by stepping down from
/// above the amplitude bound (h > 0 there, steps ×[`SAG_SCAN_RATIO`]) and refined in its sign
/// change; h > 0 above it, so it is stable when the sag acts (dW/dt ∝ −h) even where, at
/// its voltage held fixed, it is the amplitude map's unstable middle root, which the other
/// routes never take (150 Ω, 380 N, 0.2 N·m, 150 V). No root above
/// W = 0: the clamped stator at its own voltage, which a tiny amplitude does not start.
/// `rise` [K]: the temperature rise. `None` where a step or trial has no finite value.
///
/// A dip of h below zero narrower than a step can lie between two samples. Where a sample
/// is lower than both its neighbours, the dip about it is searched ([`dip_below_zero`]).
/// A dip narrower than about 3 % of W that does not pull a sample below its neighbours, or
/// lies away from the least one, is still passed over, and the root found is then a lower
/// one, also a steady state.
fn settle_on_amplitude(p: &Prepared, op: &OperatingPoint, rise: f64, work: &Work) -> Option<Solution> {
    let mut d = Drive::at(p, op);
    if rise != 0.0 {
        d.warm(p, rise);
    }
    let h = |w: f64| sag_balance(p, &d, op, w, work);
    let bound = p.theta * d.v / (d.omega * d.c);
    // A partly reactive source can raise the electrode voltage above the set one: grow the
    // top until h > 0.
    let (mut hi, mut h_hi) = (bound, h(bound).0);
    for _ in 0..20 {
        if h_hi > 0.0 {
            break;
        }
        hi *= 2.0;
        h_hi = h(hi).0;
    }
    if h_hi.is_nan() || h_hi <= 0.0 {
        return None;
    }
    let tiny = d.clamp_floor(p.theta);
    let mut lo = None;
    // the sample above `hi`, once there is one
    let mut above: Option<(f64, f64)> = None;
    while hi > tiny {
        // (below a thousandth of the bound, amplitudes of nanometres, coarse steps: a scan
        // that finds no root costs 289 trials instead of 682)
        let ratio = if hi > 1e-3 * bound { SAG_SCAN_RATIO } else { 0.8 };
        let w = (ratio * hi).max(tiny);
        if w >= hi {
            // a subnormal amplitude that the step no longer lowers (0.8 × 5e-324 rounds
            // back to 5e-324): the scan cannot go on, and there is no amplitude left to find
            return None;
        }
        let e = h(w);
        let hw = e.0;
        if !hw.is_finite() {
            return None;
        }
        if hw <= 0.0 {
            lo = Some((w, e));
            break;
        }
        if let Some((wa, ha)) = above {
            if h_hi < ha && h_hi < hw {
                let dip = dip_below_zero(
                    |x| {
                        let e = h(x);
                        (e.0, e)
                    },
                    (w, hw),
                    (hi, h_hi),
                    (wa, ha),
                );
                match dip {
                    Err(()) => return None,
                    Ok(Some(((wn, (_, en)), pos))) => {
                        lo = Some((wn, en));
                        (hi, h_hi) = pos;
                        break;
                    }
                    Ok(None) => {}
                }
            }
        }
        above = Some((hi, h_hi));
        (hi, h_hi) = (w, hw);
    }
    let Some((lo_w, lo_eval)) = lo else {
        // no root above W = 0: the clamped stator, at the voltage its own current leaves
        let rest = |d: &Drive, _: f64, _: Option<&Solution>| finish(p, d, op, &clamped_trial(p, d), Status::Clamped, 0);
        let (c, _, settled) = settle(p, op, None, (false, true), rise, work, &rest);
        return (settled && c.status == Status::Clamped).then_some(c);
    };
    // Illinois regula falsi in the sign change, to the amplitude solve's tolerance
    let rtol = amplitude_rtol(p);
    let mut b = SignBracket { neg: Some((lo_w, lo_eval.0)), pos: Some((hi, h_hi)), last_side: 0 };
    let (mut best, mut evals) = (lo_eval, 0u32);
    for _ in 0..200 {
        let (Some((a, _)), Some((c, _))) = (b.neg, b.pos) else { return None };
        if (c - a).abs() <= rtol * c {
            break;
        }
        let w = b.regula_falsi()?;
        let e = h(w);
        evals += 1;
        if !e.0.is_finite() {
            return None;
        }
        if e.0.abs() < best.0.abs() {
            best = e;
        }
        b.record(w, e.0, true);
        if e.0 == 0.0 {
            break;
        }
    }
    let (_, t, ve) = best;
    d.v = ve;
    let s = finish(p, &d, op, &t, if t.stalled { Status::Stall } else { Status::Ok }, evals);
    s.status.is_valid().then_some(s)
}

/// Which solution-dependent inputs [`solve_effects`] iterates on at `op`: (the temperature
/// rise of `thermal_drift`, the electrode voltage of `voltage_sag`).
pub(crate) fn iterated(p: &Prepared, op: &OperatingPoint) -> (bool, bool) {
    (p.thermal.iter().any(|&x| x != 0.0) && op.elapsed_s > 0.0, p.sag_ohm > 0.0)
}

/// One pass of the steady-state map at the state z = (amplitude W [m], temperature rise
/// [K], electrode voltage [V]): the trial at W under the drive that z sets, its solution,
/// and the state it implies (Θ·V/|Z|, the rise from its losses, the sagged voltage); the
/// components [`iterated`] leaves alone are copied from z. `guess` = (θs, φ0) starts the
/// inner angle solves, whose roots are unique. A converged [`solve_effects`] is a fixed
/// point of this map (to its tolerances) and the solution is the one it reported.
///
/// `same`: a trial at the same z and operating point of a motor whose trials are this
/// one's ([`Prepared::same_trials`]), reused instead of computed.
pub(crate) fn state_map(
    p: &Prepared,
    op: &OperatingPoint,
    z: [f64; 3],
    guess: (f64, Option<f64>),
    same: Option<&Trial>,
) -> ([f64; 3], Solution, Trial) {
    let (thermal, sag) = iterated(p, op);
    let mut d = Drive::at(p, op);
    if thermal {
        d.warm(p, z[1]);
    }
    if sag {
        d.v = z[2];
    }
    let mut t = match same {
        Some(t) => *t,
        None => trial(p, &d, z[0], Some((guess.0, None)), guess.1.map(|g| (g, None))),
    };
    // once, so that a reused trial carries it
    if p.stall_torque {
        t.tf0 = rest_torque_factor(p, &d, &t);
    }
    let mut s = finish(p, &d, op, &t, if t.stalled { Status::Stall } else { Status::Ok }, 1);
    let mut next = [t.w_next, z[1], z[2]];
    if thermal {
        s.temperature_rise_at_elapsed_k = z[1];
        next[1] = temperature_rise_for_drift(p, s.total_loss_w(), op.elapsed_s);
    }
    if sag {
        next[2] = sagged_voltage_v(p, op, &s);
    }
    (next, s, t)
}

/// Passes of the effects' fixed point before it falls back to regula falsi inside a sign
/// change of x − G(x). Normal points settle within ~15 passes and never reach it.
const BRACKET_AFTER: usize = 30;

/// Swings of the passes between states of different kinds (a clamped stator, a stalled
/// rotor, a running one) after which they switch to regula falsi before [`BRACKET_AFTER`]:
/// passes that swing so are crossing a jump of G (the stator clamps or the rotor stalls on
/// one side of it), around which the secant steps cycle without closing in (a calibrated
/// ring motor with a 1074 Ω sag at 263 N, 0.06 N·m, 200 V: 133.2 → 125.2 → 105.2 → 118.9
/// → 133.2 V, again and again). Four swings are two such cycles; where a fixed point lies
/// between the two states after all, regula falsi inside the sign change finds it too.
const JUMP_SWINGS: usize = 4;

/// Width of a sign change of x − G(x), relative to the scalar's scale, below which a
/// residual of [`JUMP_RESIDUAL`] at its latest end shows a jump of G: a continuous G would
/// need |G'| ≥ 10⁴ there, and a crossing that steep ends unsettled at the 1e-12 width the
/// passes otherwise narrow to (the residual left there, up to |G'|·1e-12, above the 1e-9
/// that settles), about seven passes later.
const JUMP_WIDTH: f64 = 1e-7;

/// Width of a sign change of x − G(x), relative to the scalar's scale, below which states
/// of different kinds at its two ends (clamped, stalled, running), each with a residual of
/// at least [`JUMP_RESIDUAL`], show a jump of G: a continuous G would fall there with a
/// slope below −19 while the branch changes.
const KIND_JUMP_WIDTH: f64 = 1e-4;

/// Residual |x − G(x)|, relative to the scalar's scale, that [`JUMP_WIDTH`] judges.
const JUMP_RESIDUAL: f64 = 1e-3;

/// Temperature rise driving `thermal_drift`: Chen et al. 2020 eq. 11 (one lumped capacity)
/// for the candidate form, and its two-node family; the truth forms rise in shapes no sum
/// of decaying exponentials with positive shares takes (docs/EFFECTS.md):
/// - first family: two capacities in series, the stator's bulk (time constant τ) warmed
///   through the layer where the losses are made (τ/4): ΔT = ss·(1 − (τ·e^(−t/τ) −
///   τ₂·e^(−t/τ₂))/(τ − τ₂)), which starts with zero slope (an S-shaped rise);
/// - second family: heat diffusing into a thick body from the heated surface with linear
///   loss there (Carslaw and Jaeger 1959, the semi-infinite solid with surface heat
///   transfer): ΔT = ss·(1 − e^x·erfc(√x)), x = t/τ, which starts as √t and approaches
///   its end as 1/√t.
pub(super) fn temperature_rise_for_drift(p: &Prepared, loss_w: f64, elapsed_s: f64) -> f64 {
    let ss = loss_w / p.alpha_s;
    let tau = p.heat_cap / p.alpha_s;
    if p.truth_b(Effect::ThermalDrift) {
        ss * (1.0 - erfcx((elapsed_s.max(0.0) / tau).sqrt()))
    } else if p.truth(Effect::ThermalDrift) {
        let tau2 = 0.25 * tau;
        ss * (1.0 - (tau * (-elapsed_s / tau).exp() - tau2 * (-elapsed_s / tau2).exp()) / (tau - tau2))
    } else if p.thermal_interface != 0.0 {
        two_node_rise(ss, tau, p.thermal_interface, elapsed_s)
    } else {
        ss * (1.0 - (-elapsed_s / tau).exp())
    }
}

/// The scaled complementary error function e^(z²)·erfc(z) for z ≥ 0, by the Chebyshev
/// fit of Press et al. (Numerical Recipes, 2nd ed., §6.2, `erfcc`; relative error below
/// 1.2e-7), written without the e^(−z²) factor so that it cannot underflow. 1 at z = 0,
/// falling as 1/(z·√π) for large z.
pub(super) fn erfcx(z: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98 + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    t * poly.exp()
}

/// `thermal_drift`'s two-node family: the steady rise `ss` [K] reached by a lumped capacity
/// with time constant `tau` [s] (Chen et al. 2020 eq. 11) for the share 1 − f, and by a fast
/// node at the friction interface, with a tenth of the time constant, for the share f:
/// ΔT(t) = ss·(1 − (1 − f)·e^(−t/τ) − f·e^(−10t/τ)). The losses are made in the contact and
/// the piezoceramic, so the layer next to them warms before the stator's bulk does; f = 0 is
/// the one-capacity law. Valid for f in [0, 1) and t ≥ 0.
pub(super) fn two_node_rise(ss: f64, tau: f64, f: f64, elapsed_s: f64) -> f64 {
    ss * (1.0 - (1.0 - f) * (-elapsed_s / tau).exp() - f * (-elapsed_s / (0.1 * tau)).exp())
}

//! The amplitude descent: from an upper bound of the largest fixed point of
//! W ↦ G(W) = Θ·V/|Z(W)| down onto it, with secant, Newton and regula-falsi steps, and
//! where the modal stiffness depends on W, capped steps and the window searches around
//! the stiffness crossing that keep it from stepping over the largest root.

use super::bracket::SignBracket;
use super::finish::{clamped_trial, finish};
use super::trial::{Drive, Trial};
use super::{OperatingPoint, Prepared, Solution, Status, Work};
use crate::interface::AngleCarry;
use crate::stator::{elastic_detuning, stiffness_crossing};
use std::f64::consts::PI;

/// Largest fall of the amplitude per step of a multi-branch descent before a root is
/// bracketed (see `solve_drive_below`).
const MULTI_BRANCH_STEP: f64 = 0.8;

/// Fall of the amplitude per fixed-point step of a multi-branch descent below 1e-3 of its
/// top before a root is bracketed (see `solve_drive_below`).
const DEEP_CLAMPED_STEP: f64 = 0.1;

/// The steady amplitude under drive `d`: the descent from the cold bound onto the largest
/// fixed point ([`solve_drive_below`]), its trials charged to `work`.
pub(super) fn solve_drive(
    p: &Prepared,
    d: &Drive,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    work: &Work,
) -> Solution {
    solve_drive_below(p, d, op, guess, None, work)
}

/// A sweep's warm start of the amplitude descent (`solve_in_sweep`): a proven upper bound
/// of the largest fixed point (the previous point's amplitude) and an amplitude predicted
/// below the bound.
#[derive(Clone, Copy, Debug)]
pub(super) struct WarmTop {
    /// A proven upper bound of the largest fixed point [m].
    pub(super) bound: f64,
    /// The amplitude extrapolated from the sweep's previous points [m], below the bound.
    pub(super) predicted: Option<f64>,
    /// The contact half-angle φ0 extrapolated to this point [rad], for the first trial.
    pub(super) contact_rad: Option<f64>,
    /// The stick half-angle θs extrapolated to this point [rad], for the first trial.
    pub(super) stick_rad: Option<f64>,
}

/// Relative tolerance of the amplitude solve on r(W) = W − G(W). The Coulomb interface's
/// map is smooth to rounding: 1e-13 (1e-12 left 1.7e-9 on the efficiency just below
/// stall, where the speed is a difference of nearly equal torques, against the Python
/// reference; 1e-13 costs 0.2 evaluations a point). The generalised interface integrates
/// numerically (and solves its stick point to 1e-13), so its amplitude map carries ~1e-12
/// of noise: converge to 1e-10 there.
pub(super) fn amplitude_rtol(p: &Prepared) -> f64 {
    if p.law.radial_ratio == 0.0 && p.compliance == 0.0 {
        1e-13
    } else {
        1e-10
    }
}

/// The trials of one amplitude descent under one drive, counted, each starting its inner
/// angle solves from the previous trial's.
///
/// The inner root finds (contact and stick angles) have unique roots: starting them from
/// the previous trial (the first from the neighbouring point's) only makes them cheaper.
/// The generalised interface's speed solve costs 2-6 numerical integrals per trial; late
/// in the descent the amplitude moves along a secant, and θs extrapolated linearly in W
/// starts it within a hair of its root (7 % fewer integrals). The Coulomb interface instead
/// carries each angle from the previous trial along its exact derivative in W, with its
/// sine and cosine: late in the descent that start is the root to rounding and the angle
/// solves need no `sin_cos` at all (a secant extrapolation of its angles without them
/// costs more than it saves: callgrind +7 % a point).
struct Trials<'a> {
    p: &'a Prepared,
    d: &'a Drive,
    /// The budget of the solve the descent belongs to, charged for every trial.
    work: &'a Work,
    /// Amplitude evaluations so far.
    evals: u32,
    /// Stick half-angle θs [rad] that starts the next trial's stick solve.
    ts_guess: Option<f64>,
    /// Contact half-angle φ0 [rad] that starts the next trial's contact solve (none after
    /// a trial in full contact).
    phi_guess: Option<f64>,
    /// True for the generalised interface (radial slip or shear compliance), whose stick
    /// angle is extrapolated through the last two trials.
    general: bool,
    /// (W [m], θs [rad]) of the last two trials, oldest first.
    history: [Option<(f64, f64)>; 2],
    /// The last trial's amplitude W [m] and its contact and stick angles with their
    /// derivatives in W (the Coulomb interface only).
    carried: Option<(f64, [Option<AngleCarry>; 2])>,
    /// True when the last trial stalled: the next one's speed solve then starts with the
    /// rotor at rest (`trial_after`).
    stalled: bool,
}

impl<'a> Trials<'a> {
    /// No trial yet: the first starts its angle solves at the warm top's extrapolated
    /// angles, else at the neighbouring point's (`guess`).
    fn new(p: &'a Prepared, d: &'a Drive, work: &'a Work, guess: Option<&Solution>, top: Option<&WarmTop>) -> Self {
        let ts_guess =
            top.and_then(|t| t.stick_rad).or(guess.map(|g| g.stick_half_angle_rad)).filter(|t| t.is_finite());
        let phi_guess =
            top.and_then(|t| t.contact_rad).or(guess.map(|g| g.contact_half_angle_rad)).filter(|t| t.is_finite());
        let general = p.law.radial_ratio != 0.0 || p.compliance != 0.0;
        Trials {
            p,
            d,
            work,
            evals: 0,
            ts_guess,
            phi_guess,
            general,
            history: [None, None],
            carried: None,
            stalled: false,
        }
    }

    /// The trial at amplitude `w` [m].
    fn eval(&mut self, w: f64) -> Trial {
        self.evals += 1;
        let guess = match self.history {
            [Some(a), Some(b)] if self.general && a.0 != b.0 => {
                let g = b.1 + (b.1 - a.1) * (w - b.0) / (b.0 - a.0);
                self.ts_guess.map(|f| if g.is_finite() && g > 0.0 && g < PI { g } else { f })
            }
            _ => self.ts_guess,
        };
        let carried = self.carried;
        let start = |i: usize, plain: Option<f64>| {
            carried.and_then(|(from, c)| c[i]?.start_at(from, w)).or(plain.map(|g| (g, None)))
        };
        let t = self.work.trial_after(self.p, self.d, w, start(1, guess), start(0, self.phi_guess), self.stalled);
        self.stalled = t.stalled;
        self.ts_guess = Some(t.ts);
        self.phi_guess = Some(t.contact.half_angle_rad).filter(|_| !t.contact.full);
        self.history = [self.history[1], Some((w, t.ts))];
        self.carried = Some((w, t.carry));
        t
    }
}

/// True when trial `t` is a root of r(W) = W − G(W) to the relative tolerance `rtol`.
fn converged_at(t: &Trial, rtol: f64) -> bool {
    (t.w - t.w_next).abs() <= rtol * t.w
}

/// True when r(W) = W − G(W) ≥ 0 at trial `t`, or r is no number at all.
fn not_below(t: &Trial) -> bool {
    !matches!(t.w.partial_cmp(&t.w_next), Some(std::cmp::Ordering::Less))
}

/// The top of a warm descent and the trial below the root that brackets it, if any.
///
/// The previous root was converged to rtol only, so r may come out a rounding below zero
/// at the bound; within rtol it is this point's root too (where the load does not move G
/// at all, in a stall, always). The predicted amplitude first: a root within the
/// tolerance there is the answer; with r ≥ 0 it is the top of the descent (a further root
/// between it and the bound would need two sign changes within one extrapolation error);
/// with r < 0 up to three Newton steps go up (secants where a trial has no slope; below
/// the bound), the first with r ≥ 0 is the top and the last below it the bracket's lower
/// end; failing that the bound is the top.
fn warm_top(trials: &mut Trials, top: &WarmTop, rtol: f64) -> (Trial, Option<Trial>) {
    let Some(w) = top.predicted.filter(|&w| w > 0.0 && w < top.bound) else {
        return (trials.eval(top.bound), None);
    };
    let t = trials.eval(w);
    // (a NaN residual is no bracket: it fails the warm filter of the caller and the
    // point descends from the cold bound)
    if not_below(&t) || converged_at(&t, rtol) {
        return (t, None);
    }
    // Up to three steps up from below inside the bound; the first with r ≥ 0 is the top.
    let mut b = t;
    let mut last: Option<Trial> = None;
    for _ in 0..3 {
        let rb = b.w - b.w_next;
        let x = match (b.newton(), last) {
            (Some(x), _) => x,
            (None, Some(l)) if l.w != b.w => b.w - rb * (b.w - l.w) / (rb - (l.w - l.w_next)),
            _ => f64::NAN,
        };
        if !(x > b.w && x < top.bound) {
            break;
        }
        let u = trials.eval(x);
        if not_below(&u) || converged_at(&u, rtol) {
            return (u, Some(b));
        }
        (last, b) = (Some(b), u);
    }
    let top = trials.eval(top.bound);
    (top, Some(b))
}

/// The top of the descent, a trial with r(W) ≥ 0: the `warm` one, else the cold bound
/// `w_cold()` [m] ([`cold_top`]), raised by half while r < 0 (at most 60 times).
///
/// Without preload stiffening or Hertz softening the modal stiffness does not depend on
/// W, and the friction damping c_t·ω is ≥ 0 (the wave gives power to friction and rotor
/// at a load torque ≥ 0), so |Z(W)| ≥ |k − mω² + iωc| at every W: a bound that also counts
/// the detuning, closer to the root off resonance. It holds too where the W-dependent
/// stiffness only moves the mode away from the drive: stiffening (≥ 0) below the
/// resonance, softening (≤ 0) above it. Softening could in principle exceed either bound;
/// the bracket is then grown.
fn descent_top(trials: &mut Trials, warm: Option<Trial>, w_cold: impl FnOnce() -> f64) -> Trial {
    let mut hi = match warm {
        Some(t) => t,
        None => trials.eval(w_cold()),
    };
    let mut grow = 0;
    while hi.w < hi.w_next && grow < 60 {
        hi = trials.eval(hi.w_next * 1.5);
        grow += 1;
    }
    hi
}

/// The amplitude [m] a cold descent starts from ([`descent_top`]): Θ·V/|k − mω² + iωc| where
/// the W-dependent stiffness cannot move the mode towards the drive, else `w_hi0` =
/// Θ·V/(ω·c).
fn cold_top(p: &Prepared, d: &Drive, detuning: f64, w_hi0: f64) -> f64 {
    if (p.stiffening == 0.0 || detuning >= 0.0) && (p.beta == 0.0 || detuning <= 0.0) {
        p.theta * d.v / detuning.hypot(d.omega * d.c)
    } else {
        w_hi0
    }
}

/// The crossing probe of a cold multi-branch descent started without the trial at the cold
/// top `w_cold` [m]: (a top to descend from, the trial at the stiffness crossing).
///
/// Friction damping is ≥ 0, so Im Z ≥ ω·c at every W, and with the elastic detuning
/// ([`elastic_detuning`], exact) G(W) ≤ Θ·V/hypot(Re Z(W), ω·c) needs no interface
/// integral. Where that bound puts r ≥ 0 at `w_cold` (the cold descent's top, which then
/// needs no growing), the crossing is the one [`probe_crossing`] finds from it, and its
/// trial is taken first. With r < 0 there, the top is the trial at the lowest amplitude
/// the bound rules out above the crossing ([`clear_from`] with Im Z = ω·c; r ≥ 0 there),
/// a few per cent above the largest root at `trum60a` as shipped, instead of the cold top
/// 60-100× above it: one trial fewer than descending from `w_cold`, whose trial only
/// serves the same bound. Otherwise no top: the descent goes on from the cold top as
/// usual, and what was found from `w_cold` ([`Known`]) spares [`probe_crossing`] the
/// search.
// (not inlined: inlined, it enlarges the descent of every stator for the multi-branch ones)
#[inline(never)]
fn cold_crossing(trials: &mut Trials, w_cold: f64) -> (Option<Trial>, Known) {
    let (p, d) = (trials.p, trials.d);
    let Some(ws) = stiffness_crossing(p, d, w_cold) else {
        return (None, Some((w_cold, None)));
    };
    let damping = d.omega * d.c;
    // (false for a NaN too)
    let ruled_out = w_cold * elastic_detuning(p, d, w_cold).hypot(damping) >= p.theta * d.v;
    if !ruled_out {
        return (None, None);
    }
    let t = trials.eval(ws);
    if t.w < t.w_next {
        let top = clear_from(p, d, ws, w_cold, damping).map(|w| trials.eval(w)).filter(|u| u.w >= u.w_next);
        return (top, Some((w_cold, Some(t))));
    }
    (None, Some((w_cold, Some(t))))
}

/// The stiffness crossing as [`cold_crossing`] found it: (the top it searched below [m],
/// the trial at the crossing, `None` where there is none), or `None` where it did not look.
type Known = Option<(f64, Option<Trial>)>;

/// The first amplitude below the top `hi` (before any step cap).
///
/// The amplitude always descends from an upper bound onto the largest fixed point — the
/// bound Θ·V/(ω·c), or a proven one (`solve_in_sweep`): a warm amplitude from a
/// neighbouring point can sit below the middle one of several fixed points and fall onto
/// another branch (tests/reliability_known_bugs.rs). The guess still warm-starts the inner
/// stick-angle solves.
fn first_step(warm: Option<Trial>, below: Option<Trial>, hi: &Trial) -> f64 {
    match (warm, below) {
        // a trial below the root and the top above it: Newton from the one nearer the
        // root where its exact slope is known and the step stays between them, else
        // their secant
        (Some(h), Some(l)) => {
            let (rl, rh) = (l.w - l.w_next, h.w - h.w_next);
            let near = if rh.abs() < rl.abs() { h } else { l };
            let x = near.newton().filter(|&x| x > l.w && x < h.w).unwrap_or(l.w - rl * (h.w - l.w) / (rh - rl));
            if x > l.w && x < h.w {
                x
            } else {
                0.5 * (l.w + h.w)
            }
        }
        // a warm top alone: Newton on its slope where that stays above zero (a warm
        // top is within a torque step of the root), else the fixed-point step
        (Some(h), None) => h.newton().filter(|&x| x > 0.0 && x <= h.w).unwrap_or(h.w_next),
        // a cold top: Newton on W·|Z(W)| − Θ·V where the slope is exact ([`balance_newton`]),
        // else the fixed-point step
        _ => balance_newton(hi).filter(|&x| x > 0.0 && x < hi.w).unwrap_or(hi.w_next),
    }
}

/// The Newton step [m] of h(W) = W·|Z(W)| − Θ·V, whose roots are those of
/// r(W) = W − G(W), from trial `t` where it has an exact slope of r (the baseline
/// Coulomb interface) and h rises there.
///
/// h' = |Z|·(1 + (W/G)·(r' − 1)) from the trial's slope r'. W·Re Z is linear in W and
/// W·Im Z = ω·c·W + D(W), where D, the friction force the wave works against, falls
/// slowly with W (a Coulomb force, set by the preload and the load torque): h is the
/// length of a nearly affine vector, nearly linear and convex. Newton on a convex h from
/// above never passes the root, as the fixed-point step W ↦ G(W) never does, and it
/// closes in quadratically where the fixed-point step converges linearly and Newton on r,
/// with its 1/|Z| curvature, more slowly (4.4 trials a cold point of the point_cost grid
/// against 6.7 from the fixed-point step and secants). A step that does pass the root
/// lands where r < 0 and brackets it, as a secant's would.
/// `solve::tests::effect_free_stators_report_the_largest_fixed_point` checks the largest
/// fixed point at random drives with several fixed points and clamped ones.
fn balance_newton(t: &Trial) -> Option<f64> {
    let r = t.w - t.w_next;
    let denominator = 1.0 + t.w / t.w_next * (t.slope - 1.0);
    (denominator > 0.0).then(|| t.w - r / denominator)
}

/// The step cap of a multi-branch descent (preload stiffening, Hertz softening).
///
/// Where the modal stiffness depends on W, G(W) need not rise with W, and one fixed-point
/// or secant step from far above can jump over the largest fixed point onto a lower
/// branch (generic60 with stiffening 0.504 at 389 N, 190 V, 40.88 kHz, 0.42 N·m: the step
/// from the bound, 74 µm, lands at 3.7 µm, by the unstable middle root, though the running
/// state at 10.1 µm is stable). Until a root is bracketed such a descent falls by at most
/// a factor [`MULTI_BRANCH_STEP`] per step, down to 1e-3 of the top (below that it is a
/// clamped stator's descent to zero, the cap released so that it ends in the budget).
///
/// Stiffening alone on a mode already stiffer than the drive only moves it further away:
/// G rises with W below its one fixed point, no branch to step over, no cap (24 → 14
/// evaluations a point at trum60a, stiffening 1, no point of the census of
/// `multi_branch_stators_report_the_largest_fixed_point` moves).
/// Not so for softening on a mode below the drive (a long step near clamping lands on a
/// lower branch).
#[derive(Clone, Copy)]
struct StepCap {
    /// Whether the descent's steps are capped at all.
    on: bool,
    /// The amplitude W [m] the descent started from.
    w_top: f64,
}

impl StepCap {
    fn new(p: &Prepared, detuning: f64, w_top: f64) -> Self {
        let multi_branch = p.stiffening != 0.0 || p.beta != 0.0;
        StepCap { on: multi_branch && !(p.beta == 0.0 && detuning >= 0.0), w_top }
    }

    /// Step `x` from `from` [m], capped.
    fn apply(self, x: f64, from: f64) -> f64 {
        if self.on && from >= 1e-3 * self.w_top {
            x.max(MULTI_BRANCH_STEP * from)
        } else {
            x
        }
    }

    /// True below the cap's floor, where a capped descent is a clamped stator's to zero.
    fn deep(self, w: f64) -> bool {
        self.on && w < 1e-3 * self.w_top
    }
}

/// The probe of the stiffness crossing below the top `hi` of a multi-branch descent:
/// (the lower end of a bracket, the crossing's trial with r ≥ 0), at most one of them.
/// The crossing is searched below `w_top` [m] (the cold top where `hi` is a top the bound
/// found, [`cold_crossing`]); `known`: what [`cold_crossing`] found, used where it
/// searched below the same top.
///
/// G peaks in a spike where the W-dependent stiffness cancels the detuning k − mω²,
/// narrower than any step cap (10 % wide in W at generic60, β = 3e17). Where the spike
/// reaches r < 0 a root lies between it and the top, but not necessarily the largest: the
/// falling friction damping can give r more than one sign change up there (trum60a with
/// candidate-form softening 1e18: 2 of 300 000 random points). `highest_window` brackets
/// the highest window, to the width of a capped descent step (the rigour of the descent
/// itself; 0.5-3.8 more evaluations a point in the census, 5-12 % of a diagnosis), and
/// lowers `hi` to the probe above it. Where r ≥ 0 at the spike a window of r < 0 can still
/// open next to it, because friction damping falls with W and moves G's peak off the
/// crossing:
/// - below it, near a fold (trum60-qut truth form, β = 1.089e18 at 211.8 N, 252.6 V,
///   39479 Hz: a stable branch at 0.9997 of the spike, a window 0.3 % wide);
/// - above it, |Z| still falling past the crossing (trum60a, stiffening and softening in
///   truth form, at 567.7 N, 0.316 N·m, 182.8 V, 44 258 Hz: a window 26 % wide from
///   1.72 µm, the crossing at 1.69 µm; searching below first ends on the lower branch).
///
/// So the descent from the top goes on down to the crossing, and only there are the
/// windows searched, the highest first ([`windows_at_crossing`]).
fn probe_crossing(trials: &mut Trials, hi: &mut Trial, w_top: f64, known: &Known) -> (Option<Trial>, Option<Trial>) {
    let (p, d) = (trials.p, trials.d);
    // (found from the same top: no crossing, or its trial, whose amplitude is the crossing)
    let (ws, known) = match known.filter(|k| k.0 == w_top) {
        Some((_, Some(t))) => (t.w, Some(t)),
        Some((_, None)) => return (None, None),
        None => match stiffness_crossing(p, d, w_top) {
            Some(ws) => (ws, None),
            None => return (None, None),
        },
    };
    let t = match known {
        Some(t) => t,
        None => trials.eval(ws),
    };
    if t.w < t.w_next {
        let found =
            highest_window(p, d, ws, vec![*hi, t], 40, 1.0 - MULTI_BRANCH_STEP, probe_split(), &mut |w| trials.eval(w));
        let (tl, top) = found.unwrap_or((t, *hi));
        *hi = top;
        (Some(tl), None)
    } else {
        (None, Some(t))
    }
}

/// Whether a multi-branch descent uses the bound on G that needs no interface integral
/// ([`cold_crossing`], `Split::Bounded`, secant steps inside the bracket): always, but where
/// a test asks for the descent without it, the reference it is compared with.
fn bounded() -> bool {
    #[cfg(test)]
    if REFERENCE_DESCENT.with(std::cell::Cell::get) {
        return false;
    }
    true
}

/// The split of the crossing probe's window search.
fn probe_split() -> Split {
    if bounded() {
        Split::Bounded
    } else {
        Split::Midpoint
    }
}

#[cfg(test)]
thread_local! {
    /// Set by a test: multi-branch descents run without the bound ([`bounded`]): from the
    /// cold top's trial, midpoint splits, regula falsi inside the bracket.
    pub(super) static REFERENCE_DESCENT: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// The windows of r < 0 at the stiffness crossing `spike`, which the descent is about to
/// pass without a bracket: first a window above the crossing that its steps went over
/// (`above`: the descent's trials above it, r ≥ 0 at each), then the fold window just
/// below it and any window between the one it finds and the crossing. The highest window
/// found brackets the largest root: (its trial with r < 0, the probe above it).
fn windows_at_crossing(trials: &mut Trials, spike: Trial, mut above: Vec<Trial>) -> Option<(Trial, Trial)> {
    let (p, d) = (trials.p, trials.d);
    above.push(spike);
    highest_window(p, d, spike.w, above, 40, 0.0, Split::Midpoint, &mut |w| trials.eval(w)).or_else(|| {
        // the fold window's trials, to rule out a window above the one it found
        let mut seen = vec![spike];
        let tm = fold_window(p, d, &spike, &mut |w| {
            let t = trials.eval(w);
            seen.push(t);
            t
        })?;
        seen.retain(|t| t.w >= tm.w);
        highest_window(p, d, spike.w, seen, 40, 0.0, Split::Midpoint, &mut |w| trials.eval(w))
    })
}

/// The next amplitude below `cur` [m] while no root is bracketed (`prev` the trial before
/// it, `stretch` the fixed-point step multiplier, doubled per rejected secant).
///
/// Newton on W·|Z(W)| − Θ·V where the trial's slope is exact ([`balance_newton`]), else
/// the secant from the previous iterate, if it moves down; else a fixed-point step,
/// lengthened while the secant keeps pointing up: there the residual grows as W falls and
/// plain steps of r ≈ 10⁻³·W would take the whole budget (points near stall and clamping
/// of the dense preset maps, tests/solver_convergence.rs). The step is at most a tenth of
/// W so that a root is not stepped over lightly; a step into r < 0 brackets one. Not so
/// below the cap's floor ([`StepCap::deep`]), a clamped stator's descent to zero: there
/// G ≈ κ·W with κ just below 1 (full contact, the friction set by the preload, not by W),
/// so the secant points at W ≤ 0 and tenths would take about 130 trials a clamped row
/// down to the clamping threshold (docs/PERFORMANCE.md). A decade a step there (or the
/// fixed-point step when it goes further): no bolder than the secant steps the release
/// allows.
///
/// A secant across a change of r within rounding (1e-14·W; r itself is still above the
/// 1e-13·W tolerance) is noise: just past a fold, where r has a minimum a hair above zero
/// (2.6e-18 m at W = 2.9e-6 m), noisy secants accepted at random lengths would keep
/// resetting the stretch and crawl (trum60a, sag 150 Ω and nominal thermal drift, a rise
/// of 40 K, 131.06 V, 400.7 N, 0.789 N·m, 39.9 kHz).
fn unbracketed_step(cur: &Trial, prev: Option<Trial>, stretch: &mut f64, cap: StepCap) -> f64 {
    let r = cur.w - cur.w_next;
    let deep = cap.deep(cur.w);
    let secant = prev.filter(|pv| (r - (pv.w - pv.w_next)).abs() > 1e-14 * cur.w).map(|pv| {
        let rp = pv.w - pv.w_next;
        cur.w - r * (cur.w - pv.w) / (r - rp)
    });
    let newton = balance_newton(cur).filter(|&x| x > 0.0 && x < cur.w);
    let x = match newton.or(secant) {
        Some(x) if x.is_finite() && x > 0.0 && x < cur.w => {
            *stretch = 1.0;
            x
        }
        _ if deep => cur.w_next.min(DEEP_CLAMPED_STEP * cur.w),
        _ => {
            let x = cur.w - (r * *stretch).min(0.1 * cur.w).max(r);
            *stretch *= 2.0;
            x
        }
    };
    cap.apply(x, cur.w)
}

/// [`solve_drive`], the amplitude descending from a warm `top` instead of the bound
/// Θ·V/(ω·c) when `top.bound` is a proven upper bound of the largest fixed point and
/// r(W) ≥ 0 holds there numerically (else from the bound as usual); see
/// [`super::solve_in_sweep`]. The prediction, when given, is tried first (the top where
/// r ≥ 0 there; below the root it is stepped up, never past the bound, and brackets the
/// root with the first step above). From a warm top the first step is a Newton step on the
/// trial's exact slope of r (every warm trial has one: the baseline Coulomb interface)
/// instead of a fixed-point one; a cold descent with such slopes takes Newton steps on
/// W·|Z(W)| − Θ·V from its top ([`balance_newton`]). Inside a bracket the descent also
/// takes Newton steps on exact slopes where they stay inside it (regula falsi otherwise).
///
/// The steps: the top ([`warm_top`], [`descent_top`]) and the first step below it
/// ([`first_step`]); for a multi-branch stator the crossing probe ([`probe_crossing`]);
/// then steps down ([`unbracketed_step`], capped by [`StepCap`]) until a root is
/// bracketed, the windows at the crossing searched before the descent passes it
/// ([`windows_at_crossing`]), and Newton or regula-falsi steps inside the bracket.
///
/// Every trial is charged to `work`; once it is spent the descent ends unconverged.
pub(super) fn solve_drive_below(
    p: &Prepared,
    d: &Drive,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    top: Option<WarmTop>,
    work: &Work,
) -> Solution {
    let rtol = amplitude_rtol(p);
    // Upper bound: |Z| ≥ ω·c, so W' ≤ Θ·V/(ω·c).
    let w_hi0 = p.theta * d.v / (d.omega * d.c);
    let floor = d.clamp_floor(p.theta);
    let mut trials = Trials::new(p, d, work, guess, top.as_ref());
    let (warm_trial, below) = match top {
        Some(wt) => {
            let (t, below) = warm_top(&mut trials, &wt, rtol);
            (Some(t), below)
        }
        None => (None, None),
    };
    if let Some(t) = warm_trial.filter(|t| converged_at(t, rtol)) {
        let status = if t.stalled { Status::Stall } else { Status::Ok };
        return finish(p, d, op, &t, status, trials.evals);
    }
    let warm = warm_trial.filter(|t| t.w >= t.w_next);
    let below = below.filter(|_| warm.is_some());
    let detuning = d.ks - p.m * d.omega * d.omega;
    let multi_branch = p.stiffening != 0.0 || p.beta != 0.0;
    // (a top found by the bound stands for the cold top `w_top`, where r ≥ 0 by the same
    // bound)
    let (mut hi, w_top, crossing) = match multi_branch && warm.is_none() && bounded() {
        true => {
            let w_cold = cold_top(p, d, detuning, w_hi0);
            match cold_crossing(&mut trials, w_cold) {
                (Some(top), known) => (top, w_cold, known),
                (None, known) => {
                    let hi = descent_top(&mut trials, warm, || w_cold);
                    (hi, hi.w, known)
                }
            }
        }
        false => {
            let hi = descent_top(&mut trials, warm, || cold_top(p, d, detuning, w_hi0));
            (hi, hi.w, None)
        }
    };
    let mut lo: Option<Trial> = below;
    let start = first_step(warm, below, &hi);
    let cap = StepCap::new(p, detuning, w_top);
    let (cur, mut spike) =
        if multi_branch { probe_crossing(&mut trials, &mut hi, w_top, &crossing) } else { (None, None) };
    // secant steps inside the bracket where the descent met a stiffness crossing
    let secants = (cur.is_some() || spike.is_some()) && bounded();
    // the descent's trials above the crossing (r ≥ 0 at each); no allocation without one
    let mut above = Vec::new();
    if spike.is_some() {
        above.push(hi);
    }
    let mut cur = match (cur, spike) {
        (Some(t), _) => t,
        // A first step that would pass the crossing starts at it instead (its trial is
        // known, r ≥ 0), so that the loop's next step runs the window searches: landing
        // below the crossing with r < 0 would bracket the first root regula falsi finds
        // between there and the top, not necessarily the largest. Not a crossing trial
        // without a finite residual: as `cur` it would become `lo`.
        (None, Some(sp)) if lo.is_none() && sp.w_next.is_finite() && cap.apply(start, hi.w) <= sp.w => sp,
        (None, _) => trials.eval(cap.apply(start, hi.w)),
    };
    // From a warm top (within a hair of the root) the first secant already uses it; from
    // the far bound it would be a poor partner (21 statuses change in dense maps).
    let mut prev: Option<Trial> = warm.map(|_| hi);
    let mut converged = false;
    // Illinois bookkeeping of the bracket's residuals. When one end is kept twice in a row
    // its stored residual is halved again each time (cumulatively: halving only once
    // stalls into linear convergence at ratio ~0.7, tests/invariants.rs).
    let mut bracket =
        SignBracket { neg: lo.map(|l| (l.w, l.w - l.w_next)), pos: Some((hi.w, hi.w - hi.w_next)), last_side: 0 };
    let mut stretch = 1.0; // fixed-point step multiplier, doubled per rejected secant
    for _ in 0..if multi_branch { 200 } else { 80 } {
        if work.exhausted() {
            break;
        }
        let r = cur.w - cur.w_next;
        if r.abs() <= rtol * cur.w.max(1e-300) {
            converged = true;
            break;
        }
        bracket.record(cur.w, r, true);
        if r > 0.0 {
            hi = cur;
            if spike.is_some_and(|sp| cur.w > sp.w) {
                above.push(cur);
            }
        } else {
            lo = Some(cur);
        }
        if cur.w < floor && r > 0.0 && lo.is_none() {
            // Descending towards zero with W' < W: the only fixed point is W = 0 (clamped).
            break;
        }
        let next = match lo {
            // Newton with the trial's exact slope where its step stays inside [lo, hi],
            // else regula falsi (Illinois) there.
            Some(l) => match cur
                .newton()
                .or_else(|| secants.then(|| secant(&cur, prev)).flatten())
                .filter(|&x| x > l.w && x < hi.w)
            {
                Some(x) => x,
                None => bracket.regula_falsi().unwrap_or(0.5 * (l.w + hi.w)),
            },
            None => unbracketed_step(&cur, prev, &mut stretch, cap),
        };
        if let Some(sp) = spike.filter(|sp| lo.is_none() && next <= sp.w) {
            spike = None;
            if let Some((t, top)) = windows_at_crossing(&mut trials, sp, std::mem::take(&mut above)) {
                bracket.record(top.w, top.w - top.w_next, true);
                (hi, prev, cur) = (top, Some(top), t);
                continue;
            }
        }
        prev = Some(cur);
        cur = trials.eval(next);
    }
    let evals = trials.evals;
    if !converged {
        if cur.w < floor && !work.exhausted() {
            return finish(p, d, op, &clamped_trial(p, d), Status::Clamped, evals);
        }
        let mut s = finish(p, d, op, &cur, Status::NoConvergence, evals);
        s.status = Status::NoConvergence;
        return s;
    }
    // Use the trial consistent with the converged amplitude for every output.
    let status = if cur.stalled { Status::Stall } else { Status::Ok };
    finish(p, d, op, &cur, status, evals)
}

/// The root of the secant of r = W − G(W) through the trials `cur` and `prev`, where `cur`
/// has the smaller |r| (at most half of `prev`'s: the iterates close in on a root).
fn secant(cur: &Trial, prev: Option<Trial>) -> Option<f64> {
    let pv = prev?;
    let (rc, rp) = (cur.w - cur.w_next, pv.w - pv.w_next);
    (rc.abs() <= 0.5 * rp.abs() && rc != rp).then(|| cur.w - rc * (cur.w - pv.w) / (rc - rp)).filter(|x| x.is_finite())
}

/// A trial with r = W − G(W) < 0 just below the stiffness crossing `spike` (where r ≥ 0),
/// or `None`. Below the crossing Re Z grows like |s|·(W_s − W) (s = dRe Z/dW), so G can
/// only exceed its value at the crossing within a few widths Y/|s| of the peak (Y = Im Z):
/// r(W_s − δ) ≥ r(W_s) − δ while Y holds, and there is nothing to find when r(W_s) is
/// above 2·Y/|s|. Otherwise golden-section search for the least r on [W_s − 2·Y/|s|, W_s]
/// (r falls, then rises to the crossing), stopped at the first r < 0; at most 40 trials,
/// to a relative width of 1e-7 (a narrower window is beyond the amplitude tolerance of
/// any scan). The same bound ends the search early: every W of the bracket [a, b] lies
/// below a probed point z ≤ b (or b itself), so r(W) ≥ r(z) − (b − a); once the least
/// probed r, the bracket's right end included, exceeds b − a, no r < 0 is left to find.
fn fold_window(p: &Prepared, d: &Drive, spike: &Trial, eval: &mut dyn FnMut(f64) -> Trial) -> Option<Trial> {
    let ws = spike.w;
    let h = 1e-6 * ws;
    let slope = (elastic_detuning(p, d, ws + h) - elastic_detuning(p, d, ws - h)) / (2.0 * h);
    let width = spike.z.1 / slope.abs();
    let r0 = spike.w - spike.w_next;
    if !(width.is_finite() && width > 0.0) || r0 > 2.0 * width {
        return None;
    }
    const INV_PHI: f64 = 0.618_033_988_749_894_9;
    let (mut a, mut b) = ((ws - 2.0 * width).max(1e-3 * ws), ws);
    let mut probe = |w: f64| {
        let t = eval(w);
        let r = t.w - t.w_next;
        (t, r)
    };
    let (mut x1, mut x2) = (b - INV_PHI * (b - a), a + INV_PHI * (b - a));
    let (t1, mut r1) = probe(x1);
    if r1 < 0.0 {
        return Some(t1);
    }
    let (t2, mut r2) = probe(x2);
    if r2 < 0.0 {
        return Some(t2);
    }
    // r at the bracket's right end (the crossing itself at first)
    let mut rb = r0;
    for _ in 0..38 {
        if b - a < 1e-7 * ws || r1.min(r2).min(rb) > b - a {
            break;
        }
        // keep the side of the smaller residual
        let (t, r) = if r1 < r2 {
            (b, x2, r2, rb) = (x2, x1, r1, r2);
            x1 = b - INV_PHI * (b - a);
            let (t, r) = probe(x1);
            r1 = r;
            (t, r)
        } else {
            (a, x1, r1) = (x1, x2, r2);
            x2 = a + INV_PHI * (b - a);
            let (t, r) = probe(x2);
            r2 = r;
            (t, r)
        };
        if r < 0.0 {
            return Some(t);
        }
    }
    None
}

/// The highest window of r = W − G(W) < 0 over the span of `probes` (trials at either
/// side of the stiffness crossing `ws`, which is one of them): its highest trial with
/// r < 0 and the probe above it, or `None` when the span holds none.
///
/// Friction damping falls with W, and so does Re Z (both W-dependent stiffnesses fall), so
/// between two probes z1 < z2 a bound on G rules a window out:
/// - below the crossing (Re Z ≥ 0) |Z(W)| ≥ |Z(z2)|, G(W) ≤ G(z2): none where z1 ≥ G(z2);
/// - above it (Re Z ≤ 0) |Z(W)| ≥ hypot(Re Z(z1), Im Z(z2)): none where z1 ≥ Θ·V over that.
///
/// The highest interval not ruled out is split (`split`: halved, or `Split::Bounded`),
/// top down, until every interval above a
/// probe with r < 0 is ruled out or narrower than 1e-7 relative (as `fold_window`), or
/// `budget` new probes are spent (then the highest r < 0 found so far). The bound never
/// rules out the interval just above a probe with r < 0 (there G(z2) > z1), so a search
/// that finds a window halves that interval to 1e-7 or to the budget: the budget exit is
/// the usual one then. An interval with r < 0 at its lower end that is narrower than
/// `resolved` (relative) is taken as the answer at once: 1 − MULTI_BRANCH_STEP, the step
/// the capped descent trusts, from a crossing with r < 0 (bounded splits there: at
/// `trum60a` as shipped the top is 6-8 % above the root, and the regula falsi root between
/// it and the crossing, 8-15 % below the root, closes such an interval at once); 0 after
/// the descent (halved). (Returning
/// at any width would miss a higher window inside that interval: generic60, softening
/// 3e17, 409 N, 1.47 N·m.) A search that finds none costs nothing
/// where the descent kept clear of the crossing.
///
/// Both falls held without exception for the Coulomb interface on fine scans (4000
/// amplitudes from 1e-3 of the crossing to the top, 1740 random points of the
/// multi-branch test configurations; 10 000 points × 6 000 amplitudes, torque up to
/// 5 N·m). Under `tangential_compliance` Im Z can jump up where the speed ratio drops
/// (generic60, stiffening 3.3 and compliance 1 in truth form: 7× over 0.2 % of W), so the
/// bound above the crossing is not proven there; on dense grids of 18 configurations no
/// interval it rules out holds r < 0.
#[allow(clippy::too_many_arguments)]
fn highest_window(
    p: &Prepared,
    d: &Drive,
    ws: f64,
    mut probes: Vec<Trial>,
    budget: usize,
    resolved: f64,
    split: Split,
    eval: &mut dyn FnMut(f64) -> Trial,
) -> Option<(Trial, Trial)> {
    let theta_v = p.theta * d.v;
    let below = |t: &Trial| t.w < t.w_next;
    let clear = |z1: &Trial, z2: &Trial| {
        z2.w - z1.w < 1e-7 * z2.w
            || if z2.w <= ws { z1.w >= z2.w_next } else { z1.w - theta_v / z1.z.0.hypot(z2.z.1) >= 0.0 }
    };
    probes.sort_by(|a, b| a.w.total_cmp(&b.w));
    let mut spent = 0;
    // `Split::Bounded`: whether the latest new probe was a secant step, and whether secant
    // steps are still taken (until one lands above the root where it rules nothing out)
    let (mut secant_step, mut secants) = (false, true);
    'refine: loop {
        // top down: a probe with r < 0 is the answer once every interval above it is clear
        for j in (0..probes.len()).rev() {
            if below(&probes[j]) {
                return probes.get(j + 1).map(|&above| (probes[j], above));
            }
            if j == 0 || clear(&probes[j - 1], &probes[j]) {
                continue;
            }
            if below(&probes[j - 1]) && probes[j].w - probes[j - 1].w <= resolved * probes[j].w {
                return Some((probes[j - 1], probes[j]));
            }
            if spent == budget {
                // out of budget: the highest r < 0 found, if any
                let k = (0..j).rev().find(|&k| below(&probes[k]))?;
                return Some((probes[k], probes[k + 1]));
            }
            spent += 1;
            let mid = 0.5 * (probes[j - 1].w + probes[j].w);
            let (x, secant) = match split {
                Split::Bounded if above_crossing(ws, &probes[j - 1]) => {
                    bounded_split(p, d, &probes, j, secants && !secant_step, mid)
                }
                _ => (mid, false),
            };
            let t = eval(x);
            if secant && !below(&t) && !clear(&t, &probes[j]) {
                secants = false;
            }
            secant_step = secant;
            probes.insert(j, t);
            continue 'refine;
        }
        return None;
    }
}

/// How [`highest_window`] splits an interval it cannot rule out.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Split {
    /// At its midpoint.
    Midpoint,
    /// Above the crossing, where the bound on G is known in closed form but for Im Z:
    /// alternately at the lowest amplitude the bound rules out from the interval's upper
    /// probe ([`clear_from`]) and at a secant root of r (`bounded_split`), never above the
    /// midpoint.
    Bounded,
}

/// True when the probe `z` lies at or above the stiffness crossing `ws`, where Re Z ≤ 0.
fn above_crossing(ws: f64, z: &Trial) -> bool {
    z.w >= ws
}

/// The next probe inside the interval (`probes[j − 1]`, `probes[j]`) that
/// [`highest_window`] cannot rule out, every interval above `probes[j]` ruled out
/// (r ≥ 0 at `probes[j]`), for the split `Split::Bounded`: (the amplitude [m], whether it
/// is a secant step).
///
/// A secant step, where `secant` allows it: the root of the secant of r through
/// `probes[j]` and the probe above it (both r ≥ 0, above the root), or without one the
/// probe below where r < 0 there (regula falsi), where it lies inside the interval. It
/// lands below the root (r < 0: the lower end of a narrow bracket) or above it where the
/// bound rules out the rest of the interval (a lower top).
/// Otherwise a bound step: the lowest amplitude from which the interval up to
/// `probes[j]` is ruled out ([`clear_from`]), so that the probe there rules out all of the
/// interval above it (r ≥ 0 there by the same bound); its rate is that of Im Z's fall
/// between the probes, a seventh of the distance to the root a step at `trum60a` as
/// shipped. Never above the midpoint `mid`: where the bound is weak (r a hair above zero
/// over a long stretch) the halving of the midpoint rule is kept.
fn bounded_split(p: &Prepared, d: &Drive, probes: &[Trial], j: usize, secant: bool, mid: f64) -> (f64, bool) {
    let (z1, z2) = (&probes[j - 1], &probes[j]);
    let inside = |x: f64| (x > z1.w && x < z2.w).then_some(x);
    if secant {
        // (the probe above, else the one below where r < 0 there: regula falsi)
        if let Some(z3) = probes.get(j + 1).or(Some(z1).filter(|z| z.w < z.w_next)) {
            let (r2, r3) = (z2.w - z2.w_next, z3.w - z3.w_next);
            if r3 != r2 {
                if let Some(x) = inside(z2.w - r2 * (z3.w - z2.w) / (r3 - r2)) {
                    return (x, true);
                }
            }
        }
    }
    (clear_from(p, d, z1.w, z2.w, z2.z.1).and_then(inside).map_or(mid, |x| x.min(mid)), false)
}

/// The lowest amplitude W in [`lo`, `hi`] [m] from which no root of r = W − G(W) lies up
/// to `hi` by the bound of [`highest_window`] above the crossing, `im_z` [N/m] a lower
/// bound of Im Z on [W, `hi`] (Im Z at a probe `hi`: friction damping falls with W):
/// W·hypot(Re Z(W), `im_z`) ≥ Θ·V. Re Z falls with W above the crossing, so the left side
/// rises with W and the interval above W is ruled out as a whole. Re Z is the elastic
/// detuning ([`elastic_detuning`], a contact solve without the interface integrals).
/// Illinois regula falsi to 1e-4 relative, returning the end where the bound holds;
/// `None` where it holds at `lo` already or nowhere.
fn clear_from(p: &Prepared, d: &Drive, lo: f64, hi: f64, im_z: f64) -> Option<f64> {
    let theta_v = p.theta * d.v;
    let f = |w: f64| w * elastic_detuning(p, d, w).hypot(im_z) - theta_v;
    let (f_lo, f_hi) = (f(lo), f(hi));
    if !(f_lo < 0.0 && f_hi >= 0.0) {
        return None;
    }
    let mut b = SignBracket { neg: Some((lo, f_lo)), pos: Some((hi, f_hi.max(f64::MIN_POSITIVE))), last_side: 0 };
    for _ in 0..60 {
        let (a, c) = (b.neg?.0, b.pos?.0);
        if c - a <= 1e-4 * c {
            break;
        }
        let x = b.regula_falsi()?;
        let fx = f(x);
        if fx.is_nan() {
            return None;
        }
        if fx >= 0.0 {
            b.record(x, fx.max(f64::MIN_POSITIVE), true);
        } else {
            b.record(x, fx, true);
        }
    }
    Some(b.pos?.0)
}

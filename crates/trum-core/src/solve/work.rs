//! The work bound of one steady-state solve: every amplitude trial of every route the
//! solve nests (the eccentric revolution's samples, the thermal and voltage-sag fixed
//! points, the sag's amplitude scan, the descents and their window searches) is charged to
//! one budget, and a solve that spends it ends as [`Status::NoConvergence`] with
//! [`Solution::work_bound_reached`] set.
//!
//! The unit is one evaluation of an interface integrand at a quadrature node, the step
//! whose count the cost of a trial follows: 35-95 ns each on the project's reference
//! machine, whichever interface law, rule or panel grading a trial takes. A trial costs
//! [`TRIAL_WORK`] units for its closed-form part (contact zone, stick angle, modal
//! impedance) plus the nodes its numerical interface integrals sum (none for the Coulomb
//! interface, whose factors are closed forms).

use super::trial::{trial_after, Drive, Trial};
use super::{Prepared, Solution, Status};
use crate::contact::{AngleStart, Contact};
use std::cell::Cell;

/// The default work bound of one solve ([`Prepared::with_work_bound`]) [units of
/// integrand evaluations, module docs]: 10⁹, about 35-95 s of one core of the reference
/// machine. Four times the most any converging point of a census of 9216 points needed
/// (every preset; no effect, each effect alone and all seven together, candidate and truth
/// forms; 50-500 N, 0-1.5 N·m, 100-300 V, 40-45 kHz, 120 s): 2.5·10⁸ units, 10.8 s, at
/// generic60 with all seven effects in truth form at 150 N, 0.8 N·m, 100 V, 40 kHz; 31
/// times the most of any converging point in the test suite (3.2·10⁷ units). A bound near
/// the census's most would turn converging points of valid motors into `no_convergence`
/// (docs/RELIABILITY.md, "The work bound of a solve").
pub const WORK_BOUND: u64 = 1_000_000_000;

/// Work units of a trial besides its integrand evaluations: a Coulomb trial costs about
/// as much as ten evaluations (0.3 µs).
pub(crate) const TRIAL_WORK: u64 = 10;

/// The budget of one solve, shared by every route it nests. Not `Sync`: each solve makes
/// its own, on the thread that runs it (a rayon sweep solves its points on many threads,
/// each with its own budget).
#[derive(Debug)]
pub(crate) struct Work {
    spent: Cell<u64>,
    limit: u64,
}

impl Work {
    /// A budget of `limit` units, none spent.
    pub(crate) fn new(limit: u64) -> Work {
        Work { spent: Cell::new(0), limit }
    }

    /// The budget of a solve of `p` ([`Prepared::with_work_bound`]).
    pub(crate) fn of(p: &Prepared) -> Work {
        Work::new(p.work_bound)
    }

    /// Units spent so far.
    pub(crate) fn spent(&self) -> u64 {
        self.spent.get()
    }

    /// True once the budget is spent: every later trial is [`spent_trial`], and the solve
    /// ends as `no_convergence` ([`Work::verdict`]).
    pub(crate) fn exhausted(&self) -> bool {
        self.spent.get() >= self.limit
    }

    /// [`trial_after`] charged to this budget; once it is spent, a trial without numbers
    /// that costs nothing ([`spent_trial`]), so that every route above ends at its next
    /// check of a residual or status.
    pub(crate) fn trial_after(
        &self,
        p: &Prepared,
        d: &Drive,
        w: f64,
        ts_guess: Option<AngleStart>,
        phi_guess: Option<AngleStart>,
        after_stall: bool,
    ) -> Trial {
        if self.exhausted() {
            return spent_trial(w);
        }
        let before = crate::interface::integrand_evaluations();
        let t = trial_after(p, d, w, ts_guess, phi_guess, after_stall);
        let nodes = crate::interface::integrand_evaluations().wrapping_sub(before);
        self.spent.set(self.spent.get().saturating_add(TRIAL_WORK).saturating_add(nodes));
        t
    }

    /// [`Work::trial_after`] without a stall before it.
    pub(crate) fn trial(
        &self,
        p: &Prepared,
        d: &Drive,
        w: f64,
        ts_guess: Option<AngleStart>,
        phi_guess: Option<AngleStart>,
    ) -> Trial {
        self.trial_after(p, d, w, ts_guess, phi_guess, false)
    }

    /// `s` as the solve that spent this budget reports it: `no_convergence` with
    /// [`Solution::work_bound_reached`] once the budget is spent (whatever the routes made
    /// of the trials without numbers), else `s` unchanged.
    pub(crate) fn verdict(&self, mut s: Solution) -> Solution {
        if self.exhausted() && s.status != Status::InvalidInput {
            s.status = Status::NoConvergence;
            s.work_bound_reached = true;
        }
        s
    }
}

/// The trial at amplitude `w` [m] of a solve whose budget is spent: every number NaN
/// (no residual, no slope), the rotor-at-rest factor 0 so that no integral is taken for it.
fn spent_trial(w: f64) -> Trial {
    let n = f64::NAN;
    Trial {
        w,
        contact: Contact { half_angle_rad: n, offset: n, full: false },
        chi0: n,
        ts: n,
        vr: n,
        stalled: false,
        a: n,
        v0: n,
        tf: n,
        pf: n,
        rf: n,
        tf0: 0.0,
        z: (n, n),
        k_eff: n,
        w_next: n,
        slope: n,
        carry: [None; 2],
    }
}

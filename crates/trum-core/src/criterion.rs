//! The preload optimisation criterion (Chen, Zheng and Fan 2020, section 5). For each
//! candidate preload: stall torque (the load torque at which the loaded rotor stops),
//! maximum efficiency over load torque, temperature rise after a set run time (Chen et
//! al. 2020 eq. 11) and the speed fluctuation from an assembly runout
//! ([`crate::fluctuation`]). Each indicator is scaled to [0, 1] over the candidates
//! (1 = best: high stall torque, high efficiency, low temperature rise, low fluctuation),
//! and the weighted mean is the score. The optimum is the best score; the optimum
//! region is the contiguous run of candidates around it whose score is within
//! `region_tolerance` of the best.
//!
//! Candidates that exceed a limit of the motor's `[limits]` ([`crate::limits`]; the drive
//! voltage, the larger amplitude and input power of the no-load and run points, and the
//! temperature after the run time, ambient included) are scored but kept out of the
//! optimum and its region, unless no running candidate is within the limits
//! ([`CriterionResult::within_limits`]).
//!
//! The paper combines the four indicators graphically (its Figure 9), giving priority to
//! speed smoothness and temperature rise; the default weights here do the same (2, 2 for
//! fluctuation and temperature; 1, 1 for stall torque and efficiency) and are
//! configurable.

use crate::error::TrumError;
use crate::fluctuation::fluctuation_about;
use crate::limits::{LimitWarnings, LimitedQuantities};
use crate::params::Motor;
use crate::solve::{solve_prepared, OperatingPoint, Prepared, Status};
use crate::sweep::Axis;
use crate::thermal;

/// Settings of the criterion.
#[derive(Clone, Debug, PartialEq)]
pub struct CriterionConfig {
    /// Candidate preloads [N].
    pub preload_n: Axis,
    /// Drive voltage amplitude [V].
    pub voltage_v: f64,
    /// Drive frequency [Hz].
    pub frequency_hz: f64,
    /// Run time for the temperature rise [s] (Chen et al. 2020 section 4.2 uses 10 s).
    pub run_time_s: f64,
    /// Load torque during the temperature run [N·m] (Chen et al. 2020: no load).
    pub run_torque_nm: f64,
    /// Axial runout for the speed fluctuation [m].
    pub runout_m: f64,
    /// Weights of stall torque, max efficiency, temperature rise, speed fluctuation.
    pub weights: [f64; 4],
    /// Score tolerance of the optimum region, as a fraction of the best score.
    pub region_tolerance: f64,
    /// Load torques sampled per preload to find the maximum efficiency.
    pub torque_samples: usize,
}

impl CriterionConfig {
    /// The paper's TRUM60A setting: 150-500 N, 200 V, 43 kHz (Chen et al. 2020 section 4),
    /// 10 s no-load runs, 5 µm runout (assumed: typical axial runout of a 60 mm rotor).
    /// A motor's own drive (`[drive]`) replaces the voltage and frequency in `trum optimize`.
    pub fn seed000() -> CriterionConfig {
        CriterionConfig {
            preload_n: Axis::linspace(150.0, 500.0, 36),
            voltage_v: 200.0,
            frequency_hz: 43_000.0,
            run_time_s: 10.0,
            run_torque_nm: 0.0,
            runout_m: 5e-6,
            weights: [1.0, 1.0, 2.0, 2.0],
            region_tolerance: 0.1,
            torque_samples: 48,
        }
    }

    fn validate(&self) -> Result<(), TrumError> {
        let pos = [("voltage_v", self.voltage_v), ("frequency_hz", self.frequency_hz), ("run_time_s", self.run_time_s)];
        for (n, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(TrumError::input(format!("{n} = {v} must be a finite number > 0")));
            }
        }
        for (n, v) in [
            ("run_torque_nm", self.run_torque_nm),
            ("runout_m", self.runout_m),
            ("region_tolerance", self.region_tolerance),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(TrumError::input(format!("{n} = {v} must be a finite number >= 0")));
            }
        }
        if self.weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) || self.weights.iter().sum::<f64>() <= 0.0 {
            return Err(TrumError::input("weights must be finite, >= 0 and not all zero"));
        }
        // a NaN start or stop must take the error branch
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if self.preload_n.n < 2
            || !(self.preload_n.start > 0.0)
            || !(self.preload_n.stop > self.preload_n.start)
            || !self.preload_n.stop.is_finite()
        {
            return Err(TrumError::input("preload_n: need at least 2 candidates with 0 < start < stop"));
        }
        if self.torque_samples < 4 {
            return Err(TrumError::input("torque_samples must be >= 4"));
        }
        Ok(())
    }
}

/// The indicators and score of one candidate preload.
#[derive(Clone, Debug, PartialEq)]
pub struct CriterionRow {
    /// Candidate preload [N].
    pub preload_n: f64,
    /// Status at no load (a clamped stator disqualifies the candidate).
    pub status: Status,
    /// Stall torque [N·m]: the smallest load torque at which the loaded rotor stops
    /// ([`loaded_stall_torque_nm`]), the torque where `trum map` turns to `stall`.
    pub stall_torque_nm: f64,
    /// Maximum efficiency over load torque [-].
    pub max_efficiency: f64,
    /// Load torque at the maximum efficiency [N·m].
    pub torque_at_max_efficiency_nm: f64,
    /// Temperature rise after the run time at the run torque [K] (Chen et al. 2020 eq. 11
    /// at t = run time; not the steady rise `temperature_rise_k` of a solution).
    pub temperature_rise_after_run_k: f64,
    /// Speed standard deviation over a revolution at no load [rev/min].
    pub speed_std_rpm: f64,
    /// No-load speed [rev/min].
    pub no_load_speed_rpm: f64,
    /// Weighted score in [0, 1] (NaN for disqualified candidates).
    pub score: f64,
    /// True inside the optimum region.
    pub in_region: bool,
    /// The motor's `[limits]` the candidate exceeds (module docs say on what).
    pub warnings: LimitWarnings,
}

impl CriterionRow {
    /// True when the candidate may be the optimum: running, scored and, when `limits`,
    /// within the motor's limits.
    fn eligible(&self, limits: bool) -> bool {
        self.score.is_finite() && (!limits || self.warnings.is_empty())
    }
}

/// The criterion's table and conclusion.
#[derive(Clone, Debug, PartialEq)]
pub struct CriterionResult {
    /// One row per candidate.
    pub rows: Vec<CriterionRow>,
    /// Preload with the best score [N].
    pub optimum_preload_n: f64,
    /// Optimum region [N].
    pub region_n: (f64, f64),
    /// True when the optimum and its region were chosen among the candidates within the
    /// motor's limits; false when no running candidate is within them (then among all).
    pub within_limits: bool,
}

/// Where the optimum sits in the searched range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// Strictly inside: the best score has a worse candidate on each side.
    Interior,
    /// On the lowest candidate preload: the true optimum may be lower.
    Low,
    /// On the highest candidate preload: the true optimum may be higher.
    High,
}

impl CriterionResult {
    /// Whether the optimum is the first or last eligible candidate (clamped or stalled
    /// candidates at the ends, and those beyond a limit, do not count as searched).
    pub fn optimum_edge(&self) -> Edge {
        let running: Vec<f64> =
            self.rows.iter().filter(|r| r.eligible(self.within_limits)).map(|r| r.preload_n).collect();
        match (running.first(), running.last()) {
            (Some(&lo), _) if self.optimum_preload_n <= lo => Edge::Low,
            (_, Some(&hi)) if self.optimum_preload_n >= hi => Edge::High,
            _ => Edge::Interior,
        }
    }
}

/// Overlap of two preload intervals [N] (0 when they are disjoint), and the fraction of
/// `reference` it covers (1 when `reference` is a single point inside `region`).
pub fn region_overlap(region: (f64, f64), reference: (f64, f64)) -> (f64, f64) {
    let ov = (region.1.min(reference.1) - region.0.max(reference.0)).max(0.0);
    let width = reference.1 - reference.0;
    let frac = if width > 0.0 {
        ov / width
    } else if region.0 <= reference.0 && reference.0 <= region.1 {
        1.0
    } else {
        0.0
    };
    (ov, frac)
}

/// The stall torque of the loaded rotor [N·m]: the smallest load torque at which the
/// steady state is `stall`, by bisection on the status between no load (running) and a
/// torque that stalls, to a relative 1e-9. Under load the rotor slows, the friction takes
/// more power from the wave and the amplitude falls, so this is at most the no-load
/// solution's `stall_torque_nm` (the rotor-at-rest torque at the no-load amplitude) for
/// the baseline interface, and can be far below it near clamping. Returns NaN when the
/// rotor does not run at no load or no stalling torque is found below 64 times that value.
pub fn loaded_stall_torque_nm(p: &Prepared, motor: &Motor, preload_n: f64, voltage_v: f64, frequency_hz: f64) -> f64 {
    let status = |t: f64| solve_prepared(p, motor, &OperatingPoint::new(preload_n, t, voltage_v, frequency_hz), None);
    let s0 = status(0.0);
    // a NaN no-load stall torque must take the NaN return
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if s0.status != Status::Ok || !(s0.stall_torque_nm > 0.0) {
        return f64::NAN;
    }
    let (mut lo, mut hi) = (0.0, s0.stall_torque_nm);
    let mut grow = 0;
    loop {
        match status(hi).status {
            Status::Stall | Status::Clamped => break,
            Status::Ok if grow < 6 => {
                lo = hi;
                hi *= 2.0;
                grow += 1;
            }
            _ => return f64::NAN,
        }
    }
    while hi - lo > 1e-9 * hi {
        let mid = 0.5 * (lo + hi);
        match status(mid).status {
            Status::Ok => lo = mid,
            _ => hi = mid,
        }
    }
    hi
}

/// Evaluates the criterion. `progress(done, total)` is called after each candidate.
pub fn evaluate(
    motor: &Motor,
    cfg: &CriterionConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<CriterionResult, TrumError> {
    cfg.validate()?;
    let p = Prepared::new(motor);
    let n = cfg.preload_n.n;
    let mut rows = Vec::with_capacity(n);
    for i in 0..n {
        let f = cfg.preload_n.at(i);
        let op0 = OperatingPoint::new(f, 0.0, cfg.voltage_v, cfg.frequency_hz);
        let s0 = solve_prepared(&p, motor, &op0, None);
        let mut row = CriterionRow {
            preload_n: f,
            status: s0.status,
            stall_torque_nm: f64::NAN,
            max_efficiency: 0.0,
            torque_at_max_efficiency_nm: 0.0,
            temperature_rise_after_run_k: f64::NAN,
            speed_std_rpm: f64::NAN,
            no_load_speed_rpm: s0.speed_rpm,
            score: f64::NAN,
            in_region: false,
            warnings: LimitWarnings::NONE,
        };
        let mut limited = LimitedQuantities::of_point(motor.thermal.ambient_c, &op0, &s0);
        limited.stator_temperature_c = f64::NAN;
        if s0.status == Status::Ok {
            row.stall_torque_nm = loaded_stall_torque_nm(&p, motor, f, cfg.voltage_v, cfg.frequency_hz);
        }
        if s0.status == Status::Ok && row.stall_torque_nm.is_finite() {
            // max efficiency: sample torques up to stall, then golden-section refine about
            // the best sample and its neighbours (they bracket the peak; efficiency is 0 at
            // no load and at stall, so a best sample with efficiency above 0 is interior)
            let eff = |t: f64| {
                solve_prepared(&p, motor, &OperatingPoint::new(f, t, cfg.voltage_v, cfg.frequency_hz), None).efficiency
            };
            let tmax = row.stall_torque_nm;
            let m = cfg.torque_samples;
            let step = tmax / (m - 1) as f64;
            let samples: Vec<(f64, f64)> = (0..m).map(|j| (j as f64 * step, eff(j as f64 * step))).collect();
            let (bi, &(mut t_best, mut e_best)) =
                samples.iter().enumerate().fold((0, &(0.0, 0.0)), |m, (j, s)| if s.1 > m.1 .1 { (j, s) } else { m });
            if bi > 0 && bi + 1 < m {
                let neg = |(t, e): (f64, f64)| (t, -e);
                let triple = (neg(samples[bi - 1]), neg(samples[bi]), neg(samples[bi + 1]));
                let ((_, b, _), _) = crate::golden::minimise(|t| -eff(t), triple, 1e-8 * step, 60, |_| false);
                (t_best, e_best) = (b.0, -b.1);
            }
            row.max_efficiency = e_best;
            row.torque_at_max_efficiency_nm = t_best;
            let run = solve_prepared(
                &p,
                motor,
                &OperatingPoint::new(f, cfg.run_torque_nm, cfg.voltage_v, cfg.frequency_hz),
                None,
            );
            row.temperature_rise_after_run_k =
                thermal::temperature_rise_k(run.total_loss_w(), p.alpha_s, p.heat_cap, cfg.run_time_s);
            if run.status.is_valid() {
                limited.amplitude_m = limited.amplitude_m.max(run.amplitude_m);
                limited.input_power_w = limited.input_power_w.max(run.input_power_w);
            }
            limited.stator_temperature_c = motor.thermal.ambient_c + row.temperature_rise_after_run_k;
            row.speed_std_rpm = fluctuation_about(motor, &p, &op0, &s0, cfg.runout_m, 16).speed_std_rpm;
        }
        row.warnings = motor.limits.check(&limited);
        rows.push(row);
        progress(i + 1, n);
    }
    score(&mut rows, cfg);
    let within_limits = rows.iter().any(|r| r.eligible(true));
    let (bi, best) = rows.iter().enumerate().filter(|(_, r)| r.eligible(within_limits)).fold(
        (usize::MAX, f64::NEG_INFINITY),
        |acc, (i, r)| {
            if r.score > acc.1 {
                (i, r.score)
            } else {
                acc
            }
        },
    );
    if bi == usize::MAX {
        return Err(TrumError::input("no candidate preload gives a running motor at this drive"));
    }
    let thr = best - cfg.region_tolerance * best.abs();
    let (mut lo, mut hi) = (bi, bi);
    let inside = |r: &CriterionRow| r.eligible(within_limits) && r.score >= thr;
    while lo > 0 && inside(&rows[lo - 1]) {
        lo -= 1;
    }
    while hi + 1 < rows.len() && inside(&rows[hi + 1]) {
        hi += 1;
    }
    for r in rows.iter_mut().take(hi + 1).skip(lo) {
        r.in_region = true;
    }
    Ok(CriterionResult {
        optimum_preload_n: rows[bi].preload_n,
        region_n: (rows[lo].preload_n, rows[hi].preload_n),
        rows,
        within_limits,
    })
}

fn score(rows: &mut [CriterionRow], cfg: &CriterionConfig) {
    let valid: Vec<usize> =
        (0..rows.len()).filter(|&i| rows[i].status == Status::Ok && rows[i].stall_torque_nm.is_finite()).collect();
    let metric = |r: &CriterionRow, k: usize| match k {
        0 => r.stall_torque_nm,
        1 => r.max_efficiency,
        2 => -r.temperature_rise_after_run_k,
        _ => -r.speed_std_rpm,
    };
    let mut ranges = [(f64::INFINITY, f64::NEG_INFINITY); 4];
    for &i in &valid {
        for (k, rg) in ranges.iter_mut().enumerate() {
            let v = metric(&rows[i], k);
            *rg = (rg.0.min(v), rg.1.max(v));
        }
    }
    let wsum: f64 = cfg.weights.iter().sum();
    for &i in &valid {
        let mut s = 0.0;
        for (k, rg) in ranges.iter().enumerate() {
            let span = rg.1 - rg.0;
            let x = if span > 0.0 { (metric(&rows[i], k) - rg.0) / span } else { 1.0 };
            s += cfg.weights[k] * x;
        }
        rows[i].score = s / wsum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The maximum efficiency over load torque is the peak of a dense scan (4001 torques to
    /// stall, the peak placed by the parabola through the best and its neighbours): within
    /// 1e-10 of it and at least every scanned value, its torque within a tenth of a scan
    /// step; with a coarse sampling of 8 torques too (the refine starts from the best sample
    /// and its neighbours).
    #[test]
    fn max_efficiency_is_the_peak_of_a_dense_scan() {
        let motor = crate::presets::preset("trum60a").expect("preset");
        for (preload, samples) in [(180.0, 48), (320.0, 48), (320.0, 8)] {
            // (the criterion needs two candidates; the first is the one checked)
            let axis = Axis::linspace(preload, preload + 10.0, 2);
            let cfg = CriterionConfig { preload_n: axis, torque_samples: samples, ..CriterionConfig::seed000() };
            let r = evaluate(&motor, &cfg, &mut |_, _| {}).expect("criterion");
            let row = &r.rows[0];
            let tmax = row.stall_torque_nm;
            let n = 4000;
            let scan: Vec<(f64, f64)> = (0..=n)
                .map(|j| {
                    let t = tmax * j as f64 / n as f64;
                    let op = OperatingPoint::new(preload, t, cfg.voltage_v, cfg.frequency_hz);
                    (t, crate::solve::solve(&motor, &op).efficiency)
                })
                .collect();
            let i = (1..n).fold(1, |m, j| if scan[j].1 > scan[m].1 { j } else { m });
            // the peak between the scan's best and its neighbours, by the parabola through them
            let (l, c, r) = (scan[i - 1].1, scan[i].1, scan[i + 1].1);
            let h = tmax / n as f64;
            let peak = c + (r - l).powi(2) / (8.0 * (2.0 * c - l - r));
            let at = scan[i].0 + 0.5 * h * (r - l) / (2.0 * c - l - r);
            assert!(row.max_efficiency >= c - 1e-12, "{preload} N: {} below the scan's {c}", row.max_efficiency);
            assert!(
                (row.max_efficiency - peak).abs() < 1e-10,
                "{preload} N: {} vs the peak {peak}",
                row.max_efficiency
            );
            assert!((row.torque_at_max_efficiency_nm - at).abs() <= 0.1 * h, "{row:?} vs the peak at {at}");
        }
    }

    /// For every preset at its drive: just below the loaded stall torque the rotor turns,
    /// just above it the rotor is at rest (`stall`, or `clamped`), and the loaded rotor stops no later than
    /// the rotor-at-rest torque at the no-load amplitude.
    #[test]
    fn loaded_stall_torque_is_where_the_status_turns_to_stall() {
        for preset in crate::presets::PRESETS {
            let motor = preset.motor();
            let d = preset.drive().map_or((200.0, 43_000.0), |d| (d.voltage_v, d.frequency_hz));
            let p = Prepared::new(&motor);
            for f in [150.0, 300.0] {
                let t = loaded_stall_torque_nm(&p, &motor, f, d.0, d.1);
                let at = |t: f64| solve_prepared(&p, &motor, &OperatingPoint::new(f, t, d.0, d.1), None);
                assert!(t > 0.0, "{} {f} N: {t}", preset.name);
                assert_eq!(at(t * (1.0 - 1e-6)).status, Status::Ok, "{} {f} N: {t}", preset.name);
                // at rest: stalled, or clamped where the rotor at rest takes the wave's power
                let above = at(t * (1.0 + 1e-6)).status;
                assert!(matches!(above, Status::Stall | Status::Clamped), "{} {f} N: {t}: {above}", preset.name);
                let formula = at(0.0).stall_torque_nm;
                assert!(t <= formula * (1.0 + 1e-9), "{} {f} N: loaded {t} above {formula}", preset.name);
            }
        }
    }

    /// Overlap of preload regions: contained, partial, disjoint, a point reference.
    #[test]
    fn region_overlap_measures_the_shared_interval() {
        assert_eq!(region_overlap((150.0, 360.0), (260.0, 320.0)), (60.0, 1.0));
        assert_eq!(region_overlap((150.0, 290.0), (260.0, 320.0)), (30.0, 0.5));
        assert_eq!(region_overlap((100.0, 200.0), (260.0, 320.0)), (0.0, 0.0));
        assert_eq!(region_overlap((100.0, 300.0), (260.0, 260.0)), (0.0, 1.0));
    }

    /// The optimum's place in the searched range, with disqualified candidates at the ends
    /// not counted as searched.
    #[test]
    fn optimum_edge_is_judged_among_running_candidates() {
        let row = |f: f64, score: f64| CriterionRow {
            preload_n: f,
            status: if score.is_finite() { Status::Ok } else { Status::Clamped },
            stall_torque_nm: 1.0,
            max_efficiency: 0.3,
            torque_at_max_efficiency_nm: 0.5,
            temperature_rise_after_run_k: 1.0,
            speed_std_rpm: 0.1,
            no_load_speed_rpm: 100.0,
            score,
            in_region: false,
            warnings: LimitWarnings::NONE,
        };
        let res = |opt: f64, scores: [f64; 4]| CriterionResult {
            rows: [100.0, 200.0, 300.0, 400.0].iter().zip(scores).map(|(&f, s)| row(f, s)).collect(),
            optimum_preload_n: opt,
            region_n: (opt, opt),
            within_limits: true,
        };
        assert_eq!(res(100.0, [0.9, 0.5, 0.4, 0.3]).optimum_edge(), Edge::Low);
        assert_eq!(res(400.0, [0.1, 0.5, 0.6, 0.9]).optimum_edge(), Edge::High);
        assert_eq!(res(300.0, [0.1, 0.5, 0.9, f64::NAN]).optimum_edge(), Edge::High);
        assert_eq!(res(200.0, [0.1, 0.9, 0.6, 0.3]).optimum_edge(), Edge::Interior);
    }

    /// A candidate beyond a limit is scored as before but kept out of the optimum and its
    /// region; with no candidate within the limits the optimum is chosen among all.
    #[test]
    fn candidates_beyond_a_limit_are_kept_out_of_the_optimum() {
        let motor = crate::presets::preset("trum60a").expect("preset");
        let cfg = CriterionConfig {
            preload_n: Axis::linspace(150.0, 500.0, 8),
            frequency_hz: 42_000.0,
            torque_samples: 8,
            ..CriterionConfig::seed000()
        };
        let free = evaluate(&motor, &cfg, &mut |_, _| {}).expect("criterion");
        assert!(free.within_limits && free.rows.iter().all(|r| r.warnings.is_empty()), "{free:?}");
        // an input-power cap just below the optimum's no-load input (it grows with preload here)
        let at = |f: f64| crate::solve::solve(&motor, &OperatingPoint::new(f, 0.0, cfg.voltage_v, cfg.frequency_hz));
        let mut capped = motor.clone();
        capped.limits.max_input_power_w = 0.99 * at(free.optimum_preload_n).input_power_w;
        let r = evaluate(&capped, &cfg, &mut |_, _| {}).expect("criterion");
        assert!(r.within_limits);
        for (a, b) in r.rows.iter().zip(&free.rows) {
            assert_eq!(a.score.to_bits(), b.score.to_bits(), "limits change no score");
            let beyond = at(a.preload_n).input_power_w > capped.limits.max_input_power_w;
            assert_eq!(a.warnings.contains("max_input_power_w"), beyond, "{a:?}");
            assert!(!(a.in_region && beyond), "{a:?}");
        }
        assert!(r.optimum_preload_n < free.optimum_preload_n, "{} vs {}", r.optimum_preload_n, free.optimum_preload_n);
        assert!(r.region_n.1 < free.optimum_preload_n);
        // nothing within the limits: the optimum among all, said so
        capped.limits.max_voltage_v = 100.0;
        let all = evaluate(&capped, &cfg, &mut |_, _| {}).expect("criterion");
        assert!(!all.within_limits);
        assert!(all.rows.iter().all(|r| r.warnings.contains("max_voltage_v")));
        assert_eq!((all.optimum_preload_n, all.region_n), (free.optimum_preload_n, free.region_n));
    }
}

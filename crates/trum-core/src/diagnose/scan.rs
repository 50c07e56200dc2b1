//! The coarse search of a candidate effect's whole documented range, before (and beside)
//! its local fits (docs/DIAGNOSIS.md, "Fits that search").
//!
//! A local fit starts where it is told and is bounded to a few times the effect's typical
//! strength, so that the solves stay easy; a real motor's effect need not be small, and a
//! fit can end in a valley far from the effect's own. The scan evaluates the objective
//! (nothing fitted) on a subsample of the rows at the effect's strengths on a logarithmic
//! grid from a tenth of typical to the top of its valid range, at each end, the fit start
//! and the middle of every shape parameter, from each given base motor (the calibrated baseline and the
//! nominal motor). A valley that lies beyond the fit's bounds, or lower on the scan's rows
//! than where the fit ended, is handed back as a start.

use crate::calibrate::{residuals, FitParam, ParamRef};
use crate::effects::Effect;
use crate::observable::ObservedRow;
use crate::params::Motor;

/// Most rows the scan evaluates (evenly spaced through the data).
const SCAN_ROWS: usize = 120;

/// Most valleys handed back (each costs a fit; they are fitted in parallel): the lowest by
/// χ², then the best of each other form of the effect. One more than the most forms any
/// effect's grid has (five), so that every form is fitted from its best valley (test
/// `every_form_of_every_effect_fits_under_the_cap`).
const MAX_VALLEYS: usize = 6;

/// Largest strength of the grid, × typical: two decades above the typical strength, the
/// top of the documented range where that is lower. (`voltage_sag`'s documented range
/// reaches 1e5 Ω, where the electrode voltage is all but gone and every solve of the
/// sagging drive is slow; 100 × typical is 15 kΩ.)
const MAX_FACTOR: f64 = 100.0;

/// Ratio between neighbouring strengths of the grid (√10: two points a decade).
const GRID_RATIO: f64 = 3.162_277_660_168_379;

/// A strength inside the scanned series whose χ² is below this fraction of the series' χ²
/// at its weakest strength is a valley of the effect's own, handed back as a start even
/// where it is not lower than the fit: from the nominal motor, whose parameters differ from
/// the motor's by its spread, a strong effect's valley stays above a calibrated fit that
/// has bent the baseline's parameters to mimic part of it, and the fit from the
/// calibrated baseline can collapse onto zero strength where a fit from that valley
/// reaches the noise.
const OWN_VALLEY_LEFT: f64 = 0.5;

/// A start found by the scan.
#[derive(Clone, Debug)]
pub(crate) struct Valley {
    /// The motor the effect is added to.
    pub base: Motor,
    /// The effect's parameters there.
    pub values: Vec<f64>,
    /// χ² on the scan's rows.
    pub chi2: f64,
}

/// Strength factors (× typical) of the grid: from 0.1 in steps of √10 up to the top of the
/// valid range of every strength parameter (or [`MAX_FACTOR`]), the top included.
fn factors(e: Effect) -> Vec<f64> {
    let top = e
        .info()
        .params
        .iter()
        .filter(|p| !p.shape && p.typical != 0.0)
        .map(|p| if p.typical > 0.0 { p.max / p.typical } else { p.min / p.typical })
        .fold(f64::INFINITY, f64::min);
    let mut out = Vec::new();
    let end = top.min(MAX_FACTOR);
    let mut f = 0.1;
    while f <= end * (1.0 + 1e-9) {
        out.push(f);
        f *= GRID_RATIO;
    }
    // the range's top itself, where the steps end short of it (`radial_friction`'s
    // 3 × typical, `tangential_compliance`'s 20 ×, `thermal_drift`'s 25 ×,
    // `eccentricity`'s 50 ×)
    if out.last().is_some_and(|&l| l < end * (1.0 - 1e-9)) {
        out.push(end);
    }
    out
}

/// The effect's parameter vectors of the grid: every strength at `factor` × typical; each
/// shape parameter the fits free at its minimum, its fit start, its middle and its maximum
/// (all their combinations); each held one at its typical value and, one at a time with
/// the others typical, at each of its `levels` (for `voltage_sag`'s knee: `knee_levels`):
/// (factor, values, whether a held shape is off its typical value).
fn grid(e: Effect, knee_levels: &[f64]) -> Vec<(f64, Vec<f64>, bool)> {
    let info = e.info();
    let shapes: Vec<usize> =
        info.params.iter().enumerate().filter(|(_, p)| p.shape && !p.held).map(|(i, _)| i).collect();
    let mut shape_sets: Vec<Vec<f64>> = vec![info.params.iter().map(|p| p.start()).collect()];
    for &i in &shapes {
        let p = &info.params[i];
        shape_sets = shape_sets
            .into_iter()
            .flat_map(|v| {
                let mut levels = vec![p.min, p.start(), 0.5 * (p.min + p.max), p.max];
                levels.sort_by(f64::total_cmp);
                levels.dedup();
                levels.into_iter().map(move |x| {
                    let mut w = v.clone();
                    w[i] = x;
                    w
                })
            })
            .collect();
    }
    // the held shape parameters, one at a time, on every set of the free ones
    let held_sets: Vec<Vec<f64>> = shape_sets
        .iter()
        .flat_map(|set| {
            info.params.iter().enumerate().filter(|(_, p)| p.held).flat_map(move |(i, p)| {
                let levels: &[f64] = if e == Effect::VoltageSag && i == 1 { knee_levels } else { p.levels };
                levels.iter().filter(move |&&x| x != p.typical && (p.min..=p.max).contains(&x)).map(move |&x| {
                    let mut w = set.clone();
                    w[i] = x;
                    w
                })
            })
        })
        .collect();
    let n_plain = shape_sets.len();
    shape_sets.extend(held_sets);
    let mut out = Vec::new();
    for f in factors(e) {
        for (k, set) in shape_sets.iter().enumerate() {
            let v: Vec<f64> =
                info.params.iter().zip(set).map(|(p, &s)| if p.shape { s } else { f * p.typical }).collect();
            out.push((f, v, k >= n_plain));
        }
    }
    out
}

/// A scanned point: (base index, factor, values, χ²).
type Scored = (usize, f64, Vec<f64>, f64);

/// Valleys of the objective along the effect's strength, from each motor of `bases`, that
/// the fit ending at `fitted` has not reached: lower than the fit on the scan's rows, or
/// beyond eight times the typical strength (the fit's bounds) and lower than every
/// strength within them, or a valley of the effect's own; the lowest, and the best of each
/// other form (`pick`).
pub(crate) fn valleys(bases: &[&Motor], fitted: &Motor, rows: &[ObservedRow], e: Effect) -> Vec<Valley> {
    use rayon::prelude::*;
    let step = rows.len().div_ceil(SCAN_ROWS).max(1);
    let sub: Vec<ObservedRow> = rows.iter().step_by(step).cloned().collect();
    let chi2 = |m: &Motor| residuals(m, &sub).iter().map(|z| z * z).sum::<f64>();
    let fit_chi2 = chi2(fitted);
    let knee = if e == Effect::VoltageSag {
        bases.first().map(|b| knee_levels(b, &sub)).unwrap_or_default()
    } else {
        Vec::new()
    };
    let points = grid(e, &knee);
    let score = |pts: Vec<(usize, &&Motor, f64, Vec<f64>)>| -> Vec<Scored> {
        pts.into_par_iter()
            .map(|(b, base, f, v)| {
                let mut m = (*base).clone();
                m.effects.set(e, &v);
                let c = chi2(&m);
                (b, f, v, if c.is_finite() { c } else { f64::INFINITY })
            })
            .collect()
    };
    // first the plain forms (held shapes typical) at every strength
    let mut scored: Vec<Scored> = score(
        bases
            .iter()
            .enumerate()
            .flat_map(|(b, base)| points.iter().filter(|p| !p.2).map(move |(f, v, _)| (b, base, *f, v.clone())))
            .collect(),
    );
    // then each held shape's levels: at every other strength of the grid and at those
    // within one grid step of the plain forms' best from that base, then at the neighbours
    // of each level's own best. A form can change how strong the effect must be by more
    // than a step, most where it changes how the effect scales with the operating point
    // (a softening that falls with the preload against one that grows), so its best need
    // not lie next to the plain form's; the whole grid for every level cost a null
    // diagnosis a quarter more time.
    let grid_factors = factors(e);
    let index = |f: f64| grid_factors.iter().position(|&g| g == f).unwrap_or(0);
    let near: Vec<Vec<usize>> = (0..bases.len())
        .map(|b| {
            let best = scored.iter().filter(|p| p.0 == b).min_by(|x, y| x.3.total_cmp(&y.3)).map(|p| p.1);
            let k = best.map_or(0, index);
            (k.saturating_sub(1)..(k + 2).min(grid_factors.len())).collect()
        })
        .collect();
    let first_pass = |b: usize, f: f64| index(f) % 2 == 0 || near[b].contains(&index(f));
    scored.extend(score(
        bases
            .iter()
            .enumerate()
            .flat_map(|(b, base)| {
                points.iter().filter(move |p| p.2 && first_pass(b, p.0)).map(move |(f, v, _)| (b, base, *f, v.clone()))
            })
            .collect(),
    ));
    let shape_of = |v: &[f64]| -> Vec<u64> {
        e.info().params.iter().zip(v).filter(|(q, _)| q.shape).map(|(_, x)| x.to_bits()).collect()
    };
    let mut refine: Vec<(usize, &&Motor, f64, Vec<f64>)> = Vec::new();
    for (b, base) in bases.iter().enumerate() {
        for (f, v, _) in points.iter().filter(|p| p.2 && !first_pass(b, p.0)) {
            // the level's best so far, from this base
            let key = shape_of(v);
            let best = scored
                .iter()
                .filter(|p| p.0 == b && shape_of(&p.2) == key)
                .min_by(|x, y| x.3.total_cmp(&y.3))
                .map(|p| index(p.1));
            if best.is_some_and(|k| index(*f).abs_diff(k) == 1) {
                refine.push((b, base, *f, v.clone()));
            }
        }
    }
    scored.extend(score(refine));
    let mut found: Vec<Found> = Vec::new();
    for (b, base) in bases.iter().enumerate() {
        // one series per shape set: the values with the same shape parameters
        let mut series: Vec<Vec<&Scored>> = Vec::new();
        for p in scored.iter().filter(|p| p.0 == b) {
            match series.iter_mut().find(|s| shape_of(&s[0].2) == shape_of(&p.2)) {
                Some(s) => s.push(p),
                None => series.push(vec![p]),
            }
        }
        // each series by strength (a held level's refinement was scored after its first pass)
        for s in &mut series {
            s.sort_by(|x, y| x.1.total_cmp(&y.1));
        }
        // (within the fit's bounds: every form scanned from this base, as a held shape's
        // short series may have no strength of its own there)
        let inside = scored.iter().filter(|p| p.0 == b && p.1 <= 8.0).map(|p| p.3).fold(f64::INFINITY, f64::min);
        for s in &series {
            for (i, p) in s.iter().enumerate() {
                let left = i == 0 || s[i - 1].3 > p.3;
                let right = i + 1 == s.len() || s[i + 1].3 >= p.3;
                if !(left && right) {
                    continue;
                }
                let lower = p.3 < fit_chi2 - 4.0;
                let fenced = p.1 > 8.0 && p.3 < inside - 4.0;
                // a valley of the effect's own: inside the series, and the effect there
                // removes most of what the base misses at its weakest strength
                let own = i > 0 && p.3 < OWN_VALLEY_LEFT * s[0].3;
                if lower || fenced || own {
                    let valley = Valley { base: (*base).clone(), values: p.2.clone(), chi2: p.3 };
                    found.push(Found { valley, left: p.3 / s[0].3, form: shape_of(&p.2), base: b });
                }
            }
        }
    }
    pick(found)
}

/// A valley with what ranks it among the others.
struct Found {
    valley: Valley,
    /// Its χ² over its series' χ² at the weakest strength: the part of what the base misses
    /// that the effect leaves there.
    left: f64,
    /// The effect's shape parameters there (bit patterns): its form.
    form: Vec<u64>,
    /// Which base motor it was scanned from.
    base: usize,
}

/// The valleys handed back, best first, at most [`MAX_VALLEYS`]: the lowest χ², then the
/// best of each other form by the part of its base's miss it leaves, then, while there is
/// room, the best of each form from the other base. The held shape levels are forms no fit
/// moves between, and χ² from different bases do not compare (the nominal motor's is of a
/// motor nothing was fitted to): a softening that falls with the preload, scanned from the
/// nominal motor, left an eighth of that motor's miss, where two rising forms from the
/// calibrated baseline were a little lower in χ² but fitted to nothing, and only its own
/// fit reached the noise. For the same reason one form's valley from the calibrated
/// baseline (often a small step off the fit) does not stand for the same form's valley
/// from the nominal motor: a `radial_friction` at the top of its range on a combined
/// campaign of `generic60` reached the noise only from the nominal motor's valley of the
/// form the calibrated baseline's lowest valley already had.
fn pick(mut found: Vec<Found>) -> Vec<Valley> {
    found.sort_by(|a, b| a.valley.chi2.total_cmp(&b.valley.chi2));
    let mut chosen: Vec<Found> = Vec::new();
    let mut rest = found.into_iter();
    chosen.extend(rest.next());
    let mut rest: Vec<Found> = rest.collect();
    rest.sort_by(|a, b| a.left.total_cmp(&b.left));
    let mut later = Vec::new();
    for f in rest {
        if !chosen.iter().any(|c| c.form == f.form) {
            if chosen.len() < MAX_VALLEYS {
                chosen.push(f);
            }
        } else {
            later.push(f);
        }
    }
    for f in later {
        if chosen.len() == MAX_VALLEYS {
            break;
        }
        if !chosen.iter().any(|c| c.form == f.form && c.base == f.base) {
            chosen.push(f);
        }
    }
    let mut out: Vec<Valley> = chosen.into_iter().map(|f| f.valley).collect();
    out.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
    out
}

/// Where the scan places `voltage_sag`'s knee: at the quartiles of the phase current
/// amplitude `base` draws at the scan's rows, the only scale a current limit has. (A knee
/// above every current is the baseline; one below every current sags like the resistive
/// source with a smaller set voltage.)
fn knee_levels(base: &Motor, rows: &[ObservedRow]) -> Vec<f64> {
    let p = crate::solve::Prepared::new(base).without_stall_torque();
    let inst = base.effects.instrument();
    let mut amps: Vec<f64> = rows
        .iter()
        .map(|r| crate::solve::solve_prepared(&p, base, &inst.operating_point(&r.op), None).current_a)
        .filter(|a| a.is_finite() && *a > 0.0)
        .collect();
    if amps.is_empty() {
        return Vec::new();
    }
    amps.sort_by(f64::total_cmp);
    [0.25, 0.5, 0.75].iter().map(|q| amps[((amps.len() - 1) as f64 * q).round() as usize]).collect()
}

/// Widens the bounds of `e`'s strength parameters in `params` to hold `values` with room
/// to move (three times the value, within the valid range).
pub(crate) fn widen(params: &mut [FitParam], e: Effect, values: &[f64]) {
    for fp in params.iter_mut() {
        // (a pair's fit also holds the other effect's parameters: only e's are widened)
        let ParamRef::Effect(f, i) = fp.param else { continue };
        if f != e {
            continue;
        }
        let p = &e.info().params[i];
        if p.shape {
            continue;
        }
        let v = values[i];
        if v > 0.0 {
            fp.hi = fp.hi.max((3.0 * v).min(p.max));
        } else if v < 0.0 {
            fp.lo = fp.lo.min((3.0 * v).max(p.min));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::ALL;

    #[test]
    fn the_grid_spans_each_effects_documented_range() {
        for e in ALL {
            let f = factors(e);
            assert!(!f.is_empty(), "{e}");
            assert!((f[0] - 0.1).abs() < 1e-12);
            let mut reach = f64::INFINITY;
            for p in e.info().params.iter().filter(|p| !p.shape && p.typical != 0.0) {
                let top = f.last().copied().unwrap_or(0.0) * p.typical;
                // within the range
                assert!(top.abs() <= p.max.abs().max(p.min.abs()) * (1.0 + 1e-9), "{e}: {top}");
                reach = reach.min(if p.typical > 0.0 { p.max / p.typical } else { p.min / p.typical });
            }
            // and at its end (or the grid's cap): the whole documented range
            let last = f.last().copied().unwrap_or(0.0);
            assert!((last - reach.min(MAX_FACTOR)).abs() <= 1e-9 * last, "{e}: {last} vs {reach}");
        }
        // preload_stiffening reaches its documented scale of 5 (100 × typical), beyond the
        // local fit's eight
        let ps = factors(Effect::PreloadStiffening);
        assert!(ps.last().copied().unwrap_or(0.0) * 0.05 > 3.0, "{ps:?}");
        // a shape parameter at its ends and middle
        assert_eq!(grid(Effect::PreloadStiffening, &[]).len(), 3 * ps.len());
        assert!(grid(Effect::PreloadStiffening, &[]).iter().all(|p| !p.2));
    }

    /// Each held shape parameter is scanned at its levels, one at a time with the others at
    /// their typical values, on every strength of the grid; `voltage_sag`'s knee at the
    /// levels the data give.
    #[test]
    fn the_grid_tries_each_held_shape_at_its_levels() {
        let count = |e: Effect, knee: &[f64]| grid(e, knee).len() / factors(e).len();
        assert_eq!(count(Effect::RadialFriction, &[]), 3);
        assert_eq!(count(Effect::HertzSoftening, &[]), 5);
        assert_eq!(count(Effect::ThermalDrift, &[]), 3);
        assert_eq!(count(Effect::Eccentricity, &[]), 5);
        assert_eq!(count(Effect::TangentialCompliance, &[]), 3);
        assert_eq!(count(Effect::VoltageSag, &[]), 1);
        assert_eq!(count(Effect::VoltageSag, &[0.1, 0.2, 0.3]), 4);
        // one shape moved at a time: never two held shapes off their typical values
        for (_, v, held) in grid(Effect::Eccentricity, &[]) {
            assert!(v[1] == 0.0 || v[2] == 0.0, "{v:?}");
            assert_eq!(held, v[1] != 0.0 || v[2] != 0.0, "{v:?}");
        }
        let knees: Vec<f64> = grid(Effect::VoltageSag, &[0.1, 0.2, 0.3]).iter().map(|(_, v, _)| v[1]).collect();
        assert!(knees.contains(&0.0) && knees.contains(&0.2));
    }

    /// Every form of every effect's grid (its shape parameters' combinations) gets its best
    /// valley fitted: the forms, besides the lowest valley, fit under the cap.
    #[test]
    fn every_form_of_every_effect_fits_under_the_cap() {
        for e in ALL {
            let mut forms: Vec<Vec<u64>> = grid(e, &[0.1, 0.2, 0.3])
                .iter()
                .map(|(_, v, _)| {
                    e.info().params.iter().zip(v).filter(|(q, _)| q.shape).map(|(_, x)| x.to_bits()).collect()
                })
                .collect();
            forms.sort();
            forms.dedup();
            assert!(forms.len() < MAX_VALLEYS, "{e}: {} forms", forms.len());
        }
    }

    /// The lowest valley first, then the best of each other form by the part of its base's
    /// miss it leaves, one per form, then each form's best from the other base while there
    /// is room, at most `MAX_VALLEYS`.
    #[test]
    fn the_valleys_handed_back_are_the_lowest_and_each_forms_best() {
        let motor = crate::presets::preset("generic60").expect("preset");
        let f = |chi2: f64, left: f64, form: u64, strength: f64, base: usize| Found {
            valley: Valley { base: motor.clone(), values: vec![strength, form as f64], chi2 },
            left,
            form: vec![form],
            base,
        };
        let found = vec![
            // near the calibrated baseline (base 0): lowest in χ², little of its miss removed
            f(2169.0, 0.99, 2, 0.1, 0),
            f(2178.0, 0.99, 3, 0.1, 0),
            // from the nominal motor (base 1): far above in χ², most of its miss removed
            f(18865.0, 0.06, 1, 3.0, 1),
            f(19500.0, 0.07, 1, 10.0, 1),
            f(33260.0, 0.12, 0, 100.0, 1),
            f(48024.0, 0.15, 4, 3.0, 1),
        ];
        let out = pick(found);
        let got: Vec<(f64, f64)> = out.iter().map(|v| (v.chi2, v.values[1])).collect();
        // the lowest; then by what they leave: form 1's best (not its second valley from the
        // same base), form 0, form 4 (0.15 left), form 3 (0.99); returned by χ²
        assert_eq!(got, vec![(2169.0, 2.0), (2178.0, 3.0), (18865.0, 1.0), (33260.0, 0.0), (48024.0, 4.0)]);
        // fewer than the cap: every distinct form, and a form's valley from the other base
        let two = pick(vec![f(5.0, 0.9, 1, 1.0, 0), f(7.0, 0.2, 1, 3.0, 0), f(9.0, 0.5, 2, 1.0, 0)]);
        assert_eq!(two.iter().map(|v| v.chi2).collect::<Vec<_>>(), vec![5.0, 9.0]);
        // the lowest valley is a small step off the fit from the calibrated baseline; the
        // nominal motor's valley of the same form is fitted too
        let strong = pick(vec![
            f(108_129.0, 1.0, 0, 0.1, 0),
            f(5_766_888.0, 0.162, 0, 3.0, 1),
            f(246_707.0, 0.007, 5, 3.0, 1),
            f(430_803.0, 0.012, 10, 3.0, 1),
        ]);
        assert_eq!(
            strong.iter().map(|v| v.chi2).collect::<Vec<_>>(),
            vec![108_129.0, 246_707.0, 430_803.0, 5_766_888.0]
        );
        // at the cap, every form's best comes before a second base's valley of a form
        let mut many: Vec<Found> = (0..6).map(|k| f(100.0 + k as f64, 0.5, k, 1.0, 0)).collect();
        many.push(f(5000.0, 0.01, 0, 3.0, 1));
        let capped = pick(many);
        assert_eq!(capped.len(), MAX_VALLEYS);
        assert!(capped.iter().all(|v| v.chi2 < 1000.0));
        assert!(pick(Vec::new()).is_empty());
    }

    #[test]
    fn widening_holds_the_valley_within_the_valid_range() {
        let e = Effect::PreloadStiffening;
        let mut params = crate::calibrate::effect_params(e);
        assert!((params[0].hi - 0.4).abs() < 1e-12);
        widen(&mut params, e, &[1.0, 1.0]);
        assert!((params[0].hi - 3.0).abs() < 1e-12);
        widen(&mut params, e, &[4.0, 1.0]);
        assert_eq!(params[0].hi, 5.0);
        // the shape parameter keeps its whole range
        assert_eq!((params[1].lo, params[1].hi), (0.0, 1.0));
        // in a pair's parameters only the named effect's strengths move, whatever the other
        // effect's parameter count
        let mut pair = crate::calibrate::effect_params(Effect::ThermalDrift);
        pair.extend(crate::calibrate::effect_params(Effect::VoltageSag));
        let before: Vec<(f64, f64)> = pair.iter().map(|p| (p.lo, p.hi)).collect();
        widen(&mut pair, Effect::VoltageSag, &[5000.0, 0.0]);
        for (k, p) in pair.iter().enumerate() {
            if matches!(p.param, ParamRef::Effect(Effect::VoltageSag, 0)) {
                assert_eq!(p.hi, 15000.0);
            } else {
                assert_eq!((p.lo, p.hi), before[k], "{k}");
            }
        }
    }
}

//! The context every stage of a diagnosis reads: the rows as the fits see them (bench
//! model applied, noise levels estimated from the data), their folds, the quantity scales
//! of the NRMSE and the notes so far.

use super::{bench, folds, DiagnoseOptions};
use crate::calibrate::baseline_params_with;
use crate::error::TrumError;
use crate::noise::NoiseScale;
use crate::observable::{Observable, ObservedRow};
use crate::params::Motor;
use std::collections::BTreeMap;

/// The prepared data of one diagnosis and what follows from them alone.
pub(super) struct Context<'a> {
    /// The nominal motor: bounds and priors of every fit are around it.
    pub(super) motor: &'a Motor,
    /// The run of each row the fits see (may be shorter than the rows: the rest are in
    /// run "").
    pub(super) groups: Vec<String>,
    /// The input rows the fits see, by index, when the data have more than
    /// `DiagnoseOptions::max_fit_rows` (`calibrate::systematic_sample`); `None`: all of them.
    pub(super) sample: Option<Vec<usize>>,
    /// The best noise levels (`baseline::noise_estimate`) from all input rows, when the
    /// fits see a subsample (whose runs keep too few neighbouring readings for them).
    pub(super) best_noise: Option<BTreeMap<Observable, NoiseScale>>,
    /// The options, exact cross-validation switched on for reduced data.
    pub(super) opts: DiagnoseOptions,
    /// The rows after the bench model, with their stated noise levels.
    pub(super) unscaled: Vec<ObservedRow>,
    /// The rows every fit sees: the noise levels scaled by the estimate from the data.
    pub(super) rows: Vec<ObservedRow>,
    /// Noise factors estimated from the data, per quantity (`crate::noise::estimate`).
    pub(super) est: BTreeMap<Observable, NoiseScale>,
    /// The same as reported: quantity, factor applied, line residuals it rests on.
    pub(super) noise_scale: Vec<(String, f64, usize)>,
    /// The fold of each row ([`folds::assign`]).
    pub(super) folds: Vec<usize>,
    /// Number of folds.
    pub(super) k: usize,
    /// Readings in the input.
    pub(super) n_read: usize,
    /// Fewer than four readings per baseline parameter (plus two): the parameters rest
    /// largely on their priors, and every fold is refitted exactly.
    pub(super) reduced: bool,
    /// Scale of each quantity in the NRMSE ([`scales`]).
    pub(super) sc: BTreeMap<Observable, f64>,
    /// The noise level as an NRMSE, with the noise levels the fits weigh readings by.
    pub(super) noise_weights: f64,
    /// Notes so far, in report order.
    pub(super) notes: Vec<String>,
}

impl<'a> Context<'a> {
    /// Prepares `rows` (with `groups[i]` the run of row i) for a diagnosis against `motor`.
    /// Errors on data that cannot support any held-out test.
    pub(super) fn new(
        motor: &'a Motor,
        rows: &[ObservedRow],
        groups: &[String],
        opts: &DiagnoseOptions,
    ) -> Result<Context<'a>, TrumError> {
        // The sensors' noise levels where the user states them, the defaults elsewhere.
        let stated = with_stated_noise(rows, &opts.stated_noise)?;
        // The bench model first: set points read back with noise are taken at their run's
        // mean, stale readings are left out, quantised readings carry their rounding error
        // (`bench`).
        let (unscaled, mut bench_notes) = bench_model(&stated, groups);
        // (a large file's rows are held by the caller and once here, not once per stage)
        drop(stated);
        // Noise levels from the data, so that χ² and the evidence are on the scale of the
        // actual noise; clamped to [1/4, 4] × the default levels. A level the user states
        // is kept as stated: the estimate is reported beside it.
        let mut est = crate::noise::estimate(&unscaled, groups);
        let estimated_for_stated: Vec<String> = opts
            .stated_noise
            .keys()
            .filter_map(|o| {
                est.get(o)
                    .map(|n| format!("{} {:.2} × its stated level ({} residuals)", o.column(), n.factor, n.residuals))
            })
            .collect();
        for (o, n) in est.iter_mut() {
            if opts.stated_noise.contains_key(o) {
                n.factor = 1.0;
            }
        }
        if !opts.stated_noise.is_empty() {
            let list: Vec<String> = opts
                .stated_noise
                .iter()
                .map(|(o, (a, r))| format!("{} σ = {} + {} × reading", o.column(), a, r))
                .collect();
            let estimate = if estimated_for_stated.is_empty() {
                String::new()
            } else {
                format!("; the data's own estimate: {}", estimated_for_stated.join(", "))
            };
            bench_notes.push(format!("noise levels as stated for the bench's sensors: {}{estimate}", list.join(", ")));
        }
        // Large data: the fits see a systematic subsample; the set points, the noise levels
        // and the best noise levels come from every row (each a pass over the rows, against
        // hundreds for the fits).
        let sample = crate::calibrate::systematic_sample(rows.len(), opts.max_fit_rows);
        let (unscaled, groups, best_noise) = match &sample {
            Some(s) => {
                let best = super::baseline::noise_estimate(motor, &unscaled, groups, &est);
                bench_notes.push(format!(
                    "{} rows: the fits see a systematic subsample of {} of them (one row in every {:.1}, in file order, so \
                     every run keeps its share); set points and noise levels come from all rows; the evidence, the \
                     held-out figures and their intervals are those of the subsample (wider than all rows would give)",
                    rows.len(),
                    s.len(),
                    rows.len() as f64 / s.len() as f64
                ));
                let picked: Vec<ObservedRow> = s.iter().map(|&i| unscaled[i].clone()).collect();
                let g: Vec<String> = s.iter().map(|&i| groups.get(i).cloned().unwrap_or_default()).collect();
                (picked, g, Some(best))
            }
            None => (unscaled, groups.to_vec(), None),
        };
        let scaled = noise_scaled(&unscaled, &est);
        // Gross outliers that stand alone off their neighbours are the bench's, not the
        // motor's: left out of every fit and every held-out figure. (The fits' Huber loss
        // bounds their pull, but one such reading held out can be most of a held-out NRMSE,
        // which is not clipped, and so decide a shrink.)
        let spikes = crate::noise::isolated_spikes(&scaled, &groups);
        let (unscaled, scaled) = if spikes.is_empty() {
            (unscaled, scaled)
        } else {
            bench_notes.push(spikes_note(&spikes, &scaled, sample.as_deref()));
            (without_readings(unscaled, &spikes), without_readings(scaled, &spikes))
        };
        let n_read: usize = unscaled.iter().map(|r| r.readings.len()).sum();
        let rows = &scaled[..];
        let noise_scale: Vec<(String, f64, usize)> = est
            .iter()
            .filter(|(o, _)| !opts.stated_noise.contains_key(o))
            .map(|(&o, n)| (o.column().to_string(), applied_factor(&est, o), n.residuals))
            .collect();
        if rows.len() < 4 {
            return Err(TrumError::input(format!(
                "{} rows are too few to diagnose anything; need at least 4 operating points",
                rows.len()
            )));
        }
        let (folds, k) = folds::assign(rows, &groups, opts.folds)?;
        let mut notes: Vec<String> = bench_notes;
        if !noise_scale.is_empty() {
            let list: Vec<String> = noise_scale.iter().map(|(q, f, n)| format!("{q} ×{f:.2} ({n})")).collect();
            notes.push(format!(
                "noise levels estimated from the data (residuals from lines through neighbouring readings \
                 within runs; factor on the default levels, residuals used): {}",
                list.join(", ")
            ));
        }
        let n_base = baseline_params_with(motor, rows, &opts.tolerances).len();
        let reduced = n_read < 4 * (n_base + 2);
        if reduced {
            notes.push(format!(
                "only {n_read} readings: the baseline's parameters rest largely on their priors, the held-out \
                 figures come from exact refits, and no effect can be confirmed with confidence"
            ));
        }
        // With few readings the fit is far from linear over a fold's influence: refit exactly
        // (cheap at this size).
        let opts = &DiagnoseOptions { exact_cv: opts.exact_cv || reduced, ..opts.clone() };
        let sc = scales(rows);
        // noise level as NRMSE, with the weights' noise levels
        let noise_weights = {
            let mut acc = 0.0;
            for r in rows {
                for &(o, _, s) in &r.readings {
                    acc += (s / sc[&o]).powi(2);
                }
            }
            (acc / n_read as f64).sqrt()
        };
        notes.extend(data_notes(rows));
        Ok(Context {
            motor,
            groups,
            sample,
            best_noise,
            opts: opts.clone(),
            unscaled,
            rows: scaled,
            est,
            noise_scale,
            folds,
            k,
            n_read,
            reduced,
            sc,
            noise_weights,
            notes,
        })
    }
}

/// `rows` without the readings `drop` (row index, quantity).
fn without_readings(mut rows: Vec<ObservedRow>, drop: &[(usize, Observable)]) -> Vec<ObservedRow> {
    for &(i, o) in drop {
        if let Some(r) = rows.get_mut(i) {
            r.readings.retain(|x| x.0 != o);
        }
    }
    rows
}

/// The note naming the isolated spikes left out (`rows` the fits' rows; `sample` maps them
/// to the input's rows).
fn spikes_note(spikes: &[(usize, Observable)], rows: &[ObservedRow], sample: Option<&[usize]>) -> String {
    let shown: Vec<String> = spikes
        .iter()
        .take(8)
        .map(|&(i, o)| {
            let value = rows[i].readings.iter().find(|x| x.0 == o).map(|x| x.1).unwrap_or(f64::NAN);
            let row = sample.map_or(i, |s| s[i]) + 1;
            format!("{} = {value} in data row {row}", o.column())
        })
        .collect();
    let more =
        if spikes.len() > shown.len() { format!(" and {} more", spikes.len() - shown.len()) } else { String::new() };
    format!(
        "{} reading(s) stand alone off their neighbours (more than {} standard deviations off the curve through \
         four neighbouring readings of their quantity, while the row's other readings lie on theirs): gross \
         outliers of the bench, left out of every fit and held-out figure: {}{more}",
        spikes.len(),
        crate::noise::SPIKE_Z,
        shown.join("; ")
    )
}

/// What the data cannot show, in notes: the operating coordinates that never vary and the
/// quantities never read, and which effects that leaves untestable or weakly constrained.
pub(super) fn data_notes(rows: &[ObservedRow]) -> Vec<String> {
    let mut notes = Vec::new();
    let varies = |f: &dyn Fn(&ObservedRow) -> f64| {
        let v: Vec<f64> = rows.iter().map(f).collect();
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| (a.0.min(x), a.1.max(x)));
        hi - lo > 1e-9 * hi.abs().max(1.0)
    };
    let has = |o: Observable| rows.iter().any(|r| r.readings.iter().any(|x| x.0 == o));
    if !varies(&|r| r.op.frequency_hz) {
        notes.push("frequency never varies: preload_stiffening and hertz_softening show only through amplitude and speed, not through a resonance shift".into());
    }
    if !varies(&|r| r.op.elapsed_s) {
        notes.push("no time series (elapsed_s): thermal_drift cannot act and is not testable".into());
    }
    if !has(Observable::SpeedStdRpm) {
        notes.push("no speed_std_rpm column: eccentricity shows only through the mean speed".into());
    }
    if !has(Observable::InputPowerW) && !has(Observable::CurrentA) {
        notes.push(
            "no electrical readings (input_power_w, current_a): voltage_sag and the losses are weakly constrained"
                .into(),
        );
    }
    if !varies(&|r| r.op.torque_nm) {
        notes.push(
            "load torque never varies: the speed-torque curve (radial_friction, tangential_compliance) is not observed"
                .into(),
        );
    }
    notes
}

/// The floor of a quantity's NRMSE scale, × its mean noise level.
const NOISE_SCALE_FLOOR: f64 = 2.0;

/// Scale of each observable for the NRMSE: the spread (standard deviation) of its
/// measured values, floored by its noise level.
pub(super) fn scales(rows: &[ObservedRow]) -> BTreeMap<Observable, f64> {
    let mut acc: BTreeMap<Observable, Vec<(f64, f64)>> = BTreeMap::new();
    for r in rows {
        for &(o, v, s) in &r.readings {
            acc.entry(o).or_default().push((v, s));
        }
    }
    acc.into_iter()
        .map(|(o, vs)| {
            let n = vs.len() as f64;
            let mean = vs.iter().map(|x| x.0).sum::<f64>() / n;
            let sd = (vs.iter().map(|x| (x.0 - mean).powi(2)).sum::<f64>() / n).sqrt();
            let noise = vs.iter().map(|x| x.1).sum::<f64>() / n;
            (o, sd.max(NOISE_SCALE_FLOOR * noise).max(1e-12))
        })
        .collect()
}

/// The rows as the diagnosis fits them, after the bench model (`bench`): set points read
/// back with noise at their run's mean, stale readings left out, quantised readings with
/// their rounding error; and the notes saying what was done.
pub(super) fn bench_model(rows: &[ObservedRow], groups: &[String]) -> (Vec<ObservedRow>, Vec<String>) {
    let (snapped, snap_note) = bench::snap_set_points(rows, groups);
    let (fresh, stale_note) = bench::drop_stale_readings(snapped, groups);
    let (out, quantum_note) = bench::account_for_quantisation(fresh);
    (out, snap_note.into_iter().chain(stale_note).chain(quantum_note).collect())
}

/// `rows` with the σ of every reading of a quantity in `stated` set to its stated level,
/// `absolute + relative · |reading|`. Errors on a part that is negative or not finite, and
/// on an absolute part of zero (a reading of zero would have no noise and weigh
/// infinitely).
fn with_stated_noise<'r>(
    rows: &'r [ObservedRow],
    stated: &BTreeMap<Observable, (f64, f64)>,
) -> Result<std::borrow::Cow<'r, [ObservedRow]>, TrumError> {
    for (o, &(a, r)) in stated {
        let ok = a.is_finite() && r.is_finite() && a > 0.0 && r >= 0.0;
        if !ok {
            return Err(TrumError::input(format!(
                "stated noise level of {}: the absolute part ({a}) must be a finite number > 0 and the relative part ({r}) a finite number >= 0",
                o.column()
            )));
        }
    }
    if stated.is_empty() {
        return Ok(std::borrow::Cow::Borrowed(rows));
    }
    Ok(rows
        .iter()
        .map(|row| {
            let mut row = row.clone();
            for x in row.readings.iter_mut() {
                if let Some(&(a, r)) = stated.get(&x.0) {
                    x.2 = a + r * x.1.abs();
                }
            }
            row
        })
        .collect())
}

/// The factor applied to the stated noise levels of quantity `o`: its estimate clamped to
/// [1/4, 4], or 1 without one.
pub(super) fn applied_factor(est: &BTreeMap<Observable, crate::noise::NoiseScale>, o: Observable) -> f64 {
    est.get(&o).map_or(1.0, |n| n.factor.clamp(0.25, 4.0))
}

/// The rows with each reading's σ scaled by the noise factor estimated for its quantity
/// (clamped to [1/4, 4]), marked clipped where `speed_std_clipped` says so.
pub(super) fn noise_scaled(
    rows: &[ObservedRow],
    est: &BTreeMap<Observable, crate::noise::NoiseScale>,
) -> Vec<ObservedRow> {
    let scaled: Vec<ObservedRow> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            for x in r.readings.iter_mut() {
                x.2 *= applied_factor(est, x.0);
            }
            r
        })
        .collect();
    let clipped = speed_std_clipped(&scaled, est.contains_key(&Observable::SpeedStdRpm));
    scaled.into_iter().map(|r| ObservedRow { speed_std_clipped: clipped, ..r }).collect()
}

/// Whether the speed-std readings of `rows` are compared with the expected reading of
/// clipped noise (`ObservedRow::speed_std_clipped`): some read exactly zero (the bench
/// clips at zero) and their noise level was `estimated` from the data. With the stated
/// (default) level, 2.5-5× the synthetic bench's, that expectation would overshoot; exact
/// data (the blind benchmark's reference fits) have no noise to clip.
pub(super) fn speed_std_clipped(rows: &[ObservedRow], estimated: bool) -> bool {
    estimated && rows.iter().flat_map(|r| &r.readings).any(|x| crate::noise::clipped_reading(x.0, x.1))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::super::tests::quick;
    use super::super::{diagnose, DiagnoseOptions};
    use crate::effects::Effect;
    use crate::synth::{synthesize, Campaign, SynthConfig};

    /// Two preload-torque campaigns of one motor with a voltage sag (112 rows), diagnosed with
    /// at most 56 rows fitted: the fits see one row in two, a note says so, the counts are
    /// the input's rows and the subsample's readings, every held-out reading names its row
    /// in the input with that row's measured value, and the sag is still found, with less
    /// evidence than all rows give it.
    #[test]
    fn large_data_are_diagnosed_on_a_subsample_that_the_result_names() {
        let nominal = crate::calibrate::tests::reference_motor();
        let mut truth = nominal.clone();
        truth.effects.set_strength(Effect::VoltageSag, 300.0);
        // one motor (one motor seed) measured twice with different noise
        let (mut rows, mut groups) = (Vec::new(), Vec::new());
        for seed in [11, 12] {
            let cfg = SynthConfig {
                campaign: Campaign::PreloadTorque,
                noise: 1.0,
                seed,
                motor_seed: Some(11),
                ..SynthConfig::default()
            };
            for r in synthesize(&truth, &cfg).unwrap() {
                rows.push(r.observed());
                groups.push(format!("{seed}-{}", r.run_id));
            }
        }
        let opts = DiagnoseOptions { max_fit_rows: 56, ..quick(false) };
        let part = diagnose(&nominal, &rows, &groups, &opts).unwrap();
        let all = diagnose(&nominal, &rows, &groups, &DiagnoseOptions { max_fit_rows: 0, ..opts.clone() }).unwrap();
        assert_eq!(part.n_rows, 112);
        assert_eq!(all.n_rows, 112);
        let sample = crate::calibrate::systematic_sample(112, 56).unwrap();
        let sampled_readings: usize = sample.iter().map(|&i| rows[i].readings.len()).sum();
        assert_eq!(part.n_readings, sampled_readings);
        assert!(part.notes.iter().any(|n| n.starts_with("112 rows: the fits see a systematic subsample of 56")));
        assert!(!all.notes.iter().any(|n| n.contains("subsample")));
        assert_eq!(part.heldout.len(), sampled_readings);
        for h in &part.heldout {
            assert!(sample.contains(&h.row), "row {}", h.row);
            assert!(rows[h.row].readings.iter().any(|x| x.0 == h.observable && x.1 == h.measured));
        }
        for d in [&part, &all] {
            assert_eq!(d.verdict, "voltage_sag", "{:?}", d.notes);
        }
        let evidence =
            |d: &super::super::Diagnosis| d.ranking.iter().find(|r| r.effect == "voltage_sag").unwrap().evidence;
        assert!(evidence(&part) > 5.0 && evidence(&part) < evidence(&all), "{} vs {}", evidence(&part), evidence(&all));
    }
}

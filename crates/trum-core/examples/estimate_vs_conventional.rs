//! The comparison of Sun et al. 2021 section 3.3 (correlation of estimated with measured
//! efficiency: 0.991 for the measured-input model, 0.925 for the conventional one) on
//! synthetic bench campaigns that trum did not make with the model it estimates with:
//! the bench motor is the nominal one with its uncertain parameters perturbed (3 %, the
//! feedback gain among them) and an unmodelled effect switched on in its truth form, and
//! every reading is noisy (`trum synth`'s bench, docs/SYNTH.md).
//!
//! For each case and seed: the efficiency readings of the campaign against
//! - the measured-input estimate (`trum_core::estimate`: amplitude from the feedback
//!   voltage, nominal motor), and
//! - the conventional model (`trum_core::solve` at the read operating point, nominal motor,
//!   its own simulated amplitude).
//!
//! Prints a Markdown table (docs/ESTIMATE.md): Pearson r and RMS error of each, averaged
//! over the seeds.
//!
//!     cargo run --release -p trum-core --example estimate_vs_conventional [-- SEEDS]

use trum_core::calibrate::Observable;
use trum_core::estimate::{Estimator, MeasuredPoint};
use trum_core::synth::{synthesize, Campaign, SynthConfig};
use trum_core::{presets, solve};

/// Pearson correlation of paired samples (NaN for fewer than 3 or a constant side).
fn pearson(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    if x.len() < 3 {
        return f64::NAN;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    if sxx <= 0.0 || syy <= 0.0 {
        return f64::NAN;
    }
    sxy / (sxx * syy).sqrt()
}

fn rms(x: &[f64], y: &[f64]) -> f64 {
    (x.iter().zip(y).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

struct Case {
    motor: &'static str,
    effect: &'static str,
    campaign: Campaign,
    voltage_v: f64,
    frequency_hz: f64,
}

fn main() {
    let seeds: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let g = |effect, campaign| Case { motor: "generic60", effect, campaign, voltage_v: 200.0, frequency_hz: 43_000.0 };
    let q = |effect, campaign| Case { motor: "trum60-qut", effect, campaign, voltage_v: 150.0, frequency_hz: 42_000.0 };
    let pt = Campaign::PreloadTorque;
    let cases = [
        g("", pt),
        g("voltage_sag=150", pt),
        g("voltage_sag=400", pt),
        g("radial_friction=1", pt),
        g("preload_stiffening=0.5", pt),
        g("hertz_softening=1e18", pt),
        g("tangential_compliance=1", pt),
        g("eccentricity=2e-5", pt),
        g("thermal_drift=-4e-4", Campaign::WarmUp),
        q("", pt),
        q("voltage_sag=150", pt),
        q("radial_friction=1", pt),
        q("preload_stiffening=0.5", pt),
    ];
    println!(
        "| motor | effect on the bench | campaign | rows | r measured-input | r conventional | RMS error measured-input | RMS error conventional |"
    );
    println!("|---|---|---|---:|---:|---:|---:|---:|");
    for c in cases {
        let nominal = presets::preset(c.motor).expect("preset");
        let mut bench = nominal.clone();
        if !c.effect.is_empty() {
            bench.effects.parse_assignment(c.effect).expect("effect");
        }
        let est = Estimator::new(&nominal).expect("estimator");
        let (mut r_mi, mut r_cv, mut e_mi, mut e_cv, mut rows) = (Vec::new(), Vec::new(), 0.0, 0.0, 0);
        for seed in 1..=seeds {
            let cfg = SynthConfig {
                campaign: c.campaign,
                seed,
                voltage_v: c.voltage_v,
                frequency_hz: c.frequency_hz,
                ..SynthConfig::default()
            };
            let data = synthesize(&bench, &cfg).expect("campaign");
            let (mut meas, mut mi, mut cv) = (Vec::new(), Vec::new(), Vec::new());
            for r in &data {
                let read = |o: Observable| r.readings.iter().find(|x| x.0 == o).map(|x| x.1);
                let (Some(eta), Some(vf)) = (read(Observable::Efficiency), read(Observable::FeedbackV)) else {
                    continue;
                };
                let e = est.estimate(&MeasuredPoint {
                    preload_n: r.op.preload_n,
                    voltage_v: r.op.voltage_v,
                    frequency_hz: r.op.frequency_hz,
                    torque_nm: r.op.torque_nm,
                    feedback_v: Some(vf),
                    speed_rpm: read(Observable::SpeedRpm),
                });
                let s = solve(&nominal, &r.op);
                // a row either model cannot give a number for counts as efficiency 0 for it
                let num = |v: f64, ok: bool| if ok && v.is_finite() { v } else { 0.0 };
                meas.push(eta);
                mi.push(num(e.efficiency, e.status.is_valid()));
                cv.push(num(s.efficiency, s.status.is_valid()));
            }
            rows += meas.len();
            r_mi.push(pearson(&mi, &meas));
            r_cv.push(pearson(&cv, &meas));
            e_mi += rms(&mi, &meas);
            e_cv += rms(&cv, &meas);
        }
        let mean = |v: &[f64]| {
            let ok: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            if ok.len() < v.len() {
                "n/a (constant)".to_string()
            } else {
                format!("{:.3}", ok.iter().sum::<f64>() / ok.len() as f64)
            }
        };
        let n = seeds as f64;
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.4} | {:.4} |",
            c.motor,
            if c.effect.is_empty() { "none" } else { c.effect },
            match c.campaign {
                Campaign::WarmUp => "warm-up",
                _ => "preload-torque",
            },
            rows / seeds as usize,
            mean(&r_mi),
            mean(&r_cv),
            e_mi / n,
            e_cv / n
        );
    }
}

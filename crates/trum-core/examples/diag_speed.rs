//! Diagnosis speed on a large data set (the target: 1000 rows, all seven
//! candidates, block cross-validation, under 2 s on 2 cores). Seven combined campaigns of
//! one motor (no parameter perturbation, so they agree; different noise seeds, each its
//! own bench session with its own run ids) give 980 rows.
//! Usage: `cargo run --release -p trum-core --example diag_speed [EFFECT]`.
use trum_core::synth::{synthesize, Campaign, SynthConfig};
use trum_core::*;

fn main() {
    let nominal = presets::preset("trum60a").expect("preset");
    let mut truth = nominal.clone();
    if let Some(name) = std::env::args().nth(1) {
        let e = effects::Effect::from_name(&name).expect("effect name");
        truth.effects.set_strength(e, e.info().params[0].typical);
    }
    let (mut rows, mut groups) = (Vec::new(), Vec::new());
    for seed in 0..7 {
        let cfg =
            SynthConfig { campaign: Campaign::Combined, seed: 40 + seed, perturbation: 0.0, ..SynthConfig::default() };
        for r in synthesize(&truth, &cfg).expect("synth") {
            rows.push(r.observed());
            groups.push(format!("{}-{seed}", r.run_id));
        }
    }
    let t0 = std::time::Instant::now();
    let d = diagnose::diagnose(&nominal, &rows, &groups, &diagnose::DiagnoseOptions::default()).expect("diagnosis");
    println!(
        "{} rows, {} readings: verdict {} in {:.2} s wall ({} rayon threads)",
        rows.len(),
        d.n_readings,
        d.verdict,
        t0.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
}

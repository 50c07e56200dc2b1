#![allow(clippy::unwrap_used)] // examples: developer tools, a panic is the error report
use trum_core::synth::*;
use trum_core::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let camp = Campaign::from_name(args.get(1).map(|s| s.as_str()).unwrap_or("preload-torque")).unwrap();
    let noise: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let only: Option<&str> = args.get(3).map(|s| s.as_str());
    let nominal = presets::preset("trum60a").unwrap();
    let mut cases: Vec<(String, Motor)> = vec![("none".into(), nominal.clone())];
    for e in effects::ALL {
        let mut m = nominal.clone();
        m.effects.set_strength(e, e.info().params[0].typical);
        cases.push((e.name().into(), m));
    }
    for (name, m) in cases {
        if let Some(o) = only {
            if o != name {
                continue;
            }
        }
        let t0 = std::time::Instant::now();
        let rows = synthesize(&m, &SynthConfig { campaign: camp, noise, seed: 3, ..Default::default() }).unwrap();
        let obs: Vec<_> = rows.iter().map(|r| r.observed()).collect();
        let groups: Vec<String> = rows.iter().map(|r| r.run_id.clone()).collect();
        let d = diagnose::diagnose(&nominal, &obs, &groups, &diagnose::DiagnoseOptions::default()).unwrap();
        println!(
            "{name:22} -> {:28} conf={:?} base={:.3} noise={:.3} z2={:.1} t={:.1}s rows={}",
            d.verdict,
            d.confounded_with,
            d.baseline_heldout_nrmse,
            d.noise_nrmse,
            d.baseline_heldout_chi2_per_reading,
            t0.elapsed().as_secs_f64(),
            rows.len()
        );
        for r in d.ranking.iter().take(4) {
            println!(
                "     {:40} ev={:8.1} after={:.3} shrink={:.2}",
                r.effect, r.evidence, r.heldout_nrmse_after, r.shrink
            );
        }
    }
}

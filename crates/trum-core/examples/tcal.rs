use trum_core::calibrate::*;
use trum_core::synth::*;
use trum_core::*;
fn main() {
    let nominal = presets::preset("trum60a").unwrap();
    let mut m = nominal.clone();
    m.effects.set_strength(Effect::RadialFriction, 1.0);
    let truth = std::env::args().nth(1).map(|s| s == "truth").unwrap_or(true);
    let rows = synthesize(
        &m,
        &SynthConfig {
            truth_forms: truth,
            perturbation: std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(0.03),
            ..SynthConfig::default()
        },
    )
    .unwrap();
    let obs: Vec<_> = rows.iter().map(|r| r.observed()).collect();
    let t0 = std::time::Instant::now();
    let r = residuals(&nominal, &obs);
    println!("baseline residual eval {:.3} ms ({} readings)", t0.elapsed().as_secs_f64() * 1e3, r.len());
    let t0 = std::time::Instant::now();
    let r = residuals(&m, &obs);
    println!(
        "radial residual eval {:.3} ms chi2={:.1}",
        t0.elapsed().as_secs_f64() * 1e3,
        r.iter().map(|x| x * x).sum::<f64>()
    );
    let t0 = std::time::Instant::now();
    let p = baseline_params(&nominal, &obs);
    let c = calibrate(&nominal, &obs, &p, &FitOptions { huber_k: 3.0, irls_passes: 1, max_evaluations: 120 }).unwrap();
    println!("baseline fit {:.3} s evals {} chi2 {:.1}", t0.elapsed().as_secs_f64(), c.evaluations, c.chi2);
    let mut start = c.motor.clone();
    start.effects.set(Effect::RadialFriction, &[0.5]);
    let mut p2 = p.clone();
    p2.extend(effect_params(Effect::RadialFriction));
    let t0 = std::time::Instant::now();
    let c2 = calibrate(&start, &obs, &p2, &FitOptions { huber_k: 3.0, irls_passes: 1, max_evaluations: 120 }).unwrap();
    println!("radial fit {:.3} s evals {} chi2 {:.1}", t0.elapsed().as_secs_f64(), c2.evaluations, c2.chi2);
    for p in &c2.params {
        println!("   {} = {:.4e} ± {:.2e} {} {}", p.name, p.value, p.std_error, p.at_bound, p.identifiable);
    }
    for w in &c2.warnings {
        println!("  W: {w}");
    }
}

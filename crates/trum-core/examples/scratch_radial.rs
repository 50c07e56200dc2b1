use trum_core::calibrate::*;
use trum_core::synth::*;
use trum_core::*;
fn main() {
    let nominal = presets::preset("trum60a").unwrap();
    let e = effects::Effect::from_name(&std::env::args().nth(1).unwrap_or("radial_friction".into())).unwrap();
    let s: f64 = std::env::args().nth(2).and_then(|x| x.parse().ok()).unwrap_or(1.0);
    let mut m = nominal.clone();
    m.effects.set_strength(e, s * e.info().params[0].typical);
    for truth in [true, false] {
        let rows = synthesize(&m, &SynthConfig { noise: 0.0, perturbation: 0.0, truth_forms: truth, ..Default::default() }).unwrap();
        let obs: Vec<_> = rows.iter().map(|r| r.observed()).collect();
        for st in [0.5, 1.0, 2.0] {
            let mut s0 = nominal.clone();
            s0.effects.set_strength(e, st * s * e.info().params[0].typical);
            let mut params = baseline_params(&nominal, &obs);
            params.extend(effect_params(e));
            let c = calibrate(&s0, &obs, &params, &FitOptions::default()).unwrap();
            println!("truth={truth} start={st} chi2={:.2} evals={} eff={:?}", c.chi2, c.evaluations, c.params.iter().map(|p| (p.name.clone(), p.value)).collect::<Vec<_>>());
        }
    }
}

//! Tests of the Hertzian oscillator. Tolerances are stated in each test and collected in
//! `docs/DYNAMICS.md`.
#![allow(clippy::unwrap_used)]

use super::ident::linear_stiffness_from_resonance_n_per_m;
use super::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn op200() -> OperatingPoint {
    OperatingPoint { voltage_v: 200.0, preload_n: 400.0 }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// (a) Multiple-scales (and harmonic-balance) amplitudes on stable branches versus the
/// steady state of the RK4 simulation started on the branch. Tolerance: MS 0.5 %, HB 0.3 %.
#[test]
fn multiple_scales_matches_time_simulation_on_stable_branches() {
    let o = HertzOscillator::default();
    let op = op200();
    let set = SimulationSettings::default();
    let freqs = [40_800.0, 40_880.0, 40_930.0, 40_960.0, 41_000.0, 41_100.0];
    let ms = o.frequency_response(&op, &freqs, ResponseMethod::MultipleScales).unwrap();
    let hb = o.frequency_response(&op, &freqs, ResponseMethod::HarmonicBalance).unwrap();
    assert_eq!(ms.len(), hb.len());
    let mut checked_upper = 0;
    let mut checked = 0;
    for (p, q) in ms.iter().zip(&hb) {
        assert_eq!(p.branch, q.branch);
        if !p.stable {
            assert_eq!(p.branch, Branch::Middle);
            continue;
        }
        let init = o.branch_state(&op, p).unwrap();
        let ss = o.steady_state(&op, p.frequency_hz, &init, 0.6, 40, &set).unwrap();
        let e_ms = rel(p.amplitude_m, ss.amplitude_m);
        let e_hb = rel(q.amplitude_m, ss.amplitude_m);
        assert!(e_ms < 5e-3, "MS {p:?} vs sim {} (rel {e_ms})", ss.amplitude_m);
        assert!(e_hb < 3e-3, "HB {q:?} vs sim {} (rel {e_hb})", ss.amplitude_m);
        assert!((p.phase_lag_rad - ss.phase_lag_rad).abs() < 0.02, "{p:?} vs {ss:?}");
        if p.branch == Branch::Upper {
            checked_upper += 1;
        }
        checked += 1;
    }
    assert!(checked >= 8 && checked_upper >= 3, "{checked} / {checked_upper}");
}

fn simulated_waveform(
    o: &HertzOscillator,
    op: &OperatingPoint,
    frequency_hz: f64,
    gain: f64,
) -> (Vec<f64>, Vec<f64>, f64) {
    let p = o
        .frequency_response(op, &[frequency_hz], ResponseMethod::MultipleScales)
        .unwrap()
        .into_iter()
        .max_by(|a, b| a.amplitude_m.total_cmp(&b.amplitude_m))
        .unwrap();
    let init = o.branch_state(op, &p).unwrap();
    let set = SimulationSettings::default();
    let settle = 0.6;
    let dur = settle + 40.0 / frequency_hz;
    let rec = RecordOptions { from_s: settle, stride: 2 };
    let ts = o.simulate_constant_frequency(op, frequency_hz, dur, &init, &rec, &set).unwrap();
    let v: Vec<f64> = ts.displacement_m.iter().map(|w| gain * w).collect();
    (ts.time_s, v, p.amplitude_m)
}

fn ident_input<'a>(
    o: &HertzOscillator,
    op: &OperatingPoint,
    t: &'a [f64],
    v: &'a [f64],
    f: f64,
    gain: f64,
) -> BetaIdentificationInput<'a> {
    BetaIdentificationInput {
        sample_times_s: t,
        samples_v: v,
        drive_frequency_hz: f,
        feedback_gain_v_per_m: gain,
        drive_force_amplitude_n: o.forcing_amplitude_n(op).unwrap(),
        static_force_n: Some(op.preload_n),
        modal_mass_kg: o.modal_mass_kg,
        damping_ns_per_m: o.damping_ns_per_m,
        linear_stiffness_n_per_m: o.linear_stiffness_n_per_m,
        harmonics: 3,
    }
}

/// (b) Simulate at known β (upper branch, 40.93 kHz, 200 V, 400 N), identify β back.
/// Tolerance: 1 % without noise (multi-harmonic and one-term), 2 % with 1 % RMS Gaussian
/// noise (seeded ChaCha8, seed 2022).
#[test]
fn identification_recovers_beta_from_simulated_feedback_voltage() {
    let o = HertzOscillator::default();
    let op = op200();
    let beta_true = o.beta_at_n_per_m3(&op).unwrap();
    let gain = 2.0e6; // V/m: 1 µm → 2 V on the isolated electrode (assumed)
    for f in [40_930.0, 41_000.0] {
        let (t, v, amp) = simulated_waveform(&o, &op, f, gain);
        let id = identify_beta(&ident_input(&o, &op, &t, &v, f, gain)).unwrap();
        assert!(rel(id.beta_n_per_m3, beta_true) < 0.01, "f={f}: {id:?} vs {beta_true}");
        assert!(rel(id.one_term_beta_n_per_m3, beta_true) < 0.01, "f={f}: {id:?}");
        assert!(id.harmonic_fit_r_squared > 0.999_999, "{id:?}");
        assert!(rel(id.displacement_amplitude_m, amp) < 5e-3);
        // Noisy copy: Gaussian (Box–Muller) noise of 1 % of the voltage amplitude.
        let mut rng = ChaCha8Rng::seed_from_u64(2022);
        let sigma = 0.01 * gain * amp;
        let vn: Vec<f64> = v
            .iter()
            .map(|x| {
                let u1: f64 = 1.0 - rng.random::<f64>();
                let u2: f64 = rng.random::<f64>();
                x + sigma * (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
            })
            .collect();
        let idn = identify_beta(&ident_input(&o, &op, &t, &vn, f, gain)).unwrap();
        assert!(rel(idn.beta_n_per_m3, beta_true) < 0.02, "f={f}: noisy {idn:?} vs {beta_true}");
        assert!(idn.harmonic_fit_r_squared < id.harmonic_fit_r_squared);
        assert!(idn.harmonic_fit_r_squared > 0.99);
    }
}

/// (c) Slow sweeps (25 Hz/s, about 3 % of the bandwidth per time constant) reproduce the
/// predicted jump-up / jump-down frequencies within 5 Hz (4 % of the 121 Hz hysteresis
/// width) and show hysteresis: at 40.93 kHz the up-sweep is on the lower branch and the
/// down-sweep on the upper branch (amplitudes within 2 % of the MS branches).
#[test]
fn slow_sweeps_reproduce_jumps_and_hysteresis() {
    let o = HertzOscillator::default();
    let op = op200();
    let set = SimulationSettings::default();
    let jumps = o.jump_frequencies(&op, ResponseMethod::MultipleScales).unwrap().unwrap();
    assert!(jumps.jump_up_hz > jumps.jump_down_hz + 100.0, "softening: {jumps:?}");
    let rate = 25.0;
    let sweep = |f0: f64, f1: f64, pick_upper: bool| {
        let pts = o.frequency_response(&op, &[f0], ResponseMethod::MultipleScales).unwrap();
        let p = if pick_upper { pts[pts.len() - 1] } else { pts[0] };
        let init = o.branch_state(&op, &p).unwrap();
        let fs = FrequencySweep { start_hz: f0, end_hz: f1, duration_s: (f1 - f0).abs() / rate };
        o.simulate_sweep(&op, &fs, &init, 20, &set).unwrap()
    };
    let up = sweep(40_900.0, 41_010.0, false);
    let down = sweep(40_960.0, 40_840.0, true);
    let j_up = find_jump(&up, true).unwrap();
    let j_down = find_jump(&down, false).unwrap();
    assert!((j_up.frequency_hz - jumps.jump_up_hz).abs() < 5.0, "{j_up:?} vs {jumps:?}");
    assert!((j_down.frequency_hz - jumps.jump_down_hz).abs() < 5.0, "{j_down:?} vs {jumps:?}");
    assert!(j_up.amplitude_after_m > j_up.amplitude_before_m);
    assert!(j_down.amplitude_after_m < j_down.amplitude_before_m);
    // Hysteresis at a frequency inside the bistable band.
    let at = |pts: &[SweepPoint], f: f64| {
        pts.iter().min_by(|a, b| (a.frequency_hz - f).abs().total_cmp(&(b.frequency_hz - f).abs())).unwrap().amplitude_m
    };
    let branches = o.frequency_response(&op, &[40_930.0], ResponseMethod::MultipleScales).unwrap();
    assert_eq!(branches.len(), 3);
    let (a_up, a_down) = (at(&up, 40_930.0), at(&down, 40_930.0));
    assert!(rel(a_up, branches[0].amplitude_m) < 0.02, "{a_up} vs {:?}", branches[0]);
    assert!(rel(a_down, branches[2].amplitude_m) < 0.02, "{a_down} vs {:?}", branches[2]);
    assert!(a_down > 10.0 * a_up);
}

/// (d) β = 0: harmonic balance is the exact linear FRF (1e-12 relative), multiple scales
/// is its first-order form, one branch everywhere, no jumps, vertical backbone, and the
/// simulation reproduces the linear steady state within 0.3 %.
#[test]
fn beta_zero_reduces_to_linear_resonance() {
    let o = HertzOscillator { beta_n_per_m3: 0.0, ..HertzOscillator::default() };
    let op = op200();
    let m = o.modal_mass_kg;
    let c = o.damping_ns_per_m;
    let k = o.linear_stiffness_n_per_m;
    let f_force = o.forcing_amplitude_n(&op).unwrap();
    let eff = o.effective(&op).unwrap();
    assert_eq!(eff.static_deflection_m, op.preload_n / k);
    assert_eq!(eff.stiffness_n_per_m, k);
    assert_eq!(eff.equivalent_beta_n_per_m3, 0.0);
    let f0 = o.linear_resonance_hz();
    let w0 = 2.0 * std::f64::consts::PI * f0;
    let freqs: Vec<f64> = (0..41).map(|i| f0 - 200.0 + 10.0 * i as f64).collect();
    let hb = o.frequency_response(&op, &freqs, ResponseMethod::HarmonicBalance).unwrap();
    let ms = o.frequency_response(&op, &freqs, ResponseMethod::MultipleScales).unwrap();
    assert_eq!(hb.len(), freqs.len());
    assert_eq!(ms.len(), freqs.len());
    for ((p, q), &f) in hb.iter().zip(&ms).zip(&freqs) {
        let w = 2.0 * std::f64::consts::PI * f;
        let exact = f_force / ((k - m * w * w).powi(2) + (c * w).powi(2)).sqrt();
        assert!(rel(p.amplitude_m, exact) < 1e-12, "{p:?} vs {exact}");
        let phase = (c * w).atan2(k - m * w * w);
        assert!((p.phase_lag_rad - phase).abs() < 1e-9);
        let mu = c / (2.0 * m);
        let ms_exact = f_force / (2.0 * m * w0) / (mu * mu + (w - w0).powi(2)).sqrt();
        assert!(rel(q.amplitude_m, ms_exact) < 1e-12);
        assert!(p.stable && q.stable && p.branch == Branch::Single);
    }
    // Peak of the MS response at f0 equals F/(c ω0) exactly.
    let peak = o.frequency_response(&op, &[f0], ResponseMethod::MultipleScales).unwrap()[0];
    assert!(rel(peak.amplitude_m, f_force / (c * w0)) < 1e-12);
    assert!(o.jump_frequencies(&op, ResponseMethod::MultipleScales).unwrap().is_none());
    assert!(o.jump_frequencies(&op, ResponseMethod::HarmonicBalance).unwrap().is_none());
    assert!(o.jump_frequencies_closed_form(&op).unwrap().is_none());
    for method in [ResponseMethod::MultipleScales, ResponseMethod::HarmonicBalance] {
        for b in o.backbone(&op, &[0.0, 1e-6, 3e-6], method).unwrap() {
            assert!(rel(b.frequency_hz, f0) < 1e-14);
        }
    }
    let set = SimulationSettings::default();
    let init = o.branch_state(&op, &hb[25]).unwrap();
    let ss = o.steady_state(&op, freqs[25], &init, 0.6, 40, &set).unwrap();
    assert!(rel(ss.amplitude_m, hb[25].amplitude_m) < 3e-3, "{ss:?} vs {:?}", hb[25]);
    assert!(rel(ss.mean_m, op.preload_n / k) < 1e-3);
}

/// Closed-form MS saddle nodes equal the discriminant root finding (1e-6 Hz), the
/// response has 3 roots strictly inside the band and 1 outside, and HB agrees with MS
/// within 2 Hz at 200 V.
#[test]
fn jump_points_closed_form_matches_discriminant_and_root_count() {
    let o = HertzOscillator::default();
    for v in [100.0, 200.0, 300.0] {
        let op = OperatingPoint { voltage_v: v, preload_n: 400.0 };
        let a = o.jump_frequencies(&op, ResponseMethod::MultipleScales).unwrap().unwrap();
        let b = o.jump_frequencies_closed_form(&op).unwrap().unwrap();
        assert!((a.jump_up_hz - b.jump_up_hz).abs() < 1e-6, "{a:?} {b:?}");
        assert!((a.jump_down_hz - b.jump_down_hz).abs() < 1e-6, "{a:?} {b:?}");
        assert!(rel(a.jump_up_amplitude_m, b.jump_up_amplitude_m) < 1e-6);
        assert!(rel(a.jump_down_amplitude_m, b.jump_down_amplitude_m) < 1e-6);
        let inside = 0.5 * (a.jump_up_hz + a.jump_down_hz);
        let count = |f: f64| o.frequency_response(&op, &[f], ResponseMethod::MultipleScales).unwrap().len();
        assert_eq!(count(inside), 3);
        assert_eq!(count(a.jump_up_hz + 0.5), 1);
        assert_eq!(count(a.jump_down_hz - 0.5), 1);
        let pts = o.frequency_response(&op, &[inside], ResponseMethod::MultipleScales).unwrap();
        assert_eq!(pts.iter().map(|p| p.stable).collect::<Vec<_>>(), vec![true, false, true]);
    }
    let op = op200();
    let ms = o.jump_frequencies(&op, ResponseMethod::MultipleScales).unwrap().unwrap();
    let hb = o.jump_frequencies(&op, ResponseMethod::HarmonicBalance).unwrap().unwrap();
    assert!((ms.jump_down_hz - hb.jump_down_hz).abs() < 2.0 && (ms.jump_up_hz - hb.jump_up_hz).abs() < 2.0);
}

/// Softening: backbone frequency decreases with amplitude; the resonance shift and the
/// hysteresis band grow with voltage and with preload (the Hertzian driving-circuit paper (2022) Fig. 11).
#[test]
fn softening_trends_with_voltage_and_preload() {
    let o = HertzOscillator::default();
    let bb = o.backbone(&op200(), &[0.0, 1e-6, 2e-6], ResponseMethod::MultipleScales).unwrap();
    assert!(bb[0].frequency_hz > bb[1].frequency_hz && bb[1].frequency_hz > bb[2].frequency_hz);
    let freqs: Vec<f64> = (0..50).map(|i| 40_500.0 + 12.0 * i as f64).collect();
    let by_v = o.response_vs_voltage(400.0, &[100.0, 200.0, 300.0], &freqs, ResponseMethod::MultipleScales).unwrap();
    let by_n = o.response_vs_preload(200.0, &[200.0, 300.0, 400.0], &freqs, ResponseMethod::MultipleScales).unwrap();
    for fam in [&by_v, &by_n] {
        let downs: Vec<f64> = fam.iter().map(|c| c.jumps.unwrap().jump_down_hz).collect();
        let widths: Vec<f64> =
            fam.iter().map(|c| c.jumps.unwrap().jump_up_hz - c.jumps.unwrap().jump_down_hz).collect();
        assert!(downs[0] > downs[1] && downs[1] > downs[2], "{downs:?}");
        assert!(widths[0] < widths[1] && widths[1] < widths[2], "{widths:?}");
        let peaks: Vec<f64> = fam.iter().map(|c| c.points.iter().map(|p| p.amplitude_m).fold(0.0, f64::max)).collect();
        assert!(peaks[0] < peaks[1] && peaks[1] < peaks[2], "{peaks:?}");
    }
    // Default amplitudes: about 1 - 3 µm at 100 - 300 V (400 N).
    let a100 = by_v[0].jumps.unwrap().jump_down_amplitude_m;
    let a300 = by_v[2].jumps.unwrap().jump_down_amplitude_m;
    assert!(a100 > 0.8e-6 && a100 < 1.3e-6 && a300 > 2.3e-6 && a300 < 3.0e-6, "{a100} {a300}");
    let f0 = o.linear_resonance_hz();
    assert!((40_000.0..43_000.0).contains(&f0));
}

/// (e) Bad inputs give errors, never panics.
#[test]
fn bad_inputs_give_errors() {
    let o = HertzOscillator::default();
    let op = op200();
    let set = SimulationSettings::default();
    // Parameters.
    let bad = HertzOscillator { modal_mass_kg: -1.0, ..HertzOscillator::default() };
    assert!(matches!(bad.effective(&op), Err(HertzError::InvalidParameter { .. })));
    let bad = HertzOscillator { beta_n_per_m3: f64::NAN, ..HertzOscillator::default() };
    assert!(bad.validate().is_err());
    assert!(o.beta_at_n_per_m3(&OperatingPoint { voltage_v: -1.0, preload_n: 400.0 }).is_err());
    assert!(o.frequency_response(&op, &[f64::NAN], ResponseMethod::MultipleScales).is_err());
    assert!(o.frequency_response(&op, &[0.0], ResponseMethod::HarmonicBalance).is_err());
    assert!(o.backbone(&op, &[-1e-6], ResponseMethod::MultipleScales).is_err());
    assert!(HertzOscillator::with_linear_resonance_hz(-5.0).is_err());
    assert!(matches!(static_deflection_m(1e9, -1e19, 1e9), Err(HertzError::NoStaticEquilibrium { .. })));
    assert!(matches!(
        o.effective(&OperatingPoint { voltage_v: 200.0, preload_n: 1e7 }),
        Err(HertzError::NoStaticEquilibrium { .. })
    ));
    // Unknown fields are rejected by serde.
    let toml_ok = toml::to_string(&o).unwrap();
    assert_eq!(toml::from_str::<HertzOscillator>(&toml_ok).unwrap(), o);
    assert!(toml::from_str::<HertzOscillator>(&format!("{toml_ok}\nextra = 1.0\n")).is_err());
    // Simulation.
    let s0 = OscillatorState::default();
    let few = SimulationSettings { steps_per_period: 8, ..set };
    assert!(o.steady_state(&op, 41_000.0, &s0, 0.01, 4, &few).is_err());
    let tiny = SimulationSettings { max_steps: 1000, ..set };
    assert!(matches!(o.steady_state(&op, 41_000.0, &s0, 1.0, 4, &tiny), Err(HertzError::TooManySteps { .. })));
    assert!(o.simulate_constant_frequency(&op, 41_000.0, f64::INFINITY, &s0, &RecordOptions::default(), &set).is_err());
    let rec0 = RecordOptions { from_s: 0.0, stride: 0 };
    assert!(o.simulate_constant_frequency(&op, 41_000.0, 1e-3, &s0, &rec0, &set).is_err());
    let nan_state = OscillatorState { displacement_m: f64::NAN, velocity_m_per_s: 0.0 };
    assert!(o.steady_state(&op, 41_000.0, &nan_state, 0.0, 4, &set).is_err());
    let sw = FrequencySweep { start_hz: 41_000.0, end_hz: -1.0, duration_s: 1.0 };
    assert!(o.simulate_sweep(&op, &sw, &s0, 10, &set).is_err());
    // Escape over the softening barrier: a huge drive force diverges.
    let strong = HertzOscillator { force_factor_n_per_v: 1e4, ..HertzOscillator::default() };
    assert!(matches!(strong.steady_state(&op, 40_000.0, &s0, 0.01, 4, &set), Err(HertzError::Diverged { .. })));
    assert!(find_jump(&[], true).is_none());
    // Identification.
    let f = 41_000.0;
    let gain = 2.0e6;
    let n = 400;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / (32.0 * f)).collect();
    let v: Vec<f64> = t.iter().map(|x| (2.0 * std::f64::consts::PI * f * x).cos()).collect();
    let base = ident_input(&o, &op, &t, &v, f, gain);
    assert!(identify_beta(&base).is_ok());
    let short = BetaIdentificationInput { sample_times_s: &t[..64], samples_v: &v[..64], ..base };
    assert!(matches!(identify_beta(&short), Err(HertzError::TooShort { .. })));
    let mut vn = v.clone();
    vn[17] = f64::NAN;
    assert!(matches!(
        identify_beta(&BetaIdentificationInput { samples_v: &vn, ..base }),
        Err(HertzError::NonFinite { index: 17, .. })
    ));
    assert!(matches!(
        identify_beta(&BetaIdentificationInput { samples_v: &v[..100], ..base }),
        Err(HertzError::LengthMismatch { .. })
    ));
    let mut tn = t.clone();
    tn.swap(10, 11);
    assert!(matches!(
        identify_beta(&BetaIdentificationInput { sample_times_s: &tn, ..base }),
        Err(HertzError::NonMonotonicTime { .. })
    ));
    // Not periodic at the drive frequency: a decaying transient and an off-frequency tone.
    let v_decay: Vec<f64> =
        t.iter().map(|x| (-x * 3000.0).exp() * (2.0 * std::f64::consts::PI * f * x).cos()).collect();
    assert!(matches!(
        identify_beta(&BetaIdentificationInput { samples_v: &v_decay, ..base }),
        Err(HertzError::NonPeriodic { .. })
    ));
    let v_off: Vec<f64> = t.iter().map(|x| (2.0 * std::f64::consts::PI * 0.61 * f * x).cos()).collect();
    assert!(matches!(
        identify_beta(&BetaIdentificationInput { samples_v: &v_off, ..base }),
        Err(HertzError::NonPeriodic { .. })
    ));
    let sparse: Vec<f64> = (0..400).map(|i| i as f64 / (4.0 * f)).collect();
    assert!(matches!(
        identify_beta(&BetaIdentificationInput { sample_times_s: &sparse, ..base }),
        Err(HertzError::TooShort { .. })
    ));
    assert!(identify_beta(&BetaIdentificationInput { feedback_gain_v_per_m: 0.0, ..base }).is_err());
    assert!(identify_beta(&BetaIdentificationInput { harmonics: 0, ..base }).is_err());
    assert!(identify_beta(&BetaIdentificationInput { drive_frequency_hz: f64::NAN, ..base }).is_err());
    let zeros = vec![0.0; n];
    assert!(identify_beta(&BetaIdentificationInput { samples_v: &zeros, ..base }).is_err());
    assert!(linear_stiffness_from_resonance_n_per_m(0.05, -1.0).is_err());
}

/// Parameters by name (the CLI's `--oscillator` file and Python's dict): an invalid value
/// is refused and changes nothing; the family keeps points without a static equilibrium
/// as errors; the default band holds every jump of the family.
#[test]
fn parameters_by_name_family_and_band() {
    let mut o = HertzOscillator::default();
    assert_eq!(o.set_param("damping_ns_per_m", 2.0), Ok(true));
    assert_eq!(o.damping_ns_per_m, 2.0);
    assert!(matches!(
        o.set_param("modal_mass_kg", -1.0),
        Err(HertzError::InvalidParameter { name: "modal_mass_kg", .. })
    ));
    assert_eq!(o.modal_mass_kg, HertzOscillator::default().modal_mass_kg);
    assert_eq!(o.set_param("modal_mass", 1.0), Ok(false));
    for k in HertzOscillator::PARAM_KEYS {
        assert!(HertzOscillator::default().param_mut(k).is_some(), "{k}");
    }
    let o = HertzOscillator::default();
    let ops: Vec<OperatingPoint> =
        [100.0, 200.0, 300.0].iter().map(|&v| OperatingPoint { voltage_v: v, preload_n: 400.0 }).collect();
    let (lo, hi) = o.response_band_hz(&ops, ResponseMethod::MultipleScales).unwrap();
    for op in &ops {
        let j = o.jump_frequencies(op, ResponseMethod::MultipleScales).unwrap().unwrap();
        assert!(lo < j.jump_down_hz && j.jump_up_hz < hi, "{j:?} outside {lo}..{hi}");
    }
    let mut with_bad = ops.clone();
    with_bad.push(OperatingPoint { voltage_v: 200.0, preload_n: 1e6 });
    let fam = o.response_family(&with_bad, &[40_900.0, 41_000.0], ResponseMethod::MultipleScales).unwrap();
    assert_eq!(fam.len(), 4);
    assert!(matches!(fam[3].response, Err(HertzError::NoStaticEquilibrium { .. })) && fam[3].backbone.is_empty());
    let bb = &fam[1].backbone;
    assert_eq!(bb.len(), 101);
    assert_eq!(bb[0].amplitude_m, 0.0);
    assert!(o.response_family(&ops, &[0.0], ResponseMethod::MultipleScales).is_err());
}

/// The oscillator of a motor is that motor: its linear resonance is the free stator's
/// `resonance_frequency_hz`, the linear peak is the modal force over c·ω at resonance,
/// and `hertz_softening`'s β(N) = −β0·(1 + g·N) is met at the reference preload with
/// its slope; without the effect the oscillator is linear.
#[test]
fn the_oscillator_of_a_motor_has_the_motors_modal_parameters() {
    let mut motor = crate::presets::preset("trum60a").unwrap();
    let o = HertzOscillator::from_motor(&motor);
    let st = &motor.stator;
    assert_eq!(o.beta_n_per_m3, 0.0);
    let op = OperatingPoint { voltage_v: 1.0, preload_n: 250.0 };
    let eff = o.effective(&op).unwrap();
    assert!(rel(eff.linear_resonance_hz(), st.resonance_frequency_hz) < 1e-12, "{}", eff.linear_resonance_hz());
    let f_r = st.resonance_frequency_hz;
    let freqs: Vec<f64> = (0..2001).map(|i| f_r - 200.0 + 0.2 * i as f64).collect();
    let r = o.frequency_response(&op, &freqs, ResponseMethod::HarmonicBalance).unwrap();
    let peak = r.iter().map(|p| p.amplitude_m).fold(0.0, f64::max);
    let force = st.force_factor_n_per_v * op.voltage_v + o.dynamic_contact_coefficient * op.preload_n;
    let want = force / (st.modal_damping_ns_per_m * 2.0 * PI * f_r);
    assert!(rel(peak, want) < 1e-4, "peak {peak} vs F/(c w) {want}");
    // β from hertz_softening: value and logarithmic slope at the reference preload
    motor.effects.parse_assignment("hertz_softening:beta_n_per_m3=2e18,preload_gain_per_n=0.005").unwrap();
    let o = HertzOscillator::from_motor(&motor);
    let beta = |n: f64| o.beta_at_n_per_m3(&OperatingPoint { voltage_v: 200.0, preload_n: n }).unwrap();
    let truth = |n: f64| -2e18 * (1.0 + 0.005 * n);
    let n_ref = o.reference_preload_n;
    assert!(rel(beta(n_ref), truth(n_ref)) < 1e-12);
    let slope = |f: &dyn Fn(f64) -> f64| (f(n_ref * 1.001) - f(n_ref * 0.999)) / (0.002 * n_ref);
    assert!(rel(slope(&beta), slope(&truth)) < 1e-5);
    // and the voltage does not change it
    assert_eq!(o.beta_at_n_per_m3(&OperatingPoint { voltage_v: 50.0, preload_n: n_ref }).unwrap(), beta(n_ref));
}

//! The blind benchmark of the diagnosis (docs/DIAGNOSIS.md), shared by the full run
//! (`cargo bench --bench blind`) and its fast slices in the test suite
//! (`tests/blind_slice.rs`).
//!
//! Each case goes through the file interface exactly as outside data would: `trum synth`
//! writes a measurement CSV with the injected effects in their truth forms (which differ
//! in form from the candidates the diagnosis fits), and `trum diagnose --json` reads only
//! that CSV and the nominal motor file. Nothing else passes between the two.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Nominal motor of every case: a frozen copy of the TRUM60A preset's values, so that a
/// change of the built-in preset does not move the benchmark.
pub const MOTOR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/motors/ring60.toml");

/// The nominal motor.
pub fn nominal() -> trum_core::Motor {
    let text = std::fs::read_to_string(MOTOR).expect("reference motor file");
    trum_core::Motor::from_toml_str(&text, MOTOR).expect("reference motor")
}

/// Which half of the benchmark a case belongs to: the development half (first truth
/// forms, development artefacts), on which the diagnosis may be tuned, or the held-out
/// half (second truth forms, other artefacts), which no tuning touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Half {
    /// Truth forms and artefacts the diagnosis was developed on.
    Dev,
    /// Truth forms and artefacts kept out of every tuning loop.
    HeldOut,
    /// The earlier design: first truth forms, no artefacts.
    Plain,
}

/// Bench artefacts of the development half (`trum synth --artefacts`).
pub const DEV_ARTEFACTS: &str = "readback_rel=0.004,speed_std_floor_rpm=0.3,outlier_fraction=0.01";

/// Bench artefacts of the held-out half: other levels, and a quantised speed and a torque
/// zero offset, which the development half never shows.
pub const HELDOUT_ARTEFACTS: &str =
    "readback_rel=0.006,speed_std_floor_rpm=0.5,speed_quantum_rpm=0.5,torque_offset_nm=0.002,outlier_fraction=0.005";

/// One blind case: injected effects with their strength factor (× the typical strength,
/// applied to every parameter of the effect), campaign, noise level, seed and half.
#[derive(Clone, Debug)]
pub struct Case {
    pub effects: Vec<&'static str>,
    pub factor: f64,
    pub campaign: &'static str,
    pub noise: f64,
    pub seed: u64,
    pub half: Half,
}

impl Case {
    /// Injected effects as the verdict would name them (`none` when empty).
    pub fn truth(&self) -> String {
        if self.effects.is_empty() {
            "none".into()
        } else {
            self.effects.join("+")
        }
    }

    /// `--effect` arguments of `trum synth`: every parameter at `factor` × typical.
    pub fn effect_args(&self) -> Vec<String> {
        let mut out = Vec::new();
        for name in &self.effects {
            let e = trum_core::effects::Effect::from_name(name).expect("effect name");
            let kv: Vec<String> =
                e.info().params.iter().map(|p| format!("{}={:e}", p.name, strength(p, self.factor))).collect();
            out.push("--effect".into());
            out.push(format!("{name}:{}", kv.join(",")));
        }
        out
    }

    /// `trum synth` arguments of the case's half: truth-form family and artefacts.
    pub fn half_args(&self) -> Vec<String> {
        match self.half {
            Half::Plain => vec![],
            Half::Dev => vec!["--artefacts".into(), DEV_ARTEFACTS.into()],
            Half::HeldOut => vec!["--truth-forms-b".into(), "--artefacts".into(), HELDOUT_ARTEFACTS.into()],
        }
    }

    /// The synth configuration of the case (noise level `noise`).
    fn synth_config(&self, noise: f64) -> trum_core::synth::SynthConfig {
        use trum_core::synth::{Artefacts, Campaign, SynthConfig};
        let artefacts = match self.half {
            Half::Plain => Artefacts::default(),
            Half::Dev => Artefacts::parse(DEV_ARTEFACTS).expect("artefacts"),
            Half::HeldOut => Artefacts::parse(HELDOUT_ARTEFACTS).expect("artefacts"),
        };
        SynthConfig {
            campaign: Campaign::from_name(self.campaign).expect("campaign"),
            noise,
            seed: self.seed,
            truth_form_b: self.half == Half::HeldOut,
            artefacts,
            ..SynthConfig::default()
        }
    }

    /// The nominal motor with `names` injected at the case's strength (truth forms; the
    /// truth forms ignore shape parameters, which the form-error fits start mid-range).
    fn motor_with(&self, names: &[&str]) -> trum_core::Motor {
        let mut m = nominal();
        for name in names {
            let e = trum_core::effects::Effect::from_name(name).expect("effect name");
            let v: Vec<f64> = e.info().params.iter().map(|p| strength(p, self.factor)).collect();
            m.effects.set(e, &v);
        }
        m
    }

    /// Signal of one injected effect in units of the bench noise: the χ² that remains when
    /// the baseline (without effects) is calibrated to the campaign's noise-free readings
    /// with that effect, σ being the synth noise at the case's level. It counts only what
    /// no baseline parameter can mimic. Below 25 (a 5σ total signal) no diagnosis can be
    /// expected to see the effect; a time-series effect in a campaign without time gives 0.
    pub fn signal_chi2(&self, name: &str) -> f64 {
        self.leftover_chi2(&[name], &[])
    }

    /// χ² left when the baseline plus the candidate forms of `fitted` (strengths free, from
    /// their true values) is calibrated to the noise-free readings of the motor with
    /// `injected` in their truth forms, σ as in [`Case::signal_chi2`]. Starts at the true
    /// baseline parameters: the best any calibration could do.
    fn leftover_chi2(&self, injected: &[&str], fitted: &[&str]) -> f64 {
        use trum_core::calibrate::{baseline_params, effect_params, Calibration, FitOptions, ObservedRow};
        use trum_core::synth::{reading_noise, synthesize, true_motor, Artefacts};
        // The effect's signal in the readings as the bench's instruments show them without
        // noise: their deterministic artefacts (a floor, offsets, a gain, a lag) are kept,
        // for a floor can hide a small spread and an offset can mimic a shift, and the
        // calibration below frees the same bench nuisances the diagnosis does. The random
        // ones (read-back noise, quantisation, outliers) are noise, not signal.
        let mut cfg = self.synth_config(0.0);
        cfg.artefacts = Artefacts { readback_rel: 0.0, speed_quantum_rpm: 0.0, outlier_fraction: 0.0, ..cfg.artefacts };
        let rows: Vec<ObservedRow> = synthesize(&self.motor_with(injected), &cfg)
            .expect("synth")
            .iter()
            .map(|r| ObservedRow {
                op: r.op,
                readings: r
                    .readings
                    .iter()
                    .map(|&(o, v)| (o, v, (self.noise * reading_noise(o, v)).max(1e-12)))
                    .collect(),
                ambient_c: r.ambient_c,
                speed_std_clipped: false,
            })
            .collect();
        let mut start = true_motor(&self.motor_with(fitted), &cfg);
        start.effects.set_truth_forms(false);
        // the floor's square root is not convex in it: start at the true one
        start.effects.instrument_mut().speed_std_floor_rpm = cfg.artefacts.speed_std_floor_rpm;
        let mut params = baseline_params(&nominal(), &rows);
        for name in fitted {
            params.extend(effect_params(trum_core::effects::Effect::from_name(name).expect("effect name")));
        }
        // a generous budget: this is the reference the verdicts are judged against
        let opts = FitOptions { huber_k: f64::INFINITY, irls_passes: 0, max_evaluations: 4000, fold_rtol: 0.0 };
        Calibration::builder(&start, &rows).params(&params).options(&opts).run().map(|c| c.chi2).unwrap_or(f64::NAN)
    }

    /// Held-out NRMSE of the true motor itself (the injected effects in their truth forms,
    /// the synthesised perturbation of its parameters, at the recorded operating points)
    /// on the case's data `rows`, scaled per quantity like the diagnosis's (`scale`): what
    /// a model without any error scores. Every reading is held out of some fold, and the
    /// true motor has nothing to fit, so `1 − oracle/before` is the most any diagnosis can
    /// shrink the spec's gap on this case.
    pub fn oracle_nrmse(
        &self,
        rows: &[trum_core::calibrate::ObservedRow],
        scale: &BTreeMap<trum_core::calibrate::Observable, f64>,
    ) -> f64 {
        let cfg = self.synth_config(self.noise);
        let truth = trum_core::synth::true_motor(&self.motor_with(&self.effects), &cfg);
        // residuals are (prediction − reading)/σ; a point without a solution counts 50 σ
        let z = trum_core::calibrate::residuals(&truth, rows);
        let sigmas = rows.iter().flat_map(|r| r.readings.iter().map(|x| (x.0, x.2)));
        let sum: f64 = z.iter().zip(sigmas).map(|(z, (o, s))| (z * s / scale[&o]).powi(2)).sum();
        (sum / z.len().max(1) as f64).sqrt()
    }

    /// χ² the candidate forms of the injected effects leave on the noise-free readings of
    /// their truth forms (strengths and baseline free): the form error no fit can remove.
    pub fn form_error_chi2(&self) -> f64 {
        self.leftover_chi2(&self.effects, &self.effects)
    }

    /// Signal of each injected effect. For a single effect its [`Case::signal_chi2`]; in a
    /// combination, what the effect adds beyond the others: the χ² the others' candidates
    /// leave minus the χ² all candidates together leave (0 when its own signal is below
    /// 25). An effect another one (or the others' form error) swamps cannot be expected.
    pub fn signals(&self) -> Vec<f64> {
        let own: Vec<f64> = self.effects.iter().map(|e| self.signal_chi2(e)).collect();
        if self.effects.len() < 2 {
            return own;
        }
        let all = self.leftover_chi2(&self.effects, &self.effects);
        self.effects
            .iter()
            .zip(&own)
            .map(|(e, &s)| {
                if s < 25.0 {
                    return s;
                }
                let others: Vec<&str> = self.effects.iter().copied().filter(|o| o != e).collect();
                (self.leftover_chi2(&self.effects, &others) - all).max(0.0).min(s)
            })
            .collect()
    }

    /// The injected effects the campaign can show (signal χ² ≥ 25, given each effect's
    /// signal in `signal`), as a verdict would name them: `none` when there are none.
    pub fn expected(&self, signal: &[f64]) -> String {
        // a NaN signal (the reference fit failed) must count as visible
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        let seen: Vec<&str> = self.effects.iter().zip(signal).filter(|(_, s)| !(**s < 25.0)).map(|(e, _)| *e).collect();
        if seen.is_empty() {
            "none".into()
        } else {
            seen.join("+")
        }
    }
}

/// What the diagnosis said about a case.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub case: Case,
    /// What a perfect diagnosis would say (crate `Case::expected`).
    pub expected: String,
    /// Signal χ² of each injected effect.
    pub signal: Vec<f64>,
    pub verdict: String,
    /// The JSON's `complete`.
    pub complete: bool,
    pub confounded: Vec<String>,
    /// With an `unexplained` verdict, the supported effect the diagnosis says explains part
    /// of the gap (the JSON's `partial`).
    pub partial: Option<String>,
    /// Held-out shrink of the expected (visible injected) effect(s), if ranked.
    pub true_shrink: Option<f64>,
    /// The same on the gap beyond noise: 1 − √(after² − noise²)/√(before² − noise²) in
    /// NRMSE (the spec's shrink cannot exceed 1 − noise/before when the gap is small).
    pub true_excess_shrink: Option<f64>,
    /// The spec's shrink of the true motor itself ([`Case::oracle_nrmse`]): the most any
    /// diagnosis could reach on this case.
    pub oracle_shrink: f64,
    /// Held-out shrink of the verdict's entry.
    pub verdict_shrink: Option<f64>,
    pub baseline_nrmse: f64,
    pub noise_nrmse: f64,
    pub rows: usize,
    pub seconds: f64,
}

use trum_core::diagnose::same_set;

impl Outcome {
    /// The verdict names the injected effect(s) exactly (`none` for a null case; also for an
    /// effect the campaign cannot show).
    pub fn correct(&self) -> bool {
        same_set(&self.verdict, &self.expected)
    }

    /// The expected single effect is the verdict or inside the reported confounded set.
    pub fn correct_or_confounded(&self) -> bool {
        self.correct() || (!self.expected.contains('+') && self.confounded.contains(&self.expected))
    }

    /// Some injected effect is visible in the data.
    pub fn observable(&self) -> bool {
        self.expected != "none"
    }

    /// The verdict is `unexplained` and names the expected single effect as the part of the
    /// gap it explains: not counted as correct (the spec's criterion is the verdict or the
    /// confounded set), reported beside it.
    pub fn unexplained_naming_truth(&self) -> bool {
        self.verdict == "unexplained" && self.partial.as_deref() == Some(self.expected.as_str())
    }

    /// An effect was claimed where none was injected.
    pub fn false_claim(&self) -> bool {
        self.case.effects.is_empty() && self.verdict != "none"
    }
}

/// Runs the CLI in-process; panics with its stderr when it fails (a benchmark bug).
fn trum(args: &[String]) -> String {
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let argv = std::iter::once("trum".to_string()).chain(args.iter().cloned());
    let code = trum_cli::run_with_io(argv, &mut out, &mut err);
    assert_eq!(code, 0, "trum {}: {}", args.join(" "), String::from_utf8_lossy(&err));
    String::from_utf8_lossy(&out).into_owned()
}

/// When set, every case's file loses its `run_id` column and has its rows in a
/// pseudo-random order before the diagnosis reads it (`cargo bench --bench blind --
/// --bare`): data laid out as a designed experiment without run names would be.
pub static BARE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Rewrites the synthesised CSV at `path` without its `run_id` column and with its rows
/// permuted by a generator seeded with `seed`.
fn strip_runs_and_shuffle(path: &std::path::Path, seed: u64) {
    let text = std::fs::read_to_string(path).expect("case CSV");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let keep: Vec<usize> = (0..header.len()).filter(|&i| header[i] != "run_id").collect();
    let pick = |l: &str| {
        let cells: Vec<&str> = l.split(',').collect();
        keep.iter().map(|&i| cells.get(i).copied().unwrap_or("")).collect::<Vec<_>>().join(",")
    };
    let mut rows: Vec<String> = lines.filter(|l| !l.is_empty()).map(pick).collect();
    // Fisher-Yates with a 64-bit LCG (Knuth's MMIX constants): reproducible per case
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    for i in (1..rows.len()).rev() {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        rows.swap(i, ((state >> 33) % (i as u64 + 1)) as usize);
    }
    let head: Vec<&str> = keep.iter().map(|&i| header[i]).collect();
    std::fs::write(path, format!("{}\n{}\n", head.join(","), rows.join("\n"))).expect("rewrite case CSV");
}

/// What `separating_campaigns` holds, on every diagnosis the benchmark makes: entries from
/// the lead (the single-effect verdict, or `partial` with `unexplained`) to each effect in
/// `confounded_with`, then at most one `close_in_evidence` rival, a supported single effect
/// less than 3 behind the lead in evidence (docs/DIAGNOSIS_JSON.md).
fn check_separations(v: &serde_json::Value, verdict: &str, confounded: &[String]) {
    let seps = v["separating_campaigns"].as_array().expect("separating_campaigns");
    let lead = if verdict == "unexplained" { v["partial"].as_str().unwrap_or(verdict) } else { verdict };
    let evidence = |e: &str| {
        v["ranking"].as_array().expect("ranking").iter().find(|r| r["effect"] == e).and_then(|r| r["evidence"].as_f64())
    };
    let mut close = 0;
    for s in seps {
        assert_eq!(s["effects"][0], lead, "{s}");
        let rival = s["effects"][1].as_str().expect("rival");
        match s["rival"].as_str().expect("rival kind") {
            "confounded" => assert!(confounded.iter().any(|c| c == rival), "{s}"),
            "close_in_evidence" => {
                close += 1;
                let (l, r) = (evidence(lead).expect("lead ranked"), evidence(rival).expect("rival ranked"));
                assert!(!confounded.iter().any(|c| c == rival) && !rival.contains('+'), "{s}");
                assert!(r > 0.0 && l - r < 3.0, "lead {l}, rival {r}: {s}");
            }
            other => panic!("rival kind {other}: {s}"),
        }
    }
    assert!(close <= 1, "{seps:?}");
}

/// Synthesises the case's data and diagnoses it blind.
pub fn run_case(case: &Case, dir: &std::path::Path) -> Outcome {
    let tag = format!(
        "{}-{}-{}-{}-{}-{:?}",
        case.truth().replace('+', "_"),
        case.factor,
        case.campaign,
        case.noise,
        case.seed,
        case.half
    );
    let data = dir.join(format!("{tag}.csv"));
    let json = dir.join(format!("{tag}.json"));
    let mut args: Vec<String> = vec!["synth".into(), "--motor".into(), MOTOR.into()];
    args.extend(case.effect_args());
    args.extend(case.half_args());
    for (k, v) in [
        ("--campaign", case.campaign.to_string()),
        ("--noise", case.noise.to_string()),
        ("--seed", case.seed.to_string()),
        ("-o", data.display().to_string()),
    ] {
        args.push(k.into());
        args.push(v);
    }
    trum(&args);
    if BARE.load(std::sync::atomic::Ordering::Relaxed) {
        strip_runs_and_shuffle(&data, case.seed);
    }
    let t0 = std::time::Instant::now();
    trum(&[
        "diagnose".into(),
        "--motor".into(),
        MOTOR.into(),
        "--data".into(),
        data.display().to_string(),
        "--json".into(),
        json.display().to_string(),
    ]);
    let seconds = t0.elapsed().as_secs_f64();
    let text = std::fs::read_to_string(&json).expect("diagnosis JSON");
    let v: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let verdict = v["verdict"].as_str().expect("verdict").to_string();
    let confounded: Vec<String> = v["confounded_with"]
        .as_array()
        .expect("confounded_with")
        .iter()
        .filter_map(|x| x.as_str())
        .map(String::from)
        .collect();
    let ranking = v["ranking"].as_array().expect("ranking");
    check_separations(&v, &verdict, &confounded);
    let shrink_of = |name: &str| {
        ranking
            .iter()
            .find(|r| r["effect"].as_str().is_some_and(|e| same_set(e, name)))
            .and_then(|r| r["shrink"].as_f64())
    };
    let signal = case.signals();
    let expected = case.expected(&signal);
    let (before, noise) = (
        v["gap"]["baseline_heldout_nrmse"].as_f64().unwrap_or(f64::NAN),
        v["gap"]["noise_nrmse"].as_f64().unwrap_or(f64::NAN),
    );
    let excess = |x: f64| (x * x - noise * noise).max(0.0).sqrt();
    let oracle = oracle_shrink(case, &data, &v, before);
    let after_of = |name: &str| {
        ranking
            .iter()
            .find(|r| r["effect"].as_str().is_some_and(|e| same_set(e, name)))
            .and_then(|r| r["heldout_nrmse_after"].as_f64())
    };
    Outcome {
        true_excess_shrink: if expected == "none" {
            None
        } else {
            after_of(&expected).map(|a| 1.0 - excess(a) / excess(before).max(1e-12))
        },
        true_shrink: if expected == "none" { None } else { shrink_of(&expected) },
        oracle_shrink: oracle,
        expected,
        signal,
        verdict_shrink: shrink_of(&verdict),
        complete: v["complete"].as_bool().unwrap_or(false),
        verdict,
        confounded,
        partial: v["partial"].as_str().map(String::from),
        baseline_nrmse: v["gap"]["baseline_heldout_nrmse"].as_f64().unwrap_or(f64::NAN),
        noise_nrmse: v["gap"]["noise_nrmse"].as_f64().unwrap_or(f64::NAN),
        rows: v["n_rows"].as_u64().unwrap_or(0) as usize,
        seconds,
        case: case.clone(),
    }
}

/// `1 − oracle/before` for the case whose data file is `data` and diagnosis JSON `v`: the
/// true motor's held-out NRMSE against the baseline's, both from the JSON's held-out
/// readings on the diagnosis's quantity scales.
fn oracle_shrink(case: &Case, data: &std::path::Path, v: &serde_json::Value, _before: f64) -> f64 {
    use trum_core::calibrate::Observable;
    let bytes = std::fs::read(data).expect("case CSV");
    let m = trum_core::measurements::parse_measurements(&bytes, &data.display().to_string()).expect("case CSV");
    let bench = trum_core::bench::observations(&m, &nominal());
    let scale = trum_core::diagnose::nrmse_scales(&bench.rows, &bench.groups);
    let held = v["heldout"].as_array().expect("heldout");
    let sum: f64 = held
        .iter()
        .map(|h| {
            let q = h["quantity"].as_str().expect("quantity");
            let o = Observable::ALL.into_iter().find(|o| o.column() == q).expect("known quantity");
            // a point the baseline cannot solve is predicted as 0, as in the diagnosis
            let (y, b) = (h["measured"].as_f64().expect("measured"), h["baseline"].as_f64().unwrap_or(0.0));
            ((b - y) / scale[&o]).powi(2)
        })
        .sum();
    let before = (sum / held.len() as f64).sqrt();
    1.0 - case.oracle_nrmse(&bench.rows, &scale) / before
}

/// Every effect of the registry (`trum_core::effects::ALL`), in its order.
pub fn effect_names() -> Vec<&'static str> {
    trum_core::effects::ALL.iter().map(|e| e.name()).collect()
}

/// The full benchmark: every effect × three strengths (0.3, 1 and 3 × typical) × two
/// noise levels (0.5 and 1 × the nominal bench noise) × two campaigns (preload-torque and
/// combined), eight null cases, four two-effect cases at typical strength; every seed
/// moved by `seed_offset`. The cases at 0.3 and 1 × take seeds from 101 on, the 3 × cases
/// from 201 on.
pub fn full_cases_at(seed_offset: u64) -> Vec<Case> {
    let mut out = cases_at(&FACTORS, seed_offset);
    let mut seed = 200 + seed_offset;
    for campaign in ["preload-torque", "combined"] {
        for noise in [0.5, 1.0] {
            for e in effect_names() {
                seed += 1;
                out.push(Case { effects: vec![e], factor: STRONG_FACTOR, campaign, noise, seed, half: Half::Plain });
            }
        }
    }
    out
}

/// One half of the two-half benchmark (docs/DIAGNOSIS.md): every effect at 1 and 3 ×
/// typical on the preload-torque and combined campaigns (28 cases), two null cases on each
/// of the five campaign kinds (10) and two pairs at typical strength, all at the nominal
/// bench noise, with the half's truth forms and artefacts; every seed moved by
/// `seed_offset`. The halves draw different seeds.
pub fn half_cases(half: Half, seed_offset: u64) -> Vec<Case> {
    let mut seed = seed_offset + if half == Half::HeldOut { 5000 } else { 3000 };
    let mut next = || {
        seed += 1;
        seed
    };
    let mut out = Vec::new();
    for campaign in ["preload-torque", "combined"] {
        for e in effect_names() {
            for factor in [1.0, STRONG_FACTOR] {
                out.push(Case { effects: vec![e], factor, campaign, noise: 1.0, seed: next(), half });
            }
        }
    }
    for campaign in ["preload-torque", "combined", "frequency-sweep", "warm-up", "stability"] {
        for _ in 0..2 {
            out.push(Case { effects: vec![], factor: 0.0, campaign, noise: 1.0, seed: next(), half });
        }
    }
    for pair in [["radial_friction", "thermal_drift"], ["voltage_sag", "eccentricity"]] {
        out.push(Case { effects: pair.to_vec(), factor: 1.0, campaign: "combined", noise: 1.0, seed: next(), half });
    }
    out
}

/// Every pair of two different effects, each at typical strength in the half's truth
/// forms with its artefacts, on the combined campaign (21 cases), seeds from 3200 (the
/// development half) or 5200 (the held-out half) moved by `seed_offset`: a design of
/// two-effect cases alone, beside the halves' two pairs each.
pub fn pair_cases(half: Half, seed_offset: u64) -> Vec<Case> {
    let names = effect_names();
    let mut seed = seed_offset + if half == Half::HeldOut { 5200 } else { 3200 };
    let mut out = Vec::new();
    for (i, a) in names.iter().enumerate() {
        for b in &names[i + 1..] {
            seed += 1;
            out.push(Case { effects: vec![*a, *b], factor: 1.0, campaign: "combined", noise: 1.0, seed, half });
        }
    }
    out
}

/// The fast slice of the two-half benchmark in the test suite: for each half, four single
/// effects on the preload-torque campaign (typical strength) and two null cases (one on a
/// campaign without load torque). Seeds differ from the full run's.
pub fn half_slice_cases(half: Half) -> Vec<Case> {
    let base: u64 = if half == Half::HeldOut { 7000 } else { 6000 };
    let one = |effects: Vec<&'static str>, campaign, seed: u64| Case {
        factor: if effects.is_empty() { 0.0 } else { 1.0 },
        effects,
        campaign,
        noise: 1.0,
        seed: base + seed,
        half,
    };
    vec![
        one(vec!["radial_friction"], "preload-torque", 1),
        one(vec!["voltage_sag"], "preload-torque", 2),
        one(vec!["tangential_compliance"], "preload-torque", 3),
        one(vec!["hertz_softening"], "preload-torque", 4),
        one(vec![], "preload-torque", 5),
        one(vec![], "frequency-sweep", 6),
    ]
}

/// The full benchmark's first two strengths, × typical (with their nulls and pairs).
pub const FACTORS: [f64; 2] = [0.3, 1.0];

/// The full benchmark's third strength, × typical: at 0.3 and 1 × alone the true motor's
/// median shrink is 0.67-0.71 (docs/DIAGNOSIS.md), so a target shrink of 0.7 would measure the
/// design more than the diagnosis.
pub const STRONG_FACTOR: f64 = 3.0;

/// Per strength of the observable non-null cases: (factor, hits, cases, median shrink,
/// the true motor's median shrink).
pub fn by_strength(outcomes: &[Outcome]) -> Vec<(f64, usize, usize, f64, f64)> {
    let mut factors: Vec<f64> = outcomes.iter().filter(|o| o.observable()).map(|o| o.case.factor).collect();
    factors.sort_by(f64::total_cmp);
    factors.dedup();
    factors
        .into_iter()
        .map(|f| {
            let rows: Vec<&Outcome> = outcomes.iter().filter(|o| o.observable() && o.case.factor == f).collect();
            let hits = rows.iter().filter(|o| o.correct_or_confounded()).count();
            let shrink = median(rows.iter().filter_map(|o| o.true_shrink).collect());
            let oracle = median(rows.iter().map(|o| o.oracle_shrink).collect());
            (f, hits, rows.len(), shrink, oracle)
        })
        .collect()
}

/// The full benchmark's cases with the single effects at `factors` × typical strength
/// (`cargo bench --bench blind -- --plain` runs [`full_cases_at`])
/// and every seed moved by `seed_offset` (`--seed-offset 1000`: another draw of the same
/// design).
pub fn cases_at(factors: &[f64], seed_offset: u64) -> Vec<Case> {
    let mut out = Vec::new();
    let mut seed = 100 + seed_offset;
    let mut next = || {
        seed += 1;
        seed
    };
    for campaign in ["preload-torque", "combined"] {
        for noise in [0.5, 1.0] {
            for e in effect_names() {
                for &factor in factors {
                    out.push(Case { effects: vec![e], factor, campaign, noise, seed: next(), half: Half::Plain });
                }
            }
            for _ in 0..2 {
                out.push(Case { effects: vec![], factor: 0.0, campaign, noise, seed: next(), half: Half::Plain });
            }
        }
    }
    for pair in [
        ["radial_friction", "thermal_drift"],
        ["voltage_sag", "eccentricity"],
        ["preload_stiffening", "tangential_compliance"],
        ["hertz_softening", "radial_friction"],
    ] {
        out.push(Case {
            effects: pair.to_vec(),
            factor: 1.0,
            campaign: "combined",
            noise: 1.0,
            seed: next(),
            half: Half::Plain,
        });
    }
    out
}

/// The fast slice in the test suite: the preload-torque campaign at nominal noise and
/// typical strength, for the five effects it can show, thermal_drift (which it cannot:
/// no time series, so `none` is right), one null case and one pair. Seeds differ from the
/// full run's.
pub fn slice_cases() -> Vec<Case> {
    let one = |e: &'static str, seed| Case {
        effects: vec![e],
        factor: 1.0,
        campaign: "preload-torque",
        noise: 1.0,
        seed,
        half: Half::Plain,
    };
    vec![
        one("radial_friction", 901),
        one("preload_stiffening", 902),
        one("hertz_softening", 903),
        one("voltage_sag", 904),
        one("tangential_compliance", 905),
        one("thermal_drift", 906),
        Case { effects: vec![], factor: 0.0, campaign: "preload-torque", noise: 1.0, seed: 950, half: Half::Plain },
        Case {
            effects: vec!["voltage_sag", "radial_friction"],
            factor: 1.0,
            campaign: "preload-torque",
            noise: 1.0,
            seed: 990,
            half: Half::Plain,
        },
    ]
}

/// Strong effects in the test suite (3 × typical, half the nominal noise): cases whose fits
/// can end far from the effect without the strong-effect starts, or name a second effect
/// that only polishes the first one's form error (seeds 107 and 121 for
/// `tangential_compliance` and `hertz_softening`).
pub fn strong_cases() -> Vec<Case> {
    let one = |e: &'static str, campaign, seed| Case {
        effects: vec![e],
        factor: 3.0,
        campaign,
        noise: 0.5,
        seed,
        half: Half::Plain,
    };
    vec![
        one("radial_friction", "preload-torque", 921),
        one("radial_friction", "combined", 922),
        one("tangential_compliance", "preload-torque", 107),
        one("hertz_softening", "combined", 121),
    ]
}

/// Median of the finite values (NaN when none).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Summary statistics over the outcomes.
pub struct Summary {
    /// Non-null, observable cases whose verdict is the truth or contains it in the confounded set.
    pub hit_rate: f64,
    pub non_null: usize,
    pub false_claims: usize,
    pub nulls: usize,
    pub median_true_shrink: f64,
    pub median_true_excess_shrink: f64,
    /// Median spec shrink of the true motor itself over the same cases: the ceiling.
    pub median_oracle_shrink: f64,
    /// Of the non-null cases: `unexplained` verdicts naming the truth as what explains
    /// part of the gap (not in `hit_rate`).
    pub unexplained_naming_truth: usize,
    /// Of the hits: verdicts with `complete: false`.
    pub incomplete_hits: usize,
    /// Null cases whose verdict is `unexplained`.
    pub null_unexplained: usize,
}

pub fn summarise(outcomes: &[Outcome]) -> Summary {
    let non_null: Vec<&Outcome> = outcomes.iter().filter(|o| o.observable()).collect();
    let hits = non_null.iter().filter(|o| o.correct_or_confounded()).count();
    let nulls = outcomes.iter().filter(|o| o.case.effects.is_empty()).count();
    Summary {
        hit_rate: hits as f64 / non_null.len().max(1) as f64,
        non_null: non_null.len(),
        false_claims: outcomes.iter().filter(|o| o.false_claim()).count(),
        nulls,
        median_true_shrink: median(non_null.iter().filter_map(|o| o.true_shrink).collect()),
        median_true_excess_shrink: median(non_null.iter().filter_map(|o| o.true_excess_shrink).collect()),
        median_oracle_shrink: median(non_null.iter().map(|o| o.oracle_shrink).collect()),
        unexplained_naming_truth: non_null.iter().filter(|o| o.unexplained_naming_truth()).count(),
        incomplete_hits: non_null.iter().filter(|o| o.correct_or_confounded() && !o.complete).count(),
        null_unexplained: outcomes.iter().filter(|o| o.case.effects.is_empty() && o.verdict == "unexplained").count(),
    }
}

/// The confusion matrix as Markdown: one row per injected truth, one column per verdict
/// seen, plus "truth in confounded set" and shrink statistics.
pub fn confusion_markdown(outcomes: &[Outcome]) -> String {
    let mut verdicts: Vec<String> = outcomes.iter().map(|o| o.verdict.clone()).collect();
    verdicts.sort();
    verdicts.dedup();
    // rows: none first, then the single effects, then the pairs
    let mut truths: Vec<String> = outcomes.iter().map(|o| o.case.truth()).collect();
    truths.sort_by_key(|t| (t != "none", t.contains('+'), t.clone()));
    truths.dedup();
    let mut s = String::new();
    let _ = write!(s, "| injected \\ verdict |");
    for v in &verdicts {
        let _ = write!(s, " {} |", v.replace('_', "\\_"));
    }
    let _ = writeln!(s, " cases | not visible (signal χ² < 25) | correct | truth in confounded set | unexplained, truth explains part | median shrink of truth | median shrink beyond noise |");
    let _ = write!(s, "|---|");
    for _ in &verdicts {
        let _ = write!(s, "---|");
    }
    let _ = writeln!(s, "---|---|---|---|---|---|---|");
    for t in &truths {
        let rows: Vec<&Outcome> = outcomes.iter().filter(|o| &o.case.truth() == t).collect();
        let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
        for o in &rows {
            *counts.entry(o.verdict.as_str()).or_default() += 1;
        }
        let _ = write!(s, "| {} |", t.replace('_', "\\_"));
        for v in &verdicts {
            match counts.get(v.as_str()) {
                Some(n) => {
                    let _ = write!(s, " {n} |");
                }
                None => {
                    let _ = write!(s, " · |");
                }
            }
        }
        let correct = rows.iter().filter(|o| o.correct()).count();
        let conf = rows.iter().filter(|o| !o.correct() && o.correct_or_confounded()).count();
        let part = rows.iter().filter(|o| o.unexplained_naming_truth()).count();
        let hidden = rows.iter().filter(|o| !o.case.effects.is_empty() && o.expected != o.case.truth()).count();
        let shrink = median(rows.iter().filter(|o| o.observable()).filter_map(|o| o.true_shrink).collect());
        let shrink = if t == "none" || !shrink.is_finite() { "–".to_string() } else { format!("{shrink:.2}") };
        let ex = median(rows.iter().filter(|o| o.observable()).filter_map(|o| o.true_excess_shrink).collect());
        let ex = if t == "none" || !ex.is_finite() { "–".to_string() } else { format!("{ex:.2}") };
        let _ = writeln!(s, " {} | {hidden} | {correct} | {conf} | {part} | {shrink} | {ex} |", rows.len());
    }
    s
}

/// One line per case, CSV.
pub fn cases_csv(outcomes: &[Outcome]) -> String {
    let mut s = String::from(
        "truth,factor,campaign,noise,seed,signal_chi2,expected,verdict,confounded_with,partial,correct,correct_or_confounded,true_shrink,true_excess_shrink,oracle_shrink,verdict_shrink,baseline_heldout_nrmse,noise_nrmse,rows,diagnose_s\n",
    );
    let f = |x: Option<f64>| x.map(|v| format!("{v:.4}")).unwrap_or_default();
    for o in outcomes {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.4},{},{:.4},{:.4},{},{:.2}",
            o.case.truth(),
            o.case.factor,
            o.case.campaign,
            o.case.noise,
            o.case.seed,
            o.signal.iter().map(|x| format!("{x:.0}")).collect::<Vec<_>>().join("|"),
            o.expected,
            o.verdict,
            o.confounded.join("|"),
            o.partial.as_deref().unwrap_or(""),
            o.correct(),
            o.correct_or_confounded(),
            f(o.true_shrink),
            f(o.true_excess_shrink),
            o.oracle_shrink,
            f(o.verdict_shrink),
            o.baseline_nrmse,
            o.noise_nrmse,
            o.rows,
            o.seconds
        );
    }
    s
}

/// A parameter's value in a case `factor` × typical: a shape parameter (not a strength)
/// sits mid-range.
fn strength(p: &trum_core::effects::EffectParam, factor: f64) -> f64 {
    if p.shape {
        p.start()
    } else {
        factor * p.typical
    }
}

//! The blind benchmark of `trum diagnose` (issue 5): every effect × three strengths (0.3,
//! 1 and 3 × typical) × two noise levels × two campaign kinds, null cases and two-effect
//! cases, each synthesised with `trum synth` (truth forms) and diagnosed without being
//! told the effect.
//!
//! `cargo bench --bench blind` runs all cases (7 s wall on 2 cores at stop 32, after the build) and
//! rewrites the confusion matrix in docs/DIAGNOSIS.md (between the `blind:begin` and
//! `blind:end` markers) and the per-case table docs/data/blind_cases.csv.
//! `cargo bench --bench blind -- --slice` runs only the test suite's slice, `--strong` its
//! strong-effect cases, `--factors 0.3,1` the full run's design with the
//! single effects at those strengths only (as before stop 35), `--seed-offset 1000` the full run with every seed moved by 1000 (these print
//! only); `--no-write`
//! prints without touching the docs; `--signals` prints only each case's signal χ² and the χ²
//! the candidate forms leave on the truth forms' noise-free readings;
//! `--only NAME` keeps the cases whose injected set contains NAME (`--only +`: the pairs).
//! Each case's CSV and JSON stay in target/blind/.

#[path = "../tests/support/blind.rs"]
mod blind;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let slice = args.iter().any(|a| a == "--slice");
    let write = !args.iter().any(|a| a == "--no-write") && !slice;
    let workers: usize = args
        .iter()
        .position(|a| a == "--workers")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    // `--factors 3` (comma-separated): the single effects at other strengths; prints only
    let factors: Option<Vec<f64>> = args
        .iter()
        .position(|a| a == "--factors")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.split(',').map(|x| x.parse().expect("--factors: numbers, comma-separated")).collect());
    // `--seed-offset K`: every seed of the full run moved by K; prints only
    let seed_offset: u64 = args
        .iter()
        .position(|a| a == "--seed-offset")
        .and_then(|i| args.get(i + 1))
        .map_or(0, |s| s.parse().expect("--seed-offset: a whole number"));
    let strong = args.iter().any(|a| a == "--strong");
    let write = write && factors.is_none() && !strong && seed_offset == 0;
    let mut cases = match (&factors, slice, strong) {
        (_, _, true) => blind::strong_cases(),
        (_, true, _) => blind::slice_cases(),
        (Some(f), _, _) => blind::cases_at(f, seed_offset),
        (None, _, _) => blind::full_cases_at(seed_offset),
    };
    // `--only NAME`: the cases whose injected set contains NAME (`+` for the pairs)
    if let Some(only) = args.iter().position(|a| a == "--only").and_then(|i| args.get(i + 1)) {
        cases.retain(|c| c.truth().contains(only.as_str()));
    }
    if args.iter().any(|a| a == "--signals") {
        // only what each case's injected effects leave after a baseline calibration
        for c in &cases {
            let sig: Vec<String> = c.effects.iter().zip(c.signals()).map(|(e, s)| format!("{e} {s:.0}")).collect();
            println!(
                "{:<16} x{} noise {:<4} seed {}: {}; candidate form error {:.0}",
                c.campaign,
                c.factor,
                c.noise,
                c.seed,
                sig.join(", "),
                c.form_error_chi2()
            );
        }
        return;
    }
    // the synthesised CSVs and diagnosis JSONs stay for inspection
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/blind");
    std::fs::create_dir_all(&dir).expect("target/blind");
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, blind::Outcome)>> = Mutex::new(Vec::new());
    let t0 = std::time::Instant::now();
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(case) = cases.get(i) else { break };
                let o = blind::run_case(case, &dir);
                eprintln!(
                    "[{:>3}/{}] {:>6.0} s  {:<44} {:>4} {:<14} noise {:<3} -> {:<40} confounded {:?} shrink {:?} (true motor {:.2}; {:.1} s)",
                    i + 1,
                    cases.len(),
                    t0.elapsed().as_secs_f64(),
                    o.case.truth(),
                    o.case.factor,
                    o.case.campaign,
                    o.case.noise,
                    o.verdict,
                    o.confounded,
                    o.true_shrink.map(|x| (x * 100.0).round() / 100.0),
                    o.oracle_shrink,
                    o.seconds
                );
                results.lock().expect("results").push((i, o));
            });
        }
    });
    let mut results = results.into_inner().expect("results");
    results.sort_by_key(|r| r.0);
    let outcomes: Vec<blind::Outcome> = results.into_iter().map(|r| r.1).collect();
    let sum = blind::summarise(&outcomes);
    let times: Vec<f64> = outcomes.iter().map(|o| o.seconds).collect();
    let table = blind::confusion_markdown(&outcomes);
    let summary = format!(
        "{} cases in {:.0} s wall ({} workers; diagnosis median {:.1} s, max {:.1} s per case).\n\n\
         * observable non-null cases whose verdict is the injected effect or whose confounded set contains it: \
         {:.0} % of {} (besides: `unexplained` naming the injected effect as the part of the gap it explains: {})\n* null cases with an effect claimed: {} of {}\n* median held-out shrink of the injected \
         effect(s) over the observable non-null cases: {:.2} (beyond noise: {:.2}); the true motor itself, \
         with no model error, would reach {:.2}\n",
        outcomes.len(),
        t0.elapsed().as_secs_f64(),
        workers,
        blind::median(times.clone()),
        times.iter().cloned().fold(0.0, f64::max),
        100.0 * sum.hit_rate,
        sum.non_null,
        sum.unexplained_naming_truth,
        sum.false_claims,
        sum.nulls,
        sum.median_true_shrink,
        sum.median_true_excess_shrink,
        sum.median_oracle_shrink
    );
    let strengths: Vec<String> = blind::by_strength(&outcomes)
        .iter()
        .map(|(f, hits, n, shrink, oracle)| {
            format!(
                "{f} × typical: {:.0} % of {n}, median shrink {shrink:.2} (true motor {oracle:.2})",
                100.0 * *hits as f64 / (*n).max(1) as f64
            )
        })
        .collect();
    let summary = format!("{summary}* by strength (pairs at 1 ×): {}\n", strengths.join("; "));
    println!("{table}\n{summary}");
    if write {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        std::fs::write(root.join("docs/data/blind_cases.csv"), blind::cases_csv(&outcomes)).expect("write CSV");
        let doc_path = root.join("docs/DIAGNOSIS.md");
        let doc = std::fs::read_to_string(&doc_path).expect("docs/DIAGNOSIS.md");
        let (begin, end) = ("<!-- blind:begin -->", "<!-- blind:end -->");
        let (Some(a), Some(b)) = (doc.find(begin), doc.find(end)) else {
            panic!("docs/DIAGNOSIS.md lacks the {begin} / {end} markers");
        };
        let new = format!(
            "{}{begin}\n\n{table}\n{summary}\nPer case: [docs/data/blind_cases.csv](data/blind_cases.csv).\n\n{}",
            &doc[..a],
            &doc[b..]
        );
        std::fs::write(&doc_path, new).expect("write docs/DIAGNOSIS.md");
        eprintln!("wrote docs/DIAGNOSIS.md and docs/data/blind_cases.csv");
    }
}

//! The blind benchmark of `trum diagnose` (docs/DIAGNOSIS.md, "Blind benchmark"). Each case
//! is synthesised with `trum synth` and diagnosed through the CSV file interface without
//! being told the effect.
//!
//! The benchmark has two halves. The development half injects the effects in their first
//! truth forms with the development bench artefacts; the held-out half injects them in
//! their second truth forms with other artefacts (a quantised speed and a torque zero
//! offset among them), and is kept out of every tuning of the diagnosis. Each half: every
//! effect at 1 and 3 × typical on two campaign kinds, two null cases on each of the five
//! campaign kinds, two pairs.
//!
//! `cargo bench --bench blind` runs both halves, reports each separately and rewrites their
//! tables in docs/DIAGNOSIS.md (between the `blind-dev:` and `blind-heldout:` markers) and
//! the per-case tables docs/data/blind_{dev,heldout}.csv. Options (these print only):
//! `--half dev|heldout` one half; `--seed-offset K` every seed moved by K (another draw);
//! `--slice` the test suite's slices; `--pairs` every pair of two effects alone, in the
//! half's forms and artefacts, on the combined campaign; `--plain` the earlier single-form design without
//! artefacts; `--only NAME` the cases whose injected set contains NAME; `--bare` every
//! case's file without `run_id` and with its rows shuffled; `--workers N`; `--no-write`. Each case's CSV and JSON stay in target/blind/.

#[path = "../tests/support/blind.rs"]
mod blind;

use blind::{Case, Half, Outcome};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

fn arg<'a>(args: &'a [String], name: &str) -> Option<&'a String> {
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1))
}

/// Diagnoses `cases` on `workers` threads, printing one line per case.
fn run(cases: &[Case], workers: usize, dir: &std::path::Path) -> (Vec<Outcome>, f64) {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, Outcome)>> = Mutex::new(Vec::new());
    let t0 = std::time::Instant::now();
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(case) = cases.get(i) else { break };
                let o = blind::run_case(case, dir);
                eprintln!(
                    "[{:>3}/{}] {:>6.0} s  {:?} {:<40} {:>4} {:<15} -> {:<40} complete {:<5} confounded {:?} shrink {:?} (true motor {:.2}; {:.1} s)",
                    i + 1,
                    cases.len(),
                    t0.elapsed().as_secs_f64(),
                    o.case.half,
                    o.case.truth(),
                    o.case.factor,
                    o.case.campaign,
                    o.verdict,
                    o.complete,
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
    (results.into_iter().map(|r| r.1).collect(), t0.elapsed().as_secs_f64())
}

/// The confusion table and the summary of one set of outcomes, as Markdown.
fn report(outcomes: &[Outcome], wall_s: f64, workers: usize) -> String {
    let sum = blind::summarise(outcomes);
    let times: Vec<f64> = outcomes.iter().map(|o| o.seconds).collect();
    let strengths: Vec<String> = blind::by_strength(outcomes)
        .iter()
        .map(|(f, hits, n, shrink, oracle)| {
            format!(
                "{f} × typical: {:.0} % of {n}, median shrink {shrink:.2} (true motor {oracle:.2})",
                100.0 * *hits as f64 / (*n).max(1) as f64
            )
        })
        .collect();
    format!(
        "{}\n{} cases in {:.0} s wall ({} workers; diagnosis median {:.1} s, max {:.1} s per case).\n\n\
         * observable non-null cases whose verdict is the injected effect or whose confounded set contains it: \
         **{:.0} %** of {} (of them with `complete: false`: {})\n\
         * null cases with an effect claimed: **{} of {}**; null cases `unexplained`: **{} of {}**\n\
         * median held-out shrink of the injected effect(s) over the observable non-null cases: **{:.2}** \
         (beyond noise: {:.2}); the true motor itself would reach {:.2}\n\
         * by strength (pairs at 1 ×): {}\n",
        blind::confusion_markdown(outcomes),
        outcomes.len(),
        wall_s,
        workers,
        blind::median(times.clone()),
        times.iter().cloned().fold(0.0, f64::max),
        100.0 * sum.hit_rate,
        sum.non_null,
        sum.incomplete_hits,
        sum.false_claims,
        sum.nulls,
        sum.null_unexplained,
        sum.nulls,
        sum.median_true_shrink,
        sum.median_true_excess_shrink,
        sum.median_oracle_shrink,
        strengths.join("; ")
    )
}

/// Replaces the text between `<!-- NAME:begin -->` and `<!-- NAME:end -->` in `doc`.
fn splice(doc: &str, name: &str, body: &str) -> String {
    let (begin, end) = (format!("<!-- {name}:begin -->"), format!("<!-- {name}:end -->"));
    let (Some(a), Some(b)) = (doc.find(&begin), doc.find(&end)) else {
        panic!("docs/DIAGNOSIS.md lacks the {begin} / {end} markers");
    };
    format!("{}{begin}\n\n{body}\n{}", &doc[..a], &doc[b..])
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let flag = |f: &str| args.iter().any(|a| a == f);
    let workers: usize = arg(&args, "--workers").and_then(|s| s.parse().ok()).unwrap_or(2);
    let seed_offset: u64 = arg(&args, "--seed-offset").map_or(0, |s| s.parse().expect("--seed-offset: a whole number"));
    let halves: Vec<Half> = match arg(&args, "--half").map(String::as_str) {
        Some("dev") => vec![Half::Dev],
        Some("heldout") => vec![Half::HeldOut],
        Some(other) => panic!("--half: dev or heldout, not {other}"),
        None if flag("--plain") => vec![Half::Plain],
        None => vec![Half::Dev, Half::HeldOut],
    };
    if flag("--bare") {
        blind::BARE.store(true, std::sync::atomic::Ordering::Relaxed);
    }
    let write = !flag("--no-write")
        && !flag("--bare")
        && !flag("--slice")
        && !flag("--plain")
        && !flag("--pairs")
        && seed_offset == 0
        && arg(&args, "--only").is_none();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/blind");
    std::fs::create_dir_all(&dir).expect("target/blind");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for half in halves {
        let mut cases = match (half, flag("--slice")) {
            (Half::Plain, true) => blind::slice_cases(),
            (Half::Plain, false) => blind::full_cases_at(seed_offset),
            (h, true) => blind::half_slice_cases(h),
            (h, false) if flag("--pairs") => blind::pair_cases(h, seed_offset),
            (h, false) => blind::half_cases(h, seed_offset),
        };
        if let Some(only) = arg(&args, "--only") {
            cases.retain(|c| c.truth().contains(only.as_str()));
        }
        let (outcomes, wall) = run(&cases, workers, &dir);
        let text = report(&outcomes, wall, workers);
        println!("\n## {half:?} half\n\n{text}");
        if write {
            let (name, csv) = match half {
                Half::HeldOut => ("blind-heldout", "docs/data/blind_heldout.csv"),
                _ => ("blind-dev", "docs/data/blind_dev.csv"),
            };
            std::fs::write(root.join(csv), blind::cases_csv(&outcomes)).expect("write CSV");
            let doc_path = root.join("docs/DIAGNOSIS.md");
            let doc = std::fs::read_to_string(&doc_path).expect("docs/DIAGNOSIS.md");
            let body = format!("{text}\nPer case: [{csv}]({}).\n", csv.trim_start_matches("docs/"));
            std::fs::write(&doc_path, splice(&doc, name, &body)).expect("write docs/DIAGNOSIS.md");
            eprintln!("wrote docs/DIAGNOSIS.md and {csv}");
        }
    }
}

//! The cost of one operating point, with each effect on its own: wall time and, under
//! callgrind, instructions (`bash scripts/callgrind.sh`; docs/PERFORMANCE.md).
//!
//! `cargo run --release -p trum-core --example point_cost -- SET [MODE] [POINTS]`
//!
//! * SET: `preset` (the `trum60a` preset as shipped, with its calibrated
//!   `preload_stiffening`), `none` (no effects), or one effect assignment such as
//!   `radial_friction=1` applied to the effect-free motor;
//! * MODE: `cold` (every point solved from scratch, `solve`), `sweep` (rows of a
//!   warm-started torque sweep, `solve_range`, as `trum map` and `trum.map` solve them);
//! * POINTS: how many points (rounded to rows of 25; default 4000).
//!
//! The points are the timing example's: preloads 100-300 N, torques 0-0.96 N·m in rows of
//! 25, 200 V, 43 kHz, 60 s after switch-on. The timed loop is `measured` (never inlined),
//! so `valgrind --tool=callgrind --toggle-collect='*point_cost::measured*'` counts it alone.
use std::time::Instant;
use trum_core::solve::Prepared;
use trum_core::sweep::{solve_range, Axis, Grid};
use trum_core::*;

const ROW: usize = 25;

fn motor(set: &str) -> Motor {
    let mut m = presets::preset("trum60a").expect("preset");
    if set != "preset" {
        m.effects.parse_assignment("none").expect("none");
        if set != "none" {
            m.effects.parse_assignment(set).expect("effect assignment");
        }
    }
    m
}

/// Solves rows `rows` of the grid; returns the summed evaluation count.
#[inline(never)]
fn measured(m: &Motor, g: &Grid, rows: std::ops::Range<usize>, sweep: bool) -> u64 {
    let mut evals = 0u64;
    if sweep {
        let p = Prepared::new(m);
        for r in rows {
            solve_range(m, &p, g, (r * ROW) as u64..((r + 1) * ROW) as u64, |_, _, s| evals += s.iterations as u64);
        }
    } else {
        for r in rows {
            for j in 0..ROW {
                let mut op = OperatingPoint::new(g.preload_n.at(r), g.torque_nm.at(j), 200.0, 43e3);
                op.elapsed_s = 60.0;
                evals += std::hint::black_box(solve(m, &op)).iterations as u64;
            }
        }
    }
    evals
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let set = args.first().map_or("none", String::as_str);
    let sweep = match args.get(1).map_or("cold", String::as_str) {
        "cold" => false,
        "sweep" => true,
        other => {
            eprintln!("point_cost: MODE must be cold or sweep, not {other:?}");
            std::process::exit(2);
        }
    };
    let points: usize = args.get(2).map_or(Ok(4000), |s| s.parse()).unwrap_or_else(|_| {
        eprintln!("point_cost: POINTS must be a whole number");
        std::process::exit(2);
    });
    let rows = (points / ROW).max(1);
    let m = motor(set);
    let g = Grid {
        preload_n: Axis::linspace(100.0, 300.0, rows),
        voltage_v: Axis::fixed(200.0),
        frequency_hz: Axis::fixed(43e3),
        torque_nm: Axis::linspace(0.0, 0.96, ROW),
    };
    // Times are medians over blocks of rows, so one slow block (another process
    // scheduled) does not move them; the evaluation count is the total's.
    let block = (rows / 20).max(1);
    let (mut per_point, mut evals) = (Vec::new(), 0u64);
    let mut r = 0;
    while r < rows {
        let end = (r + block).min(rows);
        let t0 = Instant::now();
        evals += measured(&m, &g, r..end, sweep);
        per_point.push(t0.elapsed().as_secs_f64() / ((end - r) * ROW) as f64);
        r = end;
    }
    per_point.sort_by(f64::total_cmp);
    let n = rows * ROW;
    println!(
        "{set:26} {:5} {:8.3} us/point (median of {} blocks), {:.2} evaluations/point, {n} points",
        if sweep { "sweep" } else { "cold" },
        per_point[per_point.len() / 2] * 1e6,
        per_point.len(),
        evals as f64 / n as f64
    );
}

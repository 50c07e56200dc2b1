//! Numerical robustness on a dense grid, for every preset: 60 preloads (log-spaced,
//! 1 mN to 5 kN) x 40 load torques (0 to 3 N·m) at frequencies from 30 to 60 kHz (far
//! below, just below, at and just above the motor's resonance, and the usual drive) and
//! voltages 1, 200 and 400 V: every point has a valid status with finite numbers that
//! agree with the status, or an explicit non-valid status. Never NaN with status ok.
//! Solved the way maps solve (warm start along the torque axis) and, for every fifth
//! point, cold as well; both must pass.
//!
//! Prints the status counts (`cargo test --test reliability_grid -- --nocapture`).

use std::collections::BTreeMap;
use trum_core::presets::PRESETS;
use trum_core::quantities::QUANTITIES;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::{solve, Motor, OperatingPoint, Solution, Status};

const N_PRELOAD: usize = 60;
const N_TORQUE: usize = 40;

fn check(m: &Motor, op: &OperatingPoint, s: &Solution, how: &str) -> Result<(), String> {
    let at = || {
        format!(
            "{} {how} at F={} N T={} N·m V={} V f={} Hz",
            m.name, op.preload_n, op.torque_nm, op.voltage_v, op.frequency_hz
        )
    };
    match s.status {
        Status::InvalidInput => return Err(format!("invalid_input for a valid point: {}", at())),
        Status::NoConvergence => return Ok(()),
        _ => {}
    }
    for q in QUANTITIES {
        let v = (q.get)(s);
        if !v.is_finite() {
            return Err(format!("status {} with {} = {v}: {}", s.status, q.name, at()));
        }
    }
    let ok = match s.status {
        Status::Ok => s.speed_rpm > 0.0 && op.torque_nm <= s.stall_torque_nm * (1.0 + 1e-9) + 1e-12,
        Status::Stall => s.speed_rpm == 0.0 && op.torque_nm >= s.stall_torque_nm * (1.0 - 1e-9) - 1e-12,
        Status::Clamped => s.amplitude_m == 0.0 && s.speed_rpm == 0.0,
        _ => true,
    };
    let ok = ok && (0.0..=1.0).contains(&s.efficiency) && s.amplitude_m >= 0.0 && s.input_power_w >= 0.0;
    if !ok {
        return Err(format!(
            "status {} disagrees with speed {} rpm, stall torque {} N·m, amplitude {} m, efficiency {}: {}",
            s.status,
            s.speed_rpm,
            s.stall_torque_nm,
            s.amplitude_m,
            s.efficiency,
            at()
        ));
    }
    Ok(())
}

#[test]
fn dense_grid_has_valid_finite_numbers_or_an_explicit_status() {
    let mut failures = Vec::new();
    let mut total: BTreeMap<String, usize> = BTreeMap::new();
    let mut points = 0usize;
    for preset in PRESETS {
        let m = preset.motor();
        let p = Prepared::new(&m);
        let fr = m.stator.resonance_frequency_hz;
        let freqs = [30_000.0, fr * 0.98, fr - 1.0, fr, fr + 1.0, 43_000.0, 60_000.0];
        let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
        for &hz in &freqs {
            for v in [1.0, 200.0, 400.0] {
                for i in 0..N_PRELOAD {
                    let f = 1e-3 * (5000.0f64 / 1e-3).powf(i as f64 / (N_PRELOAD - 1) as f64);
                    let mut prev: Option<Solution> = None;
                    for j in 0..N_TORQUE {
                        let t = 3.0 * j as f64 / (N_TORQUE - 1) as f64;
                        let op = OperatingPoint::new(f, t, v, hz);
                        let s = solve_prepared(&p, &m, &op, prev.as_ref().filter(|g| g.status.is_valid()));
                        points += 1;
                        *counts.entry(s.status.as_str()).or_default() += 1;
                        if let Err(e) = check(&m, &op, &s, "warm") {
                            failures.push(e);
                        }
                        if (i * N_TORQUE + j).is_multiple_of(5) {
                            let c = solve(&m, &op);
                            points += 1;
                            if let Err(e) = check(&m, &op, &c, "cold") {
                                failures.push(e);
                            }
                        }
                        prev = Some(s);
                    }
                }
            }
        }
        println!("{:<12} {:?}", preset.name, counts);
        for (k, n) in counts {
            *total.entry(k.to_string()).or_default() += n;
        }
    }
    println!("all presets: {points} solves; warm-start statuses {total:?}; {} failures", failures.len());
    failures.truncate(20);
    assert!(failures.is_empty(), "first failures:\n{}", failures.join("\n"));
}

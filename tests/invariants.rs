//! Invariants of the steady-state model over random valid motors and operating points
//! (proptest): zone ordering, efficiency range, power balance, monotonicity, status
//! consistency.

use proptest::prelude::*;
use trum_core::{solve, Motor, OperatingPoint, Status};

#[path = "support/scaled.rs"]
mod scaled;

/// A preset with every continuous parameter scaled by a factor in [0.7, 1.4].
fn motor_strategy() -> impl Strategy<Value = Motor> {
    (0usize..3, proptest::collection::vec(0.7f64..1.4, scaled::SCALED_KEYS.len()))
        .prop_map(|(i, f)| scaled::scaled_preset(i, &f))
}

fn op_strategy() -> impl Strategy<Value = OperatingPoint> {
    (5.0f64..600.0, 0.0f64..2.0, 30.0f64..300.0, 39_000.0f64..46_000.0)
        .prop_map(|(f, t, v, hz)| OperatingPoint::new(f, t, v, hz))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, .. ProptestConfig::default() })]

    #[test]
    fn physical_invariants(m in motor_strategy(), op in op_strategy()) {
        let s = solve(&m, &op);
        prop_assert!(s.status != Status::NoConvergence && s.status != Status::InvalidInput, "{:?} at {:?}", s.status, op);
        let per_wave = 360.0 / m.geometry.wave_number;
        prop_assert!(0.0 <= s.driving_angle_deg && s.driving_angle_deg <= s.contact_angle_deg + 1e-12);
        prop_assert!(s.contact_angle_deg <= per_wave + 1e-9);
        prop_assert!((0.0..=1.0).contains(&s.efficiency));
        let balance = s.input_power_w - s.output_power_w - s.total_loss_w();
        prop_assert!(balance.abs() <= 1e-8 * s.input_power_w.max(1e-9), "balance {} of {}", balance, s.input_power_w);
        for (name, v) in [("speed", s.speed_rpm), ("amp", s.amplitude_m), ("pin", s.input_power_w), ("fric", s.friction_loss_w), ("current", s.current_a)] {
            prop_assert!(v.is_finite() && v >= 0.0, "{} = {}", name, v);
        }
        match s.status {
            Status::Ok => prop_assert!(s.speed_rpm > 0.0 && op.torque_nm < s.stall_torque_nm + 1e-12),
            Status::Stall => prop_assert!(s.speed_rpm == 0.0 && s.output_power_w == 0.0 && op.torque_nm >= s.stall_torque_nm - 1e-9),
            Status::Clamped => prop_assert!(s.amplitude_m == 0.0 && s.speed_rpm == 0.0),
            _ => {}
        }
        if s.status != Status::Clamped {
            prop_assert!((s.axial_force_n - op.preload_n).abs() <= 1e-8 * op.preload_n);
        }
    }

    #[test]
    fn contact_grows_with_preload_and_speed_falls_with_torque(m in motor_strategy(), op in op_strategy()) {
        let a = solve(&m, &op);
        let mut op2 = op;
        op2.preload_n *= 1.05;
        let b = solve(&m, &op2);
        if a.status == Status::Ok && b.status == Status::Ok {
            prop_assert!(b.contact_angle_deg >= a.contact_angle_deg - 1e-9, "{} -> {}", a.contact_angle_deg, b.contact_angle_deg);
        }
        let mut op3 = op;
        op3.torque_nm += 0.02;
        let c = solve(&m, &op3);
        if a.status == Status::Ok && c.status.is_valid() {
            prop_assert!(c.speed_rpm <= a.speed_rpm + 1e-9, "{} -> {}", a.speed_rpm, c.speed_rpm);
        }
    }
}

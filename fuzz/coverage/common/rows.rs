//! Small measurement sets (4-8 rows) decoded from fuzz bytes, shared by the `calibrate`
//! and `diagnose` targets: set points inside the plausible ranges, readings the generic
//! motor's own with a byte-sized error (so fits start near a solution, as on a bench), or
//! any plausible speed.
use trum_core::measurements::{Column, Measurements, Row};
use trum_core::{solve, Motor, OperatingPoint};

fn unit(b: u8) -> f64 {
    f64::from(b) / 255.0
}

/// The rows encoded by `data[2..]` (six bytes a row; `data[0]` picks 4-8 rows), or `None`
/// when the input is too short or the builder refuses the rows.
pub fn small_rows(motor: &Motor, data: &[u8]) -> Option<Measurements> {
    if data.len() < 6 {
        return None;
    }
    let n = 4 + usize::from(data[0] % 5);
    let mut builder = Measurements::builder().column(Column::CurrentA);
    let mut chunks = data[2..].chunks(6);
    for i in 0..n {
        let c: Vec<u8> = chunks.next().map_or_else(|| vec![i as u8; 6], <[u8]>::to_vec);
        let c = |k: usize| c.get(k).copied().unwrap_or(0);
        let op = OperatingPoint::new(
            100.0 + 400.0 * unit(c(0)),
            0.8 * unit(c(1)),
            120.0 + 120.0 * unit(c(2)),
            41_000.0 + 4000.0 * unit(c(3)),
        );
        let s = solve(motor, &op);
        let err = (f64::from(c(4)) - 128.0) / 128.0;
        let speed = if c(5) > 250 { 9999.0 * unit(c(4)) } else { (s.speed_rpm * (1.0 + 0.2 * err)).clamp(0.0, 9999.0) };
        let current = if s.current_a.is_finite() { Some(s.current_a.abs()) } else { None };
        let mut row = Row::new(
            op.preload_n,
            op.voltage_v,
            op.frequency_hz,
            op.torque_nm,
            if speed.is_finite() { speed } else { 0.0 },
        );
        if let Some(a) = current.filter(|a| a.is_finite() && *a <= 1e3) {
            row = row.with_current_a(a);
        }
        builder = builder.row(row);
    }
    builder.build().ok()
}

//! Step-response metrics of a sampled speed history.

use super::StepMetrics;

/// First time `speed` reaches `level` (rising), linearly interpolated between samples.
fn first_crossing(time_s: &[f64], speed: &[f64], level: f64) -> Option<f64> {
    let i = speed.iter().position(|&s| s >= level)?;
    if i == 0 {
        return Some(time_s[0]);
    }
    let (s0, s1) = (speed[i - 1], speed[i]);
    let u = if s1 > s0 { (level - s0) / (s1 - s0) } else { 1.0 };
    Some(time_s[i - 1] + u * (time_s[i] - time_s[i - 1]))
}

/// Delay (50 %), rise time (10-90 % and 0-100 %), peak time, overshoot and settling time (±2 % band) of a
/// speed history against its final value. Control-textbook definitions (Ogata,
/// *Modern Control Engineering*, §5-3); the bar-type transient paper reports delay and overshoot without
/// defining them. A negative final speed (the rotor turning backwards) is measured on the
/// mirrored history −speed, so a reversed wave has the same delay, rise, overshoot and
/// settling as the forward one, and a negative peak. All are `None` when the final speed
/// is zero or not finite or the record has fewer than two samples; the settling time is
/// `None` while the speed is still outside the band at the last sample.
pub fn step_metrics(time_s: &[f64], speed_rpm: &[f64], final_speed_rpm: f64) -> StepMetrics {
    let n = time_s.len().min(speed_rpm.len());
    if final_speed_rpm < 0.0 {
        let mirrored: Vec<f64> = speed_rpm[..n].iter().map(|v| -v).collect();
        let mut m = step_metrics(time_s, &mirrored, -final_speed_rpm);
        m.final_speed_rpm = final_speed_rpm;
        m.peak_speed_rpm = -m.peak_speed_rpm;
        return m;
    }
    let (t, s) = (&time_s[..n], &speed_rpm[..n]);
    let peak = s.iter().copied().fold(f64::NAN, f64::max);
    let mut m = StepMetrics {
        final_speed_rpm,
        peak_speed_rpm: peak,
        delay_s: None,
        rise_time_s: None,
        rise_to_final_s: None,
        peak_time_s: None,
        overshoot: None,
        settling_time_s: None,
    };
    if n < 2 || final_speed_rpm.is_nan() || final_speed_rpm <= 0.0 || final_speed_rpm.is_infinite() {
        return m;
    }
    let f = final_speed_rpm;
    m.delay_s = first_crossing(t, s, 0.5 * f);
    m.rise_time_s = match (first_crossing(t, s, 0.1 * f), first_crossing(t, s, 0.9 * f)) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    m.rise_to_final_s = first_crossing(t, s, f);
    m.peak_time_s = s.iter().position(|&v| v == peak).map(|i| t[i]);
    m.overshoot = Some(((peak - f) / f).max(0.0));
    let band = 0.02 * f;
    m.settling_time_s = match s.iter().rposition(|&v| (v - f).abs() > band) {
        None => Some(t[0]),
        Some(i) if i + 1 == n => None,
        Some(i) => {
            // interpolate where the history enters the band between samples i and i+1
            let level = if s[i] > f { f + band } else { f - band };
            let (s0, s1) = (s[i], s[i + 1]);
            let u = if s1 != s0 { ((level - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { 1.0 };
            Some(t[i] + u * (t[i + 1] - t[i]))
        }
    };
    m
}

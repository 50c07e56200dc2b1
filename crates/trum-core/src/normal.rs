//! The standard normal distribution: what the noise model of a reading and the clipping
//! of a speed standard deviation at zero need.

/// The standard normal distribution function Φ(x) (through `libm::erfc`: to full relative
/// accuracy in the lower tail; take the upper tail 1 − Φ(x) as Φ(−x)).
pub(crate) fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// The standard normal density φ(x).
pub(crate) fn normal_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

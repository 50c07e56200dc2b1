//! One axis of a grid of operating points: evenly spaced values from a start to a stop,
//! as a map sweeps them and a motor file's `[sweep]` table writes them.

/// One axis: `n` points from `start` to `stop` inclusive (n = 1: just `start`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    /// First value.
    pub start: f64,
    /// Last value.
    pub stop: f64,
    /// Number of points, ≥ 1.
    pub n: usize,
}

impl Axis {
    /// A single value.
    pub fn fixed(v: f64) -> Axis {
        Axis { start: v, stop: v, n: 1 }
    }
    /// `n` evenly spaced values.
    pub fn linspace(start: f64, stop: f64, n: usize) -> Axis {
        Axis { start, stop, n }
    }
    /// Value `i`.
    #[inline]
    pub fn at(&self, i: usize) -> f64 {
        if self.n <= 1 {
            self.start
        } else {
            self.start + (self.stop - self.start) * (i as f64) / ((self.n - 1) as f64)
        }
    }
}

//! Golden-section search of a bracketing triple (Kiefer 1953; Press et al., *Numerical
//! Recipes*, § 10.2): the one-dimensional minimiser shared by the sagging drive's dip
//! search (`solve`) and the preload criterion's efficiency peak (`criterion`). Hand-written
//! because it is a dozen lines that start from points the caller has already evaluated and
//! stop early on the caller's test; argmin's golden-section solver would be a dependency
//! for one loop and re-evaluate both.

/// A point of the search: (abscissa, value).
pub(crate) type Point = (f64, f64);

/// How a search ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum End {
    /// The caller's test held at this probe.
    Stopped(Point),
    /// The bracket became narrower than asked.
    Narrow,
    /// The evaluation budget ran out.
    Budget,
    /// A probe had no finite value.
    NonFinite,
}

/// Golden-section search for a minimum of `f` in the bracketing triple a < b < c (each with
/// its value, f(b) ≤ f(a) and f(b) ≤ f(c)): each probe goes into the larger side of b, at
/// the golden fraction 0.382 of it from b, and the triple shrinks about the least point.
/// Ends when `stop` holds at a probe's value, when c − a < `width`, after `max_evals`
/// probes, or at a non-finite value. Returns the final triple (b its least point) and how
/// it ended. Linear convergence, the bracket shrinking by 0.618 every probe or two.
pub(crate) fn minimise(
    mut f: impl FnMut(f64) -> f64,
    triple: (Point, Point, Point),
    width: f64,
    max_evals: usize,
    stop: impl Fn(f64) -> bool,
) -> ((Point, Point, Point), End) {
    const GOLD: f64 = 0.381_966_011_250_105_2;
    let (mut a, mut b, mut c) = triple;
    for _ in 0..max_evals {
        if c.0 - a.0 < width {
            return ((a, b, c), End::Narrow);
        }
        let x = if c.0 - b.0 > b.0 - a.0 { b.0 + GOLD * (c.0 - b.0) } else { b.0 - GOLD * (b.0 - a.0) };
        let fx = f(x);
        if !fx.is_finite() {
            return ((a, b, c), End::NonFinite);
        }
        if stop(fx) {
            return ((a, b, c), End::Stopped((x, fx)));
        }
        match (fx < b.1, x > b.0) {
            (true, true) => (a, b) = (b, (x, fx)),
            (true, false) => (c, b) = (b, (x, fx)),
            (false, true) => c = (x, fx),
            (false, false) => a = (x, fx),
        }
    }
    ((a, b, c), End::Budget)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth minimum is found to the width asked, the triple stays bracketing, and the
    /// probes are about log(width/start)/log(0.618).
    #[test]
    fn finds_a_smooth_minimum_to_the_width_asked() {
        let f = |x: f64| (x - 0.3).powi(2) + 0.1 * (x - 0.3).powi(4);
        let mut calls = 0;
        let ((a, b, c), end) = minimise(
            |x| {
                calls += 1;
                f(x)
            },
            ((0.0, f(0.0)), (0.5, f(0.5)), (2.0, f(2.0))),
            1e-9,
            200,
            |_| false,
        );
        assert_eq!(end, End::Narrow);
        assert!(a.0 <= b.0 && b.0 <= c.0 && b.1 <= a.1 && b.1 <= c.1);
        assert!((b.0 - 0.3).abs() < 1e-9, "{b:?}");
        assert!((40..=60).contains(&calls), "{calls} probes");
    }

    /// The caller's test ends the search at the probe where it holds; a non-finite value
    /// and the budget end it too.
    #[test]
    fn stops_on_the_callers_test_a_nan_and_the_budget() {
        let f = |x: f64| (x - 1.0).powi(2) - 0.01;
        let start = ((0.0, f(0.0)), (0.8, f(0.8)), (3.0, f(3.0)));
        let (_, end) = minimise(f, start, 1e-12, 100, |v| v <= 0.0);
        match end {
            End::Stopped((x, v)) => assert!(v <= 0.0 && (x - 1.0).abs() <= 0.1, "{x} {v}"),
            other => panic!("{other:?}"),
        }
        assert_eq!(minimise(|_| f64::NAN, start, 1e-12, 100, |_| false).1, End::NonFinite);
        assert_eq!(minimise(f, start, 1e-12, 3, |_| false).1, End::Budget);
    }
}

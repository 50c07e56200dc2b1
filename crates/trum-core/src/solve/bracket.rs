//! Scalar root brackets shared by the amplitude descent, the effects' fixed points and
//! the stiffness crossing: the latest sign change of a residual with Illinois regula
//! falsi, the secant step of an alternating fixed-point pass, and the golden-section
//! search for a dip of a residual below zero.

/// The latest points on either side of a sign change of a scalar residual h(x) = x − G(x),
/// with Illinois halving of a kept end once the bracket is being used (the amplitude solve
/// from its first step, the effects' fixed point after [`BRACKET_AFTER`] passes).
#[derive(Default)]
pub(crate) struct SignBracket {
    /// The latest (x, h(x)) with h < 0.
    pub(crate) neg: Option<(f64, f64)>,
    /// The latest (x, h(x)) with h > 0.
    pub(crate) pos: Option<(f64, f64)>,
    /// Side of the latest recorded point: −1, +1, or 0 before the first.
    pub(crate) last_side: i8,
}

impl SignBracket {
    pub(crate) fn record(&mut self, x: f64, h: f64, illinois: bool) {
        if !(x.is_finite() && h.is_finite()) || h == 0.0 {
            return;
        }
        let side = if h < 0.0 { -1 } else { 1 };
        if illinois && side == self.last_side {
            let other = if side < 0 { &mut self.pos } else { &mut self.neg };
            if let Some(o) = other.as_mut() {
                o.1 *= 0.5;
            }
        }
        if side < 0 {
            self.neg = Some((x, h));
        } else {
            self.pos = Some((x, h));
        }
        self.last_side = side;
    }

    pub(crate) fn width(&self) -> Option<f64> {
        Some((self.pos?.0 - self.neg?.0).abs())
    }

    /// The middle of the sign change; `None` before it has two ends.
    pub(crate) fn midpoint(&self) -> Option<f64> {
        Some(0.5 * (self.neg?.0 + self.pos?.0))
    }

    pub(crate) fn regula_falsi(&self) -> Option<f64> {
        let ((a, ha), (b, hb)) = (self.neg?, self.pos?);
        let x = a - ha * (b - a) / (hb - ha);
        if x.is_finite() && (x - a) * (x - b) < 0.0 {
            Some(x)
        } else {
            self.midpoint()
        }
    }
}

/// The next iterate of a scalar fixed-point pass x ↦ G(x) given the previous pass
/// (x₀, G(x₀)). When the passes alternate about the fixed point, G falls with x there, so
/// the fixed point lies between x and G(x) and is unique nearby: take the secant root of
/// x − G(x), kept inside that interval. Found near clamping, where plain passes crawled at
/// a ratio of ≈ −0.85 (electrode voltage under `voltage_sag`; the temperature rise under a
/// strong `thermal_drift`: hotter → softer, detuned → fewer losses → cooler) or cycled
/// between a clamped and a moving stator. Where G rises with x the plain pass is kept: the
/// approach from the switch-on state is then monotone.
pub(super) fn bracketed_secant(x: f64, gx: f64, last: Option<(f64, f64)>) -> f64 {
    match last {
        Some((x0, g0)) if (gx - x) * (g0 - x0) < 0.0 && x != x0 => {
            let slope = (gx - g0) / (x - x0);
            let next = x + (gx - x) / (1.0 - slope);
            if slope < 0.0 && next.is_finite() {
                next.clamp(x.min(gx), x.max(gx))
            } else {
                gx
            }
        }
        _ => gx,
    }
}

/// What [`dip_below_zero`] finds: (W, (h, payload)) with h ≤ 0, and (W, h) with h > 0 above it.
pub(super) type Dip<E> = ((f64, (f64, E)), (f64, f64));

/// A dip of a scalar `h` below zero about a sampled local minimum: `a` < `b` < `c` as (W, h)
/// with h(b) > 0 below both h(a) and h(c) (`h` returns its value and what came with it).
/// Golden-section search of that bracketing triple for the least h ([`crate::golden`]),
/// stopped at the first h ≤ 0, at most 40 evaluations, to a relative width of 1e-7.
/// `Ok(Some)`: the highest evaluation with h ≤ 0 and the lowest point above it with h > 0
/// (c at worst), between which the dip's largest root lies; `Ok(None)`: the least h found
/// stays above 0; `Err`: a non-finite h. The search follows the triple's least point: a dip
/// elsewhere in [a, c], narrower than the probes around it, is not found.
#[allow(clippy::result_unit_err)]
pub(super) fn dip_below_zero<E: Clone>(
    h: impl Fn(f64) -> (f64, E),
    a: (f64, f64),
    b: (f64, f64),
    c: (f64, f64),
) -> Result<Option<Dip<E>>, ()> {
    let mut seen: Vec<(f64, (f64, E))> = Vec::new();
    let probe = |x: f64| {
        let e = h(x);
        let v = e.0;
        seen.push((x, e));
        v
    };
    let ((_, _, c), end) = crate::golden::minimise(probe, (a, b, c), 1e-7 * c.0, 40, |v| v <= 0.0);
    let (wn, (hn, en)) = match end {
        crate::golden::End::NonFinite => return Err(()),
        crate::golden::End::Stopped(_) => {
            // the probe that stopped it is the highest with h ≤ 0 (the only one)
            seen.iter().rev().find(|x| x.1 .0 <= 0.0).cloned().ok_or(())?
        }
        _ => return Ok(None),
    };
    // the lowest point above it with h > 0: a probe, or the triple's top end
    let pos =
        seen.iter()
            .filter(|x| x.0 > wn && x.1 .0 > 0.0)
            .map(|x| (x.0, x.1 .0))
            .fold(c, |m, x| if x.0 < m.0 { x } else { m });
    Ok(Some(((wn, (hn, en)), pos)))
}

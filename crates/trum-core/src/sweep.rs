//! Grids of operating points for maps, as the command-line tool (`trum map`, `trum plot`)
//! and the Python module (`trum.map`) both use them: the axes and their order, the
//! validation of a grid, and how a grid is cut into chunks that are solved with warm starts.
//! The grid is enumerated lazily (index → point), so a 10^8-point map never exists in
//! memory. Parallelism and writing live in the front ends.

pub use crate::axis::Axis;
use crate::error::TrumError;
use crate::params::Motor;
use crate::solve::{OperatingPoint, Prepared, Solution, SweepPoint, SWEEP_HISTORY};

/// The swept input axes, in the order a map writes its input columns (and the order of
/// [`OperatingPoint::new`]'s arguments). Points are enumerated in another order: see
/// [`Grid::point`].
pub const AXES: [&str; 4] = ["preload_n", "torque_nm", "voltage_v", "frequency_hz"];

/// Points per chunk of a map. A map is cut into chunks of this many points, in index
/// order, and each chunk is solved by [`solve_range`]: the first point cold, every other
/// one warm-started from its predecessors. The boundaries depend on nothing else, so a
/// map is the same number for number whatever the thread count or the front end. Large
/// enough that warm starts pay off and scheduling is cheap, small enough that a few
/// chunks per thread stay a few megabytes.
pub const CHUNK_POINTS: u64 = 4096;

/// The values of `op` on the grid's axes, in [`AXES`] order.
pub fn axis_values(op: &OperatingPoint) -> [f64; 4] {
    [op.preload_n, op.torque_nm, op.voltage_v, op.frequency_hz]
}

/// Number of chunks of `chunk` points (≥ 1) that hold `len` points.
pub fn chunk_count(len: u64, chunk: u64) -> u64 {
    len.div_ceil(chunk.max(1))
}

/// The point indices of chunk `c` of `len` points cut into chunks of `chunk` (≥ 1); the
/// last chunk may be shorter.
pub fn chunk_range(len: u64, chunk: u64, c: u64) -> std::ops::Range<u64> {
    let chunk = chunk.max(1);
    (c * chunk).min(len)..((c + 1) * chunk).min(len)
}

/// A full-factorial grid over preload × voltage × frequency × torque.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Preload axis [N].
    pub preload_n: Axis,
    /// Voltage axis [V].
    pub voltage_v: Axis,
    /// Frequency axis [Hz].
    pub frequency_hz: Axis,
    /// Load torque axis [N·m].
    pub torque_nm: Axis,
}

impl Grid {
    /// Checks the axes: at least one point each, finite values, and the operating-point
    /// ranges (preload, voltage, frequency > 0; torque ≥ 0), so that every point of the
    /// grid is a valid operating point. Errors name the axis and the value, e.g.
    /// `preload_n: 0 must be > 0`.
    pub fn validate(&self) -> Result<(), TrumError> {
        for (name, ax) in AXES.iter().zip(self.axes()) {
            if ax.n == 0 {
                return Err(TrumError::input(format!("{name}: an axis needs at least one point")));
            }
            for v in [ax.start, ax.stop] {
                if !v.is_finite() {
                    return Err(TrumError::input(format!("{name}: {v} is not a finite number")));
                }
                let ok = if *name == "torque_nm" { v >= 0.0 } else { v > 0.0 };
                if !ok {
                    let rule = if *name == "torque_nm" { ">= 0" } else { "> 0" };
                    return Err(TrumError::input(format!("{name}: {v} must be {rule}")));
                }
            }
        }
        if self.len_checked().is_none() {
            return Err(TrumError::input("the grid has more points than fit in 64 bits"));
        }
        Ok(())
    }

    /// The axes in [`AXES`] order.
    pub fn axes(&self) -> [Axis; 4] {
        [self.preload_n, self.torque_nm, self.voltage_v, self.frequency_hz]
    }

    fn len_checked(&self) -> Option<u64> {
        self.axes().iter().try_fold(1u64, |acc, a| acc.checked_mul(a.n as u64))
    }

    /// Number of points.
    pub fn len(&self) -> u64 {
        self.len_checked().unwrap_or(u64::MAX)
    }

    /// True when the grid has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The operating point with flat index `i`: torque varies fastest, then frequency,
    /// then voltage, and preload slowest (so the points along a torque line are
    /// neighbours, which is where warm starts pay off).
    pub fn point(&self, i: u64) -> OperatingPoint {
        let nt = self.torque_nm.n as u64;
        let nf = self.frequency_hz.n as u64;
        let nv = self.voltage_v.n as u64;
        let it = i % nt;
        let r = i / nt;
        let ifr = r % nf;
        let r = r / nf;
        let iv = r % nv;
        let ip = r / nv;
        OperatingPoint::new(
            self.preload_n.at(ip as usize),
            self.torque_nm.at(it as usize),
            self.voltage_v.at(iv as usize),
            self.frequency_hz.at(ifr as usize),
        )
    }
}

/// Solves the points `range` of `grid` in order, warm-starting each from the previous
/// one (the inner angle solves always; along a rising torque the amplitude too, from the
/// previous amplitude, which bounds the new one from above: crate::solve::solve_in_sweep),
/// and hands every (index, point, solution) to `sink`. The result equals the cold solves
/// to the solver's tolerance. Pure; the caller decides how chunks are spread over threads.
pub fn solve_range<F>(motor: &Motor, prepared: &Prepared, grid: &Grid, range: std::ops::Range<u64>, mut sink: F)
where
    F: FnMut(u64, &OperatingPoint, &Solution),
{
    // the last points solved, oldest first (solve_in_sweep extrapolates through them), and
    // the last solution (its angles start the next point's inner solves)
    let mut history: Vec<SweepPoint> = Vec::with_capacity(SWEEP_HISTORY + 1);
    let mut last: Option<Solution> = None;
    for i in range {
        let op = grid.point(i);
        let s = crate::solve::solve_in_sweep(prepared, motor, &op, last.as_ref(), &history);
        sink(i, &op, &s);
        if history.len() == SWEEP_HISTORY {
            history.remove(0);
        }
        history.push(SweepPoint::new(&op, &s));
        last = Some(s);
    }
}

/// Name, unit and meaning of the column maps write beside the point quantities: the load
/// torque at which the loaded motor stops at the point's preload and drive
/// ([`crate::criterion::loaded_stall_torque_nm`]). It does not depend on the load torque,
/// so it is one number per torque line.
pub const LOADED_STALL_COLUMN: (&str, &str, &str) = (
    "loaded_stall_torque_nm",
    "N·m",
    "load torque at which the loaded motor stops (stall or clamp) at this preload and drive",
);

/// [`crate::criterion::loaded_stall_torque_nm`] of the torque line through each point, for
/// map writers: the bisection (about 30 cold solves) runs once per (preload, voltage,
/// frequency) and is reused while consecutive points stay on that line, which they do
/// along a map's torque axis ([`Grid::point`]). The value is a cold computation, so it
/// does not depend on where a chunk starts. NaN where the rotor does not run at no load.
#[derive(Clone, Debug, Default)]
pub struct LineStall {
    /// The line's (preload, voltage, frequency) bits and its value.
    last: Option<([u64; 3], f64)>,
}

impl LineStall {
    /// An empty cache.
    pub fn new() -> Self {
        LineStall { last: None }
    }

    /// The loaded stall torque [N·m] of the line through `op` (its load torque is ignored).
    pub fn get(&mut self, prepared: &Prepared, motor: &Motor, op: &OperatingPoint) -> f64 {
        let key = [op.preload_n.to_bits(), op.voltage_v.to_bits(), op.frequency_hz.to_bits()];
        match self.last {
            Some((k, v)) if k == key => v,
            _ => {
                let v = crate::criterion::loaded_stall_torque_nm(
                    prepared,
                    motor,
                    op.preload_n,
                    op.voltage_v,
                    op.frequency_hz,
                );
                self.last = Some((key, v));
                v
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn sweeps_give_the_cold_answer_everywhere() {
        // Dense grids through running, stall and clamped regions: the warm-started sweep
        // (inner solves started from the neighbour) must give every point's cold status and
        // numbers to 1e-9 relative.
        use crate::quantities::QUANTITIES;
        use crate::solve::{solve, Status};
        let mut seen = std::collections::HashSet::new();
        // (amplitude evaluations of the sweep and of the cold solves, ok and stall points of
        // the stators a sweep warm-starts)
        let (mut warm_evals, mut cold_evals) = (0u64, 0u64);
        // The presets, and trum60a with a softening stator (several amplitude branches; no
        // warm amplitude there, see solve::solve_in_sweep).
        let motors = ["trum60a", "trum60-qut", "generic60", "trum60a+hertz_softening"].map(|name| {
            let mut m = crate::presets::frozen(name.split('+').next().unwrap_or(name)).expect("preset");
            if name.ends_with("softening") {
                let e = crate::effects::Effect::HertzSoftening;
                let strong: Vec<f64> =
                    e.info().params.iter().map(|p| if p.shape { p.typical } else { 3.0 * p.typical }).collect();
                m.effects.set(e, &strong);
            }
            (name, m)
        });
        for (name, m) in motors {
            let p = Prepared::new(&m);
            for (hz, v) in [(41_300.0, 88.0), (43_000.0, 200.0), (44_000.0, 300.0)] {
                let g = Grid {
                    preload_n: Axis::linspace(5.0, 700.0, 24),
                    voltage_v: Axis::fixed(v),
                    frequency_hz: Axis::fixed(hz),
                    torque_nm: Axis::linspace(0.0, 2.5, 23),
                };
                solve_range(&m, &p, &g, 0..g.len(), |_, op, s| {
                    let c = solve(&m, op);
                    seen.insert(c.status);
                    assert_eq!(s.status, c.status, "{name} {op:?}");
                    if matches!(c.status, Status::Ok | Status::Stall) && !name.ends_with("softening") {
                        warm_evals += u64::from(s.iterations);
                        cold_evals += u64::from(c.iterations);
                    }
                    if c.status.is_valid() {
                        for q in QUANTITIES {
                            let (a, b) = ((q.get)(s), (q.get)(&c));
                            assert!(
                                (a - b).abs() <= 1e-9 * b.abs().max(1e-300),
                                "{name} {op:?} {}: {a} vs {b}",
                                q.name
                            );
                        }
                    }
                });
            }
        }
        assert!([Status::Ok, Status::Stall, Status::Clamped].iter().all(|s| seen.contains(s)), "{seen:?}");
        // the torque-ordered warm start is taken (solve::solve_in_sweep): fewer amplitude
        // evaluations than cold, not the same answer by never leaving the cold path (0.514
        // of the cold count on these coarse grids; the softening stator, which a sweep
        // does not warm-start, left out)
        assert!(warm_evals * 100 < cold_evals * 53, "sweep {warm_evals} vs cold {cold_evals} amplitude evaluations");
    }

    /// Stators (softening or stiffening) whose cold descent lands on another branch than
    /// the largest: a sweep must still give the cold answer (no warm amplitude there),
    /// whatever the chunks.
    #[test]
    fn sweeps_of_multi_branch_stators_give_the_cold_answer_in_any_chunks() {
        use crate::effects::Effect;
        use crate::solve::solve;
        let cases = [
            (Effect::HertzSoftening, vec![1.021e18, 0.009052], 264.836, 97.255, 38_339.02, 1.0),
            (Effect::HertzSoftening, vec![3.5365e17, 0.002983], 480.29, 190.41, 38_483.30, 1.348),
            (Effect::HertzSoftening, vec![9.963e18, 0.006445], 37.78, 52.77, 38_671.89, 4.08),
            (Effect::PreloadStiffening, vec![0.504], 389.23, 190.38, 40_880.17, 0.8554),
        ];
        for (e, values, f, v, hz, t_max) in cases {
            let mut m = crate::presets::frozen("generic60").expect("preset");
            m.effects.set(e, &values);
            let p = Prepared::new(&m);
            let g = Grid {
                preload_n: Axis::fixed(f),
                voltage_v: Axis::fixed(v),
                frequency_hz: Axis::fixed(hz),
                torque_nm: Axis::linspace(0.0, t_max, 11),
            };
            for split in [0, 5] {
                let mut got = Vec::new();
                solve_range(&m, &p, &g, 0..split, |_, op, s| got.push((*op, s.clone())));
                solve_range(&m, &p, &g, split..11, |_, op, s| got.push((*op, s.clone())));
                for (op, s) in got {
                    let c = solve(&m, &op);
                    assert_eq!(s.status, c.status, "{e:?} {op:?} split {split}");
                    let (a, b) = (s.amplitude_m, c.amplitude_m);
                    assert!((a - b).abs() <= 1e-9 * b.abs(), "{e:?} {op:?} split {split}: W {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn index_order_is_torque_fastest() {
        let g = Grid {
            preload_n: Axis::linspace(100.0, 300.0, 3),
            voltage_v: Axis::fixed(200.0),
            frequency_hz: Axis::linspace(42e3, 43e3, 2),
            torque_nm: Axis::linspace(0.0, 0.5, 6),
        };
        assert_eq!(g.len(), 36);
        let p = g.point(0);
        assert_eq!((p.preload_n, p.frequency_hz, p.torque_nm), (100.0, 42e3, 0.0));
        let p = g.point(7);
        assert_eq!((p.preload_n, p.frequency_hz, p.torque_nm), (100.0, 43e3, 0.1));
        let p = g.point(35);
        assert_eq!((p.preload_n, p.frequency_hz, p.torque_nm), (300.0, 43e3, 0.5));
        assert!(g.validate().is_ok());
        let mut bad = g;
        bad.preload_n.start = 0.0;
        assert!(bad.validate().expect_err("an invalid grid").to_string().contains("preload_n: 0 must be > 0"));
        let mut bad = g;
        bad.torque_nm.stop = -0.1;
        assert!(bad.validate().expect_err("an invalid grid").to_string().contains("torque_nm: -0.1 must be >= 0"));
        let mut bad = g;
        bad.voltage_v.n = 0;
        assert!(bad
            .validate()
            .expect_err("an invalid grid")
            .to_string()
            .contains("voltage_v: an axis needs at least one point"));
        let mut bad = g;
        bad.frequency_hz.stop = f64::INFINITY;
        assert!(bad
            .validate()
            .expect_err("an invalid grid")
            .to_string()
            .contains("frequency_hz: inf is not a finite number"));
        // the axes, their values and the names come in one order
        let op = g.point(7);
        assert_eq!(axis_values(&op), [op.preload_n, op.torque_nm, op.voltage_v, op.frequency_hz]);
        assert_eq!(g.axes()[1], g.torque_nm);
        assert_eq!(AXES[1], "torque_nm");
    }

    #[test]
    fn chunks_cover_every_point_once_in_order() {
        for (len, chunk) in [(0u64, 4096u64), (1, 4096), (4096, 4096), (4097, 4096), (10, 3), (9, 3), (5, 1)] {
            let n = chunk_count(len, chunk);
            let mut next = 0;
            for c in 0..n {
                let r = chunk_range(len, chunk, c);
                assert_eq!(r.start, next, "len {len} chunk {chunk}");
                assert!(!r.is_empty() && r.end - r.start <= chunk, "len {len} chunk {chunk}: {r:?}");
                next = r.end;
            }
            assert_eq!(next, len, "len {len} chunk {chunk}");
        }
    }

    /// A map's statuses agree with its per-line loaded stall torque: along every torque
    /// line, warm-started as maps solve it and cut into chunks that split lines, a point
    /// runs (`ok`) below the line's loaded stall torque and not above it (outside the
    /// bisection's relative 1e-9, widened to 1e-6 for the warm start's tolerance), and a
    /// line with no loaded stall torque has no running point. Every preset at its drive,
    /// and generic60 near clamping (26.87 N, 6.63 V, 40 456.6 Hz), where the rotor-at-rest
    /// torque at no load is about three times the torque at which the loaded motor stops.
    #[test]
    fn map_statuses_agree_with_the_loaded_stall_torque_of_their_line() {
        use crate::solve::Status;
        let mut lines = 0;
        let mut far_below = false;
        // lines whose grid has running points below and stopped points above the torque
        let mut crossings = 0;
        let mut cases: Vec<(crate::params::Motor, Grid)> = crate::presets::PRESETS
            .iter()
            .map(|preset| {
                let d = preset.drive().map_or((200.0, 43_000.0), |d| (d.voltage_v, d.frequency_hz));
                let g = Grid {
                    preload_n: Axis::linspace(20.0, 600.0, 5),
                    voltage_v: Axis::linspace(0.5 * d.0, d.0, 2),
                    frequency_hz: Axis::fixed(d.1),
                    torque_nm: Axis::linspace(0.0, 3.0, 61),
                };
                (preset.motor(), g)
            })
            .collect();
        let generic = crate::presets::find("generic60").expect("generic60").motor();
        cases.push((
            generic,
            Grid {
                preload_n: Axis::fixed(26.87),
                voltage_v: Axis::fixed(6.63),
                frequency_hz: Axis::fixed(40_456.6),
                torque_nm: Axis::linspace(0.0, 0.1, 201),
            },
        ));
        for (motor, g) in &cases {
            let p = Prepared::new(motor);
            // chunks of 37 points: lines of 61 and 201 points cross chunk boundaries
            for c in 0..chunk_count(g.len(), 37) {
                let mut line = LineStall::new();
                solve_range(motor, &p, g, chunk_range(g.len(), 37, c), |_, op, s| {
                    let t = line.get(&p, motor, op);
                    assert_eq!(
                        t.to_bits(),
                        crate::criterion::loaded_stall_torque_nm(
                            &p,
                            motor,
                            op.preload_n,
                            op.voltage_v,
                            op.frequency_hz
                        )
                        .to_bits()
                    );
                    if op.torque_nm == 0.0 {
                        lines += 1;
                        far_below |= s.status == Status::Ok && t < 0.5 * s.stall_torque_nm;
                    }
                    let ok = s.status == Status::Ok;
                    if !ok
                        && op.torque_nm > t
                        && op.torque_nm - (g.torque_nm.stop - g.torque_nm.start) / (g.torque_nm.n - 1) as f64 <= t
                    {
                        crossings += 1;
                    }
                    if t.is_nan() {
                        assert!(!ok, "{}: {op:?} runs on a line with no loaded stall torque", motor.name);
                    } else if op.torque_nm < t * (1.0 - 1e-6) {
                        assert!(ok, "{}: {op:?} is {} below the loaded stall torque {t}", motor.name, s.status);
                    } else if op.torque_nm > t * (1.0 + 1e-6) {
                        assert!(!ok, "{}: {op:?} runs above the loaded stall torque {t}", motor.name);
                    }
                });
            }
        }
        assert!(lines >= 10 * crate::presets::PRESETS.len(), "{lines} lines");
        assert!(far_below, "no line where the loaded motor stops far below the rotor-at-rest torque");
        assert!(crossings >= lines / 2, "{crossings} of {lines} lines cross their loaded stall torque");
    }
}

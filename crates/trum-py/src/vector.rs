//! Vectorised solving without Python types: broadcasting of the five input columns,
//! chunked (optionally rayon-parallel) solves into column buffers, full-factorial maps.
//! Results do not depend on the thread count: a vectorised solve solves every point from a
//! cold start, and a map uses the core's fixed chunks (as `trum map` does).

use rayon::prelude::*;
use trum_core::layout::{status_code, status_meaning, status_of_code, work_bound_meaning};
use trum_core::quantities::{values, QUANTITIES};
use trum_core::solve::{solve_prepared, OperatingPoint, Prepared};
use trum_core::sweep::{axis_values, chunk_range, solve_range, Grid, AXES, CHUNK_POINTS};
use trum_core::{Motor, Solution, Status};

/// Inputs with at least this many points are solved in parallel by default.
pub const PARALLEL_MIN_POINTS: usize = 4096;

/// Points per work item of a vectorised solve (cold points: any size gives the same bits).
const CHUNK: usize = 1024;

/// Input names in the order of [`solve_points`]'s columns: the grid axes, then the time.
pub const INPUTS: [&str; 5] = [AXES[0], AXES[1], AXES[2], AXES[3], "elapsed_s"];

/// One broadcast input column: a scalar, a borrowed contiguous buffer (zero-copy) or a
/// gathered copy of a strided view.
pub enum Column<'a> {
    /// Same value everywhere.
    Scalar(f64),
    /// Contiguous, already in row-major broadcast order.
    Slice(&'a [f64]),
    /// Gathered from a strided or broadcast view.
    Owned(Vec<f64>),
}

impl Column<'_> {
    #[inline]
    fn at(&self, i: usize) -> f64 {
        match self {
            Column::Scalar(v) => *v,
            Column::Slice(s) => s[i],
            Column::Owned(v) => v[i],
        }
    }
}

/// NumPy broadcasting of `shapes`; the error names the clashing inputs.
pub fn broadcast_shape(names: &[&str], shapes: &[&[usize]]) -> Result<Vec<usize>, String> {
    let nd = shapes.iter().map(|s| s.len()).max().unwrap_or(0);
    let mut out = vec![1usize; nd];
    let mut owner: Vec<Option<usize>> = vec![None; nd];
    for (k, s) in shapes.iter().enumerate() {
        for (j, &d) in s.iter().enumerate() {
            let axis = nd - s.len() + j;
            if d == out[axis] || d == 1 {
                continue;
            }
            if out[axis] == 1 {
                out[axis] = d;
                owner[axis] = Some(k);
            } else {
                let other = owner[axis].unwrap_or(0);
                return Err(format!(
                    "inputs could not be broadcast together: {} has shape {:?}, {} has shape {:?}",
                    names[other], shapes[other], names[k], s
                ));
            }
        }
    }
    Ok(out)
}

/// Output columns of a vectorised solve, in [`QUANTITIES`] order, plus status codes
/// (`trum_core::layout::status_code`).
pub struct Columns {
    /// One column per quantity (NaN where the status is not valid).
    pub values: Vec<Vec<f64>>,
    /// Status codes (`trum_core::layout::STATUS_NAMES` indexed by code).
    pub status: Vec<u8>,
    /// Limit warnings, bit i for `trum_core::limits::LIMIT_KEYS[i]`.
    pub warnings: Vec<u8>,
    /// Whether the point's solve spent its work bound (`Solution::work_bound_reached`).
    pub work_bound: Vec<bool>,
}

/// Mutable views of one chunk of every output column.
struct ChunkOut<'a> {
    start: usize,
    values: Vec<&'a mut [f64]>,
    status: &'a mut [u8],
    warnings: &'a mut [u8],
    work_bound: &'a mut [bool],
}

impl ChunkOut<'_> {
    #[inline]
    fn write(&mut self, j: usize, s: &Solution) {
        self.status[j] = status_code(s.status);
        self.warnings[j] = s.warnings.bits();
        self.work_bound[j] = s.work_bound_reached;
        let valid = s.status.is_valid();
        for (col, v) in self.values.iter_mut().zip(values(s)) {
            col[j] = if valid { v } else { f64::NAN };
        }
    }
}

impl Columns {
    /// Zeroed buffers for `n` points; `None` when the memory cannot be had (a huge
    /// broadcast must not abort the process).
    fn try_new(n: usize) -> Option<Columns> {
        fn zeros<T: Clone + Default>(n: usize) -> Option<Vec<T>> {
            let mut v = Vec::new();
            v.try_reserve_exact(n).ok()?;
            v.resize(n, T::default());
            Some(v)
        }
        let values = (0..QUANTITIES.len()).map(|_| zeros(n)).collect::<Option<Vec<_>>>()?;
        Some(Columns { values, status: zeros(n)?, warnings: zeros(n)?, work_bound: zeros(n)? })
    }

    /// Splits every column into chunks of `chunk` points.
    fn chunks(&mut self, chunk: usize) -> Vec<ChunkOut<'_>> {
        let chunk = chunk.max(1);
        let mut out: Vec<ChunkOut<'_>> = self
            .status
            .chunks_mut(chunk)
            .zip(self.warnings.chunks_mut(chunk))
            .zip(self.work_bound.chunks_mut(chunk))
            .enumerate()
            .map(|(c, ((status, warnings), work_bound))| ChunkOut {
                start: c * chunk,
                values: Vec::with_capacity(QUANTITIES.len()),
                status,
                warnings,
                work_bound,
            })
            .collect();
        for col in self.values.iter_mut() {
            for (c, s) in col.chunks_mut(chunk).enumerate() {
                out[c].values.push(s);
            }
        }
        out
    }
}

fn run<F>(chunks: Vec<ChunkOut<'_>>, parallel: bool, work: F)
where
    F: Fn(&mut ChunkOut<'_>) + Sync + Send,
{
    if parallel {
        chunks.into_par_iter().for_each(|mut c| work(&mut c));
    } else {
        chunks.into_iter().for_each(|mut c| work(&mut c));
    }
}

/// Solves `n` points whose inputs are `cols` (in [`INPUTS`] order), each from a cold
/// start, so a point's result does not depend on its neighbours.
pub fn solve_points(motor: &Motor, cols: &[Column<'_>; 5], n: usize, parallel: bool) -> Option<Columns> {
    let p = Prepared::new(motor);
    let mut out = Columns::try_new(n)?;
    run(out.chunks(CHUNK), parallel, |c| {
        for j in 0..c.status.len() {
            let i = c.start + j;
            let op = OperatingPoint {
                preload_n: cols[0].at(i),
                torque_nm: cols[1].at(i),
                voltage_v: cols[2].at(i),
                frequency_hz: cols[3].at(i),
                elapsed_s: cols[4].at(i),
            };
            c.write(j, &solve_prepared(&p, motor, &op, None));
        }
    });
    Some(out)
}

/// Whether a status code is of a solved point (ok, stall, clamped): one without a reason.
pub fn is_valid_code(status: u8) -> bool {
    status_of_code(status).is_some_and(Status::is_valid)
}

/// Why a point with status code `status` is not valid (`None` when it is): the operating
/// point's own reason for an invalid input, the work bound where the solve spent it
/// (`work_bound`), the status's meaning otherwise.
pub fn reason(status: u8, op: &OperatingPoint, work_bound: bool) -> Option<String> {
    match status_of_code(status)? {
        Status::InvalidInput => {
            Some(op.invalid_reason().unwrap_or_else(|| status_meaning(Status::InvalidInput).into()))
        }
        Status::NoConvergence if work_bound => Some(work_bound_meaning()),
        s if !s.is_valid() => Some(status_meaning(s).into()),
        _ => None,
    }
}

/// Reasons for every non-valid point of a vectorised solve.
pub fn reasons(cols: &[Column<'_>; 5], out: &Columns) -> Vec<(usize, String)> {
    out.status
        .iter()
        .enumerate()
        .filter(|(_, &s)| !is_valid_code(s))
        .filter_map(|(i, &s)| {
            let op = OperatingPoint {
                preload_n: cols[0].at(i),
                torque_nm: cols[1].at(i),
                voltage_v: cols[2].at(i),
                frequency_hz: cols[3].at(i),
                elapsed_s: cols[4].at(i),
            };
            reason(s, &op, out.work_bound[i]).map(|r| (i, r))
        })
        .collect()
}

/// Solves a validated grid of `n` points in the core's chunks
/// ([`trum_core::sweep::CHUNK_POINTS`]), each warm-started point after point
/// ([`solve_range`]) exactly as `trum map` solves it, so the two give the same numbers.
pub fn solve_grid(motor: &Motor, grid: &Grid, n: usize, parallel: bool) -> Option<Columns> {
    let p = Prepared::new(motor);
    let chunk = usize::try_from(CHUNK_POINTS).unwrap_or(usize::MAX);
    let mut out = Columns::try_new(n)?;
    run(out.chunks(chunk), parallel, |c| {
        let start = c.start;
        let range = chunk_range(n as u64, CHUNK_POINTS, (start / chunk) as u64);
        solve_range(motor, &p, grid, range, |i, _, s| c.write(i as usize - start, s));
    });
    Some(out)
}

/// The input columns of a grid, in [`trum_core::sweep::AXES`] order.
pub fn grid_inputs(grid: &Grid, n: usize) -> [Vec<f64>; 4] {
    let mut cols: [Vec<f64>; 4] = std::array::from_fn(|_| Vec::with_capacity(n));
    for i in 0..n as u64 {
        for (c, v) in cols.iter_mut().zip(axis_values(&grid.point(i))) {
            c.push(v);
        }
    }
    cols
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn broadcasting_follows_numpy() {
        let n = ["a", "b", "c"];
        assert_eq!(broadcast_shape(&n, &[&[], &[3], &[2, 1]]), Ok(vec![2, 3]));
        assert_eq!(broadcast_shape(&n, &[&[0], &[1], &[]]), Ok(vec![0]));
        let e = broadcast_shape(&n, &[&[2], &[3], &[]]).unwrap_err();
        assert!(e.contains("a has shape [2], b has shape [3]"), "{e}");
    }

    #[test]
    fn parallel_equals_serial_equals_core() {
        let m = trum_core::presets::preset("trum60a").unwrap();
        let pre: Vec<f64> = (0..5000).map(|i| 100.0 + (i % 300) as f64).collect();
        let cols = [
            Column::Slice(&pre),
            Column::Scalar(0.1),
            Column::Scalar(200.0),
            Column::Scalar(43e3),
            Column::Scalar(0.0),
        ];
        let a = solve_points(&m, &cols, pre.len(), false).unwrap();
        let b = solve_points(&m, &cols, pre.len(), true).unwrap();
        assert_eq!(a.status, b.status);
        for (x, y) in a.values.iter().zip(&b.values) {
            assert!(x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits()));
        }
        let s = trum_core::solve(&m, &OperatingPoint::new(pre[7], 0.1, 200.0, 43e3));
        assert_eq!(a.values[0][7].to_bits(), s.speed_rpm.to_bits());
    }

    #[test]
    fn a_map_is_the_cores_chunked_sweep_in_any_parallelism() {
        use trum_core::sweep::{chunk_count, Axis};
        let m = trum_core::presets::preset("trum60a").unwrap();
        // more than one chunk, and rows (17 torques) that do not divide the chunk size
        let g = Grid {
            preload_n: Axis::linspace(100.0, 500.0, 250),
            torque_nm: Axis::linspace(0.0, 1.2, 17),
            voltage_v: Axis::fixed(200.0),
            frequency_hz: Axis::fixed(43e3),
        };
        let n = g.len() as usize;
        assert!(chunk_count(g.len(), CHUNK_POINTS) > 1);
        let serial = solve_grid(&m, &g, n, false).unwrap();
        let parallel = solve_grid(&m, &g, n, true).unwrap();
        assert_eq!(serial.status, parallel.status);
        // the core's sweep of the same chunks, as trum map runs it
        let p = Prepared::new(&m);
        let speed = QUANTITIES.iter().position(|q| q.name == "speed_rpm").unwrap();
        for c in 0..chunk_count(g.len(), CHUNK_POINTS) {
            solve_range(&m, &p, &g, chunk_range(g.len(), CHUNK_POINTS, c), |i, _, s| {
                let i = i as usize;
                assert_eq!(serial.status[i], status_code(s.status), "point {i}");
                let want = if s.status.is_valid() { s.speed_rpm } else { f64::NAN };
                assert_eq!(serial.values[speed][i].to_bits(), want.to_bits(), "point {i}");
                assert_eq!(parallel.values[speed][i].to_bits(), want.to_bits(), "point {i}");
            });
        }
        // and within the solver's tolerance of cold solves
        for i in (0..n).step_by(97) {
            let c = trum_core::solve(&m, &g.point(i as u64));
            assert_eq!(serial.status[i], status_code(c.status), "point {i}");
            let (a, b) = (serial.values[speed][i], c.speed_rpm);
            assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-9), "point {i}: {a} vs {b}");
        }
        let inputs = grid_inputs(&g, n);
        assert_eq!(inputs[1][18], g.point(18).torque_nm);
        assert_eq!(inputs[0][18], g.point(18).preload_n);
    }

    #[test]
    fn every_status_code_has_its_reason_or_none() {
        let op = OperatingPoint::new(-5.0, 0.0, 200.0, 43e3);
        assert_eq!(reason(status_code(Status::Ok), &op, false), None);
        assert_eq!(reason(status_code(Status::Clamped), &op, false), None);
        assert_eq!(
            reason(status_code(Status::InvalidInput), &op, false).as_deref(),
            Some("preload_n = -5 must be > 0")
        );
        let stopped = reason(status_code(Status::NoConvergence), &op, false).unwrap();
        assert!(stopped.starts_with("no steady state found") && !stopped.contains("work bound"), "{stopped}");
        let bounded = reason(status_code(Status::NoConvergence), &op, true).unwrap();
        assert!(bounded.starts_with("no steady state found") && bounded.contains("work bound"), "{bounded}");
        assert!(is_valid_code(2) && !is_valid_code(3) && !is_valid_code(200));
    }

    #[test]
    fn a_point_that_spent_its_work_bound_says_so_in_its_reason() {
        let m = trum_core::presets::preset("trum60a").expect("preset");
        let op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
        let stopped = solve_prepared(&Prepared::new(&m).with_work_bound(10), &m, &op, None);
        let solved = solve_prepared(&Prepared::new(&m), &m, &op, None);
        let mut out = Columns::try_new(2).expect("memory");
        {
            let mut chunks = out.chunks(2);
            chunks[0].write(0, &stopped);
            chunks[0].write(1, &solved);
        }
        assert_eq!(out.work_bound, [true, false]);
        let cols = [250.0, 0.3, 200.0, 43e3, 0.0].map(Column::Scalar);
        let r = reasons(&cols, &out);
        assert_eq!(r.len(), 1, "{r:?}");
        assert_eq!(r[0], (0, work_bound_meaning()));
    }
}

//! Dense linear least squares on the singular value decomposition of the Jacobian itself.
//!
//! For a weighted Jacobian J (m residuals × n parameters) with thin SVD J = U Σ Vᵀ,
//! [`LeastSquares`] gives the minimum-norm least-squares solution of J x ≈ r, the
//! covariance factor (JᵀJ)⁺ = V Σ⁻² Vᵀ, the part (I − U Uᵀ) S of columns S orthogonal to
//! range(J) and the Gauss–Newton decrement rᵀJ(JᵀJ)⁺Jᵀr = ‖Uᵀ r‖², all under one relative
//! singular-value cutoff. The calibration's standard errors and stopping test and the
//! diagnosis's approximate cross-validation and sensitivity signatures are built on it.
//!
//! Why J and not the normal matrix JᵀJ: κ(JᵀJ) = κ(J)², so forming JᵀJ squares the
//! condition number and loses twice the digits. A singular value of J below about √ε·σ_max
//! (1.5e-8 of the largest, ε = 2.2e-16 the machine epsilon) is lost in the rounding of JᵀJ,
//! while the SVD of J resolves singular values down to about ε·σ_max (Golub and Van Loan, Matrix
//! Computations, § 5.3, the normal equations against the QR and SVD routes; § 5.5 for the
//! rank-deficient problem, its minimum-norm solution and the numerical rank). A fit's
//! Jacobian mixes parameters whose columns differ by decades and priors add rows of yet
//! another scale; these are the matrices where the difference shows.
//!
//! The cutoff `rcond` is relative to σ_max(J): a singular value σₖ ≤ rcond·σ_max is treated
//! as zero. A threshold t on the eigenvalues of JᵀJ relative to its largest (eigenvalues
//! σₖ²) is the cutoff √t on σ(J): 1e-14 on JᵀJ is 1e-7 on J, 1e-10 is 1e-5.
//!
//! The factorisation is faer's; matrices cross the boundary as nalgebra's `DMatrix` and
//! `DVector`, the types the rest of the crate uses.

use faer::MatRef;
use nalgebra::{DMatrix, DVector};

/// The thin SVD of a Jacobian J, truncated at a relative singular-value cutoff: the kept
/// singular values σ₁ ≥ … ≥ σₖ > rcond·σ₁ and their singular vectors. Everything the
/// least-squares problem min ‖J x − r‖ needs, without forming JᵀJ (see the module
/// documentation for why).
#[derive(Clone, Debug)]
pub(crate) struct LeastSquares {
    /// U: m × k, the left singular vectors of the kept singular values (an orthonormal
    /// basis of the numerical range of J)
    u: DMatrix<f64>,
    /// σ₁ ≥ … ≥ σₖ > 0, the kept singular values (units of J)
    s: Vec<f64>,
    /// V: n × k, the right singular vectors of the kept singular values
    v: DMatrix<f64>,
}

impl LeastSquares {
    /// The truncated thin SVD of `j` (m × n, any shape, zero rows or columns included):
    /// singular values σₖ ≤ `rcond`·σ_max are dropped (`rcond` ≥ 0, dimensionless; 0 keeps
    /// every nonzero one). None when `j` holds a non-finite entry or the SVD does not
    /// converge: the caller decides what an undefined answer is (an SVD of non-finite
    /// input has no meaning, and is not attempted). A zero matrix, or one with no rows or
    /// no columns, has rank 0: every solution is zero and every projection the identity.
    pub(crate) fn new(j: &DMatrix<f64>, rcond: f64) -> Option<Self> {
        let (m, n) = j.shape();
        if !j.iter().all(|x| x.is_finite()) {
            return None;
        }
        if m == 0 || n == 0 {
            return Some(Self { u: DMatrix::zeros(m, 0), s: Vec::new(), v: DMatrix::zeros(n, 0) });
        }
        // nalgebra stores column-major and contiguously, the layout faer reads
        let svd = MatRef::from_column_major_slice(j.as_slice(), m, n).thin_svd();
        clear_upper_vector_state();
        let svd = svd.ok()?;
        let sv = svd.S().column_vector();
        let smax = sv.iter().copied().fold(0.0f64, f64::max);
        let k = sv.iter().take_while(|&&x| x > rcond * smax && x > 0.0).count();
        let (fu, fv) = (svd.U(), svd.V());
        Some(Self {
            u: DMatrix::from_fn(m, k, |i, c| fu[(i, c)]),
            s: sv.iter().take(k).copied().collect(),
            v: DMatrix::from_fn(n, k, |i, c| fv[(i, c)]),
        })
    }

    /// The numerical rank: the number of singular values kept.
    pub(crate) fn rank(&self) -> usize {
        self.s.len()
    }

    /// The minimum-norm least-squares solution x = J⁺ r = V Σ⁻¹ Uᵀ r of J x ≈ r (length n,
    /// units of r over units of J): among the minimisers of ‖J x − r‖ the one of least
    /// ‖x‖, so directions the data do not determine (dropped singular values) are left at
    /// zero. `r` has length m; a non-finite `r` gives a non-finite x.
    pub(crate) fn solve(&self, r: &DVector<f64>) -> DVector<f64> {
        let mut c = self.u.tr_mul(r);
        for (ci, s) in c.iter_mut().zip(&self.s) {
            *ci /= s;
        }
        &self.v * c
    }

    /// The Moore–Penrose inverse J⁺ = V Σ⁻¹ Uᵀ (n × m) under the cutoff: for applying the
    /// same solve to several right-hand sides.
    pub(crate) fn pseudo_inverse(&self) -> DMatrix<f64> {
        let mut vs = self.v.clone();
        for (mut col, s) in vs.column_iter_mut().zip(&self.s) {
            col /= *s;
        }
        vs * self.u.transpose()
    }

    /// (JᵀJ)⁺ = V Σ⁻² Vᵀ (n × n, units of 1/J²): the parameters' covariance for residuals
    /// of unit variance (scaled by s² for an estimated one). Zero along the directions the
    /// cutoff drops, rather than the huge and meaningless values their inverse would give.
    pub(crate) fn covariance(&self) -> DMatrix<f64> {
        let mut vs = self.v.clone();
        for (mut col, s) in vs.column_iter_mut().zip(&self.s) {
            col /= *s;
        }
        &vs * vs.transpose()
    }

    /// U (m × k): an orthonormal basis of the numerical range of J.
    pub(crate) fn range_basis(&self) -> &DMatrix<f64> {
        &self.u
    }

    /// (I − U Uᵀ) S: the part of each column of `s` (m × p) orthogonal to the numerical
    /// range of J, i.e. the residual of its least-squares fit by J's columns. Computed as
    /// S − U (Uᵀ S), never with the m × m projector.
    pub(crate) fn orthogonal_part(&self, s: &DMatrix<f64>) -> DMatrix<f64> {
        s - &self.u * self.u.tr_mul(s)
    }

    /// The Gauss–Newton decrement rᵀJ(JᵀJ)⁺Jᵀr = ‖Uᵀ r‖² (units of r²): what a full
    /// Gauss–Newton step removes from ‖r‖² if the model were linear. In [0, ‖r‖²] for a
    /// finite `r` (length m).
    pub(crate) fn decrement(&self, r: &DVector<f64>) -> f64 {
        self.u.tr_mul(r).norm_squared()
    }
}

/// `vzeroupper` where the CPU has AVX. faer's larger matrix products run hand-written
/// AVX-512 kernels that return with the upper halves of the vector registers in use; until
/// they are cleared, the SSE code of the rest of the crate (compiled for baseline x86-64)
/// runs slower: without this the 1000-row diagnosis (benches/diagnose_1000.sh) takes
/// 1.9-2.1 s of CPU on the 2-core reference machine, with it 1.6-1.7 s, the model's own
/// loops (`interface::graded_factors`) otherwise slowing by a third.
fn clear_upper_vector_state() {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx) = pulp::core_arch::x86::Avx::try_new() {
        avx._mm256_zeroupper();
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    fn random(m: usize, n: usize, seed: u64) -> DMatrix<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        DMatrix::from_fn(m, n, |_, _| StandardNormal.sample(&mut rng))
    }

    fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
        (a - b).norm() / b.norm()
    }

    /// On well-conditioned tall matrices every quantity agrees with the textbook formula
    /// through the inverse of JᵀJ (exact in exact arithmetic at full rank, and accurate
    /// here since κ(J) is small).
    #[test]
    fn agrees_with_the_normal_equations_when_well_conditioned() {
        for (seed, (m, n)) in [(40, 3), (60, 6), (200, 12), (13, 13)].into_iter().enumerate() {
            let j = random(m, n, seed as u64);
            let r = random(m, 1, 100 + seed as u64).column(0).into_owned();
            let s = random(m, 2, 200 + seed as u64);
            let inv = (j.transpose() * &j).try_inverse().unwrap();
            let lsq = LeastSquares::new(&j, 1e-12).unwrap();
            assert_eq!(lsq.rank(), n);
            let x = lsq.solve(&r);
            let x0 = &inv * (j.transpose() * &r);
            assert!((&x - &x0).norm() < 1e-10 * x0.norm(), "{m}×{n}: solve");
            assert!(rel(&lsq.covariance(), &inv) < 1e-10, "{m}×{n}: covariance");
            let p0 = &s - &j * (&inv * (j.transpose() * &s));
            let p = lsq.orthogonal_part(&s);
            // (a square J of full rank spans everything: nothing is left)
            if m > n {
                assert!(rel(&p, &p0) < 1e-10, "{m}×{n}: projection");
            } else {
                assert!(p.norm() < 1e-10 * s.norm(), "{m}×{n}: projection {}", p.norm());
            }
            let g = j.transpose() * &r;
            let d0 = g.dot(&(&inv * &g));
            assert!((lsq.decrement(&r) - d0).abs() < 1e-10 * d0, "{m}×{n}: decrement");
            assert!((lsq.pseudo_inverse() * &r - &x0).norm() < 1e-10 * x0.norm(), "{m}×{n}: J⁺");
        }
    }

    /// A duplicated column: J x ≈ r has a line of solutions, x + t(1, 0, −1); the
    /// minimum-norm one splits the duplicated coefficient evenly, and the covariance has
    /// no part along the null vector.
    #[test]
    fn a_duplicate_column_gives_the_minimum_norm_solution_and_a_null_free_covariance() {
        let base = random(30, 2, 7);
        let j = DMatrix::from_columns(&[base.column(0), base.column(1), base.column(0)]);
        let r = &j * DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let lsq = LeastSquares::new(&j, 1e-7).unwrap();
        assert_eq!(lsq.rank(), 2);
        let x = lsq.solve(&r);
        let want = DVector::from_vec(vec![2.0, 2.0, 2.0]);
        assert!((&x - &want).norm() < 1e-12 * want.norm(), "{x}");
        let cov = lsq.covariance();
        let null = DVector::from_vec(vec![1.0, 0.0, -1.0]) / 2f64.sqrt();
        assert!((&cov * &null).norm() < 1e-12 * cov.norm(), "{cov}");
        // the range part: the inverse of JᵀJ restricted to the row space (compared on the
        // two-column problem it reduces to)
        let reduced = (base.transpose() * &base).try_inverse().unwrap();
        assert!((cov[(1, 1)] - reduced[(1, 1)]).abs() < 1e-12 * reduced[(1, 1)]);
        assert!((cov[(0, 0)] - reduced[(0, 0)] / 4.0).abs() < 1e-12 * reduced[(0, 0)]);
        // the decrement of a residual in the range is all of it
        assert!((lsq.decrement(&r) - r.norm_squared()).abs() < 1e-12 * r.norm_squared());
        assert!(lsq.orthogonal_part(&DMatrix::from_column_slice(r.len(), 1, r.as_slice())).norm() < 1e-12 * r.norm());
    }

    /// Läuchli's matrix [1 1; ε 0; 0 ε] with ε = 1e-9: JᵀJ = [1+ε² 1; 1 1+ε²] rounds to
    /// the singular [1 1; 1 1] (ε² = 1e-18 is below the unit roundoff), so the normal
    /// equations lose the small singular value √1·ε entirely, while the SVD of J keeps it
    /// (κ(J) ≈ 1.4e9). For the consistent r = J (1, 2) the SVD route returns (1, 2) to
    /// about u·κ(J) ≈ 3e-7 relative (tolerance 1e-6); the normal-equations route returns
    /// (1.5, 1.5), off by a third of the answer.
    #[test]
    fn the_lauchli_matrix_is_solved_where_the_normal_equations_fail() {
        let eps = 1e-9;
        let j = DMatrix::from_row_slice(3, 2, &[1.0, 1.0, eps, 0.0, 0.0, eps]);
        let truth = DVector::from_vec(vec![1.0, 2.0]);
        let r = &j * &truth;
        let lsq = LeastSquares::new(&j, 1e-12).unwrap();
        assert_eq!(lsq.rank(), 2);
        let x = lsq.solve(&r);
        assert!((&x - &truth).norm() < 1e-6 * truth.norm(), "SVD of J: {x}");
        // (JᵀJ)⁻¹ = [1+ε² −1; −1 1+ε²] / (ε²(2+ε²)), entries ±5e17
        let c = 1.0 / (eps * eps * (2.0 + eps * eps));
        let exact = DMatrix::from_row_slice(2, 2, &[c, -c, -c, c]);
        assert!(rel(&lsq.covariance(), &exact) < 1e-6, "{}", lsq.covariance());
        assert!(lsq.orthogonal_part(&DMatrix::from_column_slice(r.len(), 1, r.as_slice())).norm() < 1e-12 * r.norm());

        // the normal-equations route (pseudo-inverse of JᵀJ, cutoff 1e-14 of its largest
        // singular value): the small direction is gone
        let h = j.transpose() * &j;
        assert_eq!(h[(0, 0)], h[(0, 1)], "JᵀJ rounds to a singular matrix");
        let svd = h.clone().svd(true, true);
        let old = svd.solve(&(j.transpose() * &r), svd.singular_values.max() * 1e-14).unwrap();
        assert!((&old - &truth).norm() > 0.3 * truth.norm(), "normal equations: {old}");
    }

    /// No parameter (zero columns), no residual (zero rows), a zero matrix: rank 0, zero
    /// solutions and covariance, the identity as projection, no decrement.
    #[test]
    fn empty_and_zero_matrices_have_rank_zero() {
        let r = DVector::from_vec(vec![1.0, -2.0, 3.0]);
        let none = LeastSquares::new(&DMatrix::zeros(3, 0), 1e-7).unwrap();
        assert_eq!(none.rank(), 0);
        assert_eq!(none.solve(&r).len(), 0);
        assert_eq!(none.covariance().shape(), (0, 0));
        assert_eq!(none.pseudo_inverse().shape(), (0, 3));
        assert_eq!(none.decrement(&r), 0.0);
        let s = random(3, 2, 3);
        assert_eq!(none.orthogonal_part(&s), s);

        let rows = LeastSquares::new(&DMatrix::zeros(0, 2), 1e-7).unwrap();
        assert_eq!(rows.solve(&DVector::zeros(0)), DVector::zeros(2));
        assert_eq!(rows.covariance(), DMatrix::zeros(2, 2));

        let zero = LeastSquares::new(&DMatrix::zeros(3, 2), 1e-7).unwrap();
        assert_eq!(zero.rank(), 0);
        assert_eq!(zero.solve(&r), DVector::zeros(2));
        assert_eq!(zero.covariance(), DMatrix::zeros(2, 2));
        assert_eq!(zero.orthogonal_part(&s), s);
    }

    /// A wide J (more parameters than residuals): the minimum-norm solution fits exactly
    /// and lies in the row space; nalgebra's SVD of J agrees.
    #[test]
    fn a_wide_matrix_gives_the_minimum_norm_exact_fit() {
        let j = random(3, 5, 11);
        let r = random(3, 1, 12).column(0).into_owned();
        let lsq = LeastSquares::new(&j, 1e-12).unwrap();
        assert_eq!(lsq.rank(), 3);
        let x = lsq.solve(&r);
        assert!((&j * &x - &r).norm() < 1e-12 * r.norm());
        let x0 = j.clone().svd(true, true).solve(&r, 0.0).unwrap();
        assert!((&x - &x0).norm() < 1e-10 * x0.norm());
        assert!(lsq.decrement(&r) - r.norm_squared() < 1e-12 * r.norm_squared());
    }

    /// Non-finite input: no factorisation (None, returned at once, no panic); a non-finite
    /// right-hand side gives a non-finite solution and decrement, not a panic.
    #[test]
    fn non_finite_input_is_refused() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut j = random(20, 4, 5);
            j[(7, 2)] = bad;
            assert!(LeastSquares::new(&j, 1e-7).is_none());
        }
        let lsq = LeastSquares::new(&random(20, 4, 5), 1e-7).unwrap();
        let mut r = random(20, 1, 6).column(0).into_owned();
        r[3] = f64::NAN;
        assert!(lsq.solve(&r).iter().all(|x| x.is_nan()));
        assert!(lsq.decrement(&r).is_nan());
    }

    /// The cutoff is relative to the largest singular value and strict: a column scaled to
    /// a singular value just below rcond·σ_max is dropped, just above kept.
    #[test]
    fn the_cutoff_is_relative_to_the_largest_singular_value() {
        let mut j = DMatrix::zeros(4, 2);
        j[(0, 0)] = 3.0;
        j[(1, 1)] = 3.0 * 0.9e-7;
        assert_eq!(LeastSquares::new(&j, 1e-7).unwrap().rank(), 1);
        j[(1, 1)] = 3.0 * 1.1e-7;
        assert_eq!(LeastSquares::new(&j, 1e-7).unwrap().rank(), 2);
        // dropped: the solution and covariance are zero along it
        j[(1, 1)] = 1e-9;
        let lsq = LeastSquares::new(&j, 1e-7).unwrap();
        let x = lsq.solve(&DVector::from_vec(vec![3.0, 1.0, 0.0, 0.0]));
        assert_eq!((x[0], x[1]), (1.0, 0.0));
        assert_eq!(lsq.covariance()[(1, 1)], 0.0);
    }
}

//! Coordinate partitioning: which coordinates are independent (the optimiser's unknowns) and
//! which are dependent (completed by Newton on `Phi = 0`).

use crate::error::FaDaeError;
use mbd_model::System;
use mbd_solve::linalg::max_abs;
use nalgebra::DMatrix;

/// The dependent block is square (`m x m`): the equations must be independent.
fn refuse_redundant(sys: &System) -> Result<(), FaDaeError> {
    mbd_solve::refuse_redundant(sys, "the firefly-algorithm DAE solver").map_err(|e| match e {
        mbd_solve::SolveError::Unsupported(s) => FaDaeError::Unsupported(s),
        other => FaDaeError::Unsupported(other.to_string()),
    })
}

/// A split of the `n` coordinates into `dof` independent and `m` dependent ones, such that the
/// dependent block `Phi_q[:, dependent]` is invertible.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Independent coordinates (ascending).
    pub independent: Vec<usize>,
    /// Dependent coordinates (ascending).
    pub dependent: Vec<usize>,
}

impl Partition {
    /// Partition by Gaussian elimination with complete pivoting of `Phi_q(q)`: the `m` pivot
    /// columns (largest remaining entry first) become the dependent coordinates, the rest are
    /// independent. For the two-link manipulator this picks the four centre-of-mass
    /// coordinates as dependent and the two link angles as independent, as the paper does.
    ///
    /// # Errors
    /// [`FaDaeError::Unsupported`] if `Phi_q` is rank deficient (redundant constraints or a
    /// singular configuration) or the system has no degree of freedom.
    pub fn auto(sys: &System, q: &[f64]) -> Result<Partition, FaDaeError> {
        refuse_redundant(sys)?;
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        if m >= n {
            return Err(FaDaeError::Unsupported(format!(
                "{m} constraints on {n} coordinates leave no degree of freedom to optimise"
            )));
        }
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, &mut j);
        let mut piv = Pivoting::new(m, n);
        match piv.eliminate(&j) {
            Ok(_) => Ok(piv.partition()),
            Err(k) => Err(FaDaeError::Unsupported(format!(
                "Phi_q is rank deficient (rank {k} < {m} constraints): redundant constraints \
                 or a singular configuration; equation {}",
                sys.equation_name(piv.rows[k])
            ))),
        }
    }

    /// A partition with the given independent coordinates; checks the indices and that the
    /// dependent block of `Phi_q(q)` is invertible.
    ///
    /// # Errors
    /// [`FaDaeError::InvalidPartition`] for a wrong count (must equal the degrees of freedom
    /// `n - m`), an index out of range, a duplicate, or a singular dependent block at `q`.
    pub fn given(sys: &System, q: &[f64], independent: &[usize]) -> Result<Partition, FaDaeError> {
        refuse_redundant(sys)?;
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let bad = |reason: String| FaDaeError::InvalidPartition {
            given: independent.to_vec(),
            reason,
        };
        if m >= n {
            return Err(FaDaeError::Unsupported(format!(
                "{m} constraints on {n} coordinates leave no degree of freedom to optimise"
            )));
        }
        if independent.len() != n - m {
            return Err(bad(format!(
                "{} indices given, but the system has {} degrees of freedom ({n} coordinates, {m} constraints)",
                independent.len(),
                n - m
            )));
        }
        let mut seen = vec![false; n];
        for &i in independent {
            if i >= n {
                return Err(bad(format!("index {i} out of range (n = {n})")));
            }
            if seen[i] {
                return Err(bad(format!("index {i} given twice")));
            }
            seen[i] = true;
        }
        let mut ind = independent.to_vec();
        ind.sort_unstable();
        let dep: Vec<usize> = (0..n).filter(|i| !seen[*i]).collect();
        let p = Partition {
            independent: ind,
            dependent: dep,
        };
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, &mut j);
        let mut lu = crate::objective::small_lu(m);
        p.fill_dependent_block(&j, lu.rows_mut());
        match lu.factor_lu().map(|()| lu.pivot_range()) {
            Ok((pmin, pmax)) if pmin > 1e-10 * pmax => Ok(p),
            _ => Err(bad(
                "the dependent block of Phi_q is singular at the initial state: these \
                 coordinates cannot be chosen freely"
                    .into(),
            )),
        }
    }

    /// Number of independent coordinates (degrees of freedom).
    pub fn dof(&self) -> usize {
        self.independent.len()
    }

    /// Copies `Phi_q[:, dependent]` into a row-major `m x m` buffer.
    pub(crate) fn fill_dependent_block(&self, j: &DMatrix<f64>, out: &mut [f64]) {
        let m = self.dependent.len();
        for r in 0..m {
            for (c, &col) in self.dependent.iter().enumerate() {
                out[r * m + c] = j[(r, col)];
            }
        }
    }
}

/// Gaussian elimination with complete pivoting of an `m x n` Jacobian `Phi_q`, with its own
/// buffers (allocation-free after construction): the choice of [`Partition::auto`], and the
/// yardstick of the repartitioning test (the best available dependent block).
#[derive(Clone, Debug)]
pub(crate) struct Pivoting {
    j: DMatrix<f64>,
    rows: Vec<usize>,
    cols: Vec<usize>,
}

impl Pivoting {
    pub(crate) fn new(m: usize, n: usize) -> Self {
        Pivoting {
            j: DMatrix::zeros(m, n),
            rows: (0..m).collect(),
            cols: (0..n).collect(),
        }
    }

    /// Eliminates a copy of `jac`: the `m` pivot columns (largest remaining entry first, lowest
    /// index on ties) are the chosen dependent coordinates. Returns `ln |det|` of the chosen
    /// block (the sum of the logarithms of the pivot magnitudes), or `Err(k)` if the `k`-th
    /// pivot is at most `1e-10` of the largest entry (or NaN): `Phi_q` is rank deficient.
    pub(crate) fn eliminate(&mut self, jac: &DMatrix<f64>) -> Result<f64, usize> {
        let (m, n) = (self.rows.len(), self.cols.len());
        let j = &mut self.j;
        j.copy_from(jac);
        for (i, r) in self.rows.iter_mut().enumerate() {
            *r = i;
        }
        for (i, c) in self.cols.iter_mut().enumerate() {
            *c = i;
        }
        let scale = max_abs(j.as_slice());
        let mut log_det = 0.0;
        for k in 0..m {
            // complete pivoting over the remaining block
            let (mut pr, mut pc, mut best) = (k, k, -1.0f64);
            for ri in k..m {
                for ci in k..n {
                    let v = j[(self.rows[ri], self.cols[ci])].abs();
                    // strict `>` keeps the lowest index on ties: deterministic
                    if v > best {
                        best = v;
                        pr = ri;
                        pc = ci;
                    }
                }
            }
            if best.is_nan() || best <= 1e-10 * scale.max(f64::MIN_POSITIVE) {
                return Err(k);
            }
            self.rows.swap(k, pr);
            self.cols.swap(k, pc);
            log_det += best.ln();
            let (r0, c0) = (self.rows[k], self.cols[k]);
            let p = j[(r0, c0)];
            for &r in &self.rows[k + 1..] {
                let l = j[(r, c0)] / p;
                if l != 0.0 {
                    for &c in &self.cols[k..] {
                        let v = j[(r0, c)];
                        j[(r, c)] -= l * v;
                    }
                }
            }
        }
        Ok(log_det)
    }

    /// The partition chosen by the last successful [`Pivoting::eliminate`].
    pub(crate) fn partition(&self) -> Partition {
        let m = self.rows.len();
        let mut dependent = self.cols[..m].to_vec();
        let mut independent = self.cols[m..].to_vec();
        dependent.sort_unstable();
        independent.sort_unstable();
        Partition {
            independent,
            dependent,
        }
    }
}

//! Coordinate partitioning: which coordinates are independent (the optimiser's unknowns) and
//! which are dependent (completed by Newton on `Phi = 0`).

use crate::error::FaDaeError;
use mbd_model::System;
use mbd_solve::linalg::max_abs;
use nalgebra::DMatrix;

/// `Partition::auto` and `Partition::given` need at least one degree of freedom.
fn no_dof(sys: &System) -> FaDaeError {
    let (n, m, k) = (sys.n_coords(), sys.n_constraints(), sys.n_redundant());
    if k == 0 {
        FaDaeError::Unsupported(format!(
            "{m} constraints on {n} coordinates leave no degree of freedom to optimise"
        ))
    } else {
        FaDaeError::Unsupported(format!(
            "{m} constraints ({k} of them redundant) on {n} coordinates leave no degree of \
             freedom to optimise"
        ))
    }
}

/// The error of [`Partition::auto`] (or of a check of [`Partition::given`]) when `Phi_q(q)`
/// does not have the rank `m - k` that the build found (`k` redundant equations).
fn rank_error(sys: &System, piv: &Pivoting, e: RankError) -> FaDaeError {
    let (m, k) = (sys.n_constraints(), sys.n_redundant());
    match e {
        RankError::Deficient(i) if k == 0 => FaDaeError::Unsupported(format!(
            "Phi_q is rank deficient (rank {i} < {m} constraints): redundant constraints \
             or a singular configuration; equation {}",
            sys.equation_name(piv.rows[i])
        )),
        RankError::Deficient(i) => FaDaeError::Unsupported(format!(
            "Phi_q is rank deficient (rank {i} < {} = {m} constraints - {k} redundant): a \
             singular configuration or more redundant constraints than the build found; \
             equation {}",
            m - k,
            sys.equation_name(piv.rows[i])
        )),
        RankError::Excess(row) => {
            let names: Vec<&str> = sys
                .redundant_equations()
                .iter()
                .map(|e| e.equation.as_str())
                .collect();
            FaDaeError::Unsupported(format!(
                "the redundancy found at build is gone: Phi_q has rank above {} = {m} \
                 constraints - {k} redundant at this configuration (redundant at build: {}); \
                 equation {} is independent of the others",
                m - k,
                names.join(", "),
                sys.equation_name(row)
            ))
        }
    }
}

/// A split of the `n` coordinates into `dof` independent and `r` dependent ones, and a choice
/// of `r` equations (rows of `Phi`) such that the dependent block
/// `Phi_q[equations, dependent]` is invertible. `r = m - k` is the rank of `Phi_q`: `m`
/// without redundant equations (then `equations` is every row), `m - k` for a mechanism with
/// `k` redundant equations ([`System::n_redundant`]), whose other rows are combinations of
/// these and hold wherever these do.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Independent coordinates (ascending).
    pub independent: Vec<usize>,
    /// Dependent coordinates (ascending).
    pub dependent: Vec<usize>,
    /// The equations (rows of `Phi`, ascending) that complete the dependent coordinates, as
    /// many as dependent coordinates.
    pub equations: Vec<usize>,
}

impl Partition {
    /// Partition by Gaussian elimination with complete pivoting of `Phi_q(q)`: the `r = m - k`
    /// pivot columns (largest remaining entry first) become the dependent coordinates, the
    /// rest are independent, and the `r` pivot rows are the equations that complete them
    /// (`k` = [`System::n_redundant`]). For the two-link manipulator this picks the four
    /// centre-of-mass coordinates as dependent and the two link angles as independent, as
    /// the paper does.
    ///
    /// # Errors
    /// [`FaDaeError::Unsupported`] if the system has no degree of freedom, if `Phi_q(q)` has
    /// rank below `m - k` (a singular configuration: a pivot at most `1e-10` of the largest
    /// entry) or above it (the redundancy found at build is gone: a row left after `m - k`
    /// pivots has an entry above that tolerance); the message names the equation.
    pub fn auto(sys: &System, q: &[f64], t: f64) -> Result<Partition, FaDaeError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        if sys.dof() == 0 {
            return Err(no_dof(sys));
        }
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, t, &mut j);
        let mut piv = Pivoting::new(m, n, sys.n_redundant());
        match piv.eliminate(&j) {
            Ok(_) => Ok(piv.partition()),
            Err(e) => Err(rank_error(sys, &piv, e)),
        }
    }

    /// The partition [`Partition::auto`] chooses, on a singular configuration of a model that
    /// starts on one (`System::singular_start_equations`): the elimination takes its last
    /// pivots, one per equation dependent at the start only, without the rank test (the
    /// largest entries left, at round-off there). The dependent block is singular at `q` but
    /// not an instant later, where the solver's repartitioning test replaces it by the best
    /// block if it is poor; the step from `q` itself is taken by the singular starter.
    /// `None` where the model does not start on a singular configuration, or the
    /// elimination fails anyway.
    pub(crate) fn at_singular_start(sys: &System, q: &[f64], t: f64) -> Option<Partition> {
        let extra = sys.singular_start_equations().len();
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        if extra == 0 || sys.dof() == 0 || q.len() != n {
            return None;
        }
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, t, &mut j);
        let mut piv = Pivoting::new(m, n, sys.n_redundant());
        piv.waive = extra;
        piv.eliminate(&j).ok().map(|_| piv.partition())
    }

    /// A partition with the given independent coordinates; checks the indices and that the
    /// dependent block of `Phi_q(q, t)` is invertible. With `k > 0` redundant equations the `r`
    /// equations are chosen by Gaussian elimination with complete pivoting of `Phi_q(q)` with
    /// the pivot columns restricted to the dependent coordinates.
    ///
    /// # Errors
    /// [`FaDaeError::InvalidPartition`] for a wrong count (must equal the degrees of freedom
    /// [`System::dof`], `n - m + k`), an index out of range, a duplicate, or a singular
    /// dependent block at `q`; [`FaDaeError::Unsupported`] for a system without degrees of
    /// freedom or (with redundant equations) a `Phi_q(q)` whose rank is not `m - k`.
    pub fn given(
        sys: &System,
        q: &[f64],
        t: f64,
        independent: &[usize],
    ) -> Result<Partition, FaDaeError> {
        let (n, m, k) = (sys.n_coords(), sys.n_constraints(), sys.n_redundant());
        let bad = |reason: String| FaDaeError::InvalidPartition {
            given: independent.to_vec(),
            reason,
        };
        let dof = sys.dof();
        if dof == 0 {
            return Err(no_dof(sys));
        }
        if independent.len() != dof {
            let redundant = if k == 0 {
                String::new()
            } else {
                format!(", {k} of them redundant")
            };
            return Err(bad(format!(
                "{} indices given, but the system has {dof} degrees of freedom ({n} \
                 coordinates, {m} constraints{redundant})",
                independent.len(),
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
        let singular = || {
            bad(
                "the dependent block of Phi_q is singular at the initial state: these \
                 coordinates cannot be chosen freely"
                    .into(),
            )
        };
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, t, &mut j);
        let equations = if k == 0 {
            (0..m).collect()
        } else {
            let mut piv = Pivoting::new(m, n, k);
            match piv.eliminate_with_dependent(&j, &dep) {
                Ok(_) => piv.partition().equations,
                Err(RankError::Deficient(_)) => return Err(singular()),
                Err(e) => return Err(rank_error(sys, &piv, e)),
            }
        };
        let p = Partition {
            independent: ind,
            dependent: dep,
            equations,
        };
        let r = p.dependent.len();
        let mut lu = crate::objective::small_lu(r);
        p.fill_dependent_block(&j, lu.rows_mut());
        match lu.factor_lu().map(|()| lu.pivot_range()) {
            Ok((pmin, pmax)) if pmin > 1e-10 * pmax => Ok(p),
            _ => Err(singular()),
        }
    }

    /// Number of independent coordinates (degrees of freedom).
    pub fn dof(&self) -> usize {
        self.independent.len()
    }

    /// Copies `Phi_q[equations, dependent]` into a row-major `r x r` buffer.
    pub(crate) fn fill_dependent_block(&self, j: &DMatrix<f64>, out: &mut [f64]) {
        crate::objective::fill_block(j, &self.equations, &self.dependent, out);
    }
}

/// Why [`Pivoting`] found no partition: `Phi_q` does not have the expected rank `m - k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RankError {
    /// Pivot `i` (counting from 0, `i < m - k`) is at most the tolerance (or NaN): rank
    /// deficient, a singular configuration.
    Deficient(usize),
    /// After `m - k` pivots this row of `Phi_q` still has an entry above the tolerance: fewer
    /// than `k` equations are dependent.
    Excess(usize),
}

/// Gaussian elimination with complete pivoting of an `m x n` Jacobian `Phi_q` of rank
/// `r = m - k` (`k` redundant equations), with its own buffers (allocation-free after
/// construction): the choice of [`Partition::auto`], and the yardstick of the repartitioning
/// test (the best available dependent block).
#[derive(Clone, Debug)]
pub(crate) struct Pivoting {
    j: DMatrix<f64>,
    rows: Vec<usize>,
    cols: Vec<usize>,
    /// The number `k` of rows expected to be dependent.
    redundant: usize,
    /// The last pivots taken without the rank test (0 but on a singular start, see
    /// [`Partition::at_singular_start`]).
    waive: usize,
}

impl Pivoting {
    /// Buffers for `m x n` Jacobians with `redundant <= m` dependent rows.
    pub(crate) fn new(m: usize, n: usize, redundant: usize) -> Self {
        Pivoting {
            j: DMatrix::zeros(m, n),
            rows: (0..m).collect(),
            cols: (0..n).collect(),
            redundant: redundant.min(m),
            waive: 0,
        }
    }

    /// Eliminates a copy of `jac`: the `r = m - k` pivot columns (largest remaining entry
    /// first, lowest index on ties) are the chosen dependent coordinates, the pivot rows the
    /// equations. Returns `ln |det|` of the chosen `r x r` block (the sum of the logarithms of
    /// the pivot magnitudes), or the [`RankError`] (tolerance: `1e-10` of the largest entry).
    pub(crate) fn eliminate(&mut self, jac: &DMatrix<f64>) -> Result<f64, RankError> {
        for (i, c) in self.cols.iter_mut().enumerate() {
            *c = i;
        }
        let n = self.cols.len();
        self.reduce(jac, n)
    }

    /// As [`Pivoting::eliminate`] with the pivot columns restricted to `dep` (`r` columns):
    /// the `r` equations for given dependent coordinates.
    pub(crate) fn eliminate_with_dependent(
        &mut self,
        jac: &DMatrix<f64>,
        dep: &[usize],
    ) -> Result<f64, RankError> {
        let n = self.cols.len();
        let mut k = 0;
        for &c in dep {
            self.cols[k] = c;
            k += 1;
        }
        for c in 0..n {
            if !dep.contains(&c) {
                self.cols[k] = c;
                k += 1;
            }
        }
        self.reduce(jac, dep.len())
    }

    /// The elimination, with pivot columns searched among the first `ncand` of `self.cols`
    /// (every remaining column is reduced).
    fn reduce(&mut self, jac: &DMatrix<f64>, ncand: usize) -> Result<f64, RankError> {
        let m = self.rows.len();
        let r = m - self.redundant;
        let j = &mut self.j;
        j.copy_from(jac);
        for (i, row) in self.rows.iter_mut().enumerate() {
            *row = i;
        }
        let scale = max_abs(j.as_slice());
        let tol = 1e-10 * scale.max(f64::MIN_POSITIVE);
        let mut log_det = 0.0;
        for k in 0..r {
            // complete pivoting over the remaining block
            let (mut pr, mut pc, mut best) = (k, k, -1.0f64);
            for ri in k..m {
                for ci in k..ncand {
                    let v = j[(self.rows[ri], self.cols[ci])].abs();
                    // strict `>` keeps the lowest index on ties: deterministic
                    if v > best {
                        best = v;
                        pr = ri;
                        pc = ci;
                    }
                }
            }
            if best.is_nan() || (best <= tol && k + self.waive < r) {
                return Err(RankError::Deficient(k));
            }
            // (a waived pivot at round-off or zero: the column and row are kept, the
            // determinant's logarithm gets the tolerance)
            let best_ln = best.max(tol).ln();
            self.rows.swap(k, pr);
            self.cols.swap(k, pc);
            log_det += best_ln;
            let (r0, c0) = (self.rows[k], self.cols[k]);
            let p = j[(r0, c0)];
            // (a waived pivot may be exactly zero: nothing to eliminate with)
            let rest = if p == 0.0 {
                &[][..]
            } else {
                &self.rows[k + 1..]
            };
            for &row in rest {
                let l = j[(row, c0)] / p;
                if l != 0.0 {
                    for &c in &self.cols[k..] {
                        let v = j[(r0, c)];
                        j[(row, c)] -= l * v;
                    }
                }
            }
        }
        // the k rows left are combinations of the pivot rows: reduced to round-off
        for &row in &self.rows[r..] {
            for &c in &self.cols[r..] {
                let v = j[(row, c)].abs();
                if v.is_nan() {
                    return Err(RankError::Deficient(r));
                }
                if v > tol {
                    return Err(RankError::Excess(row));
                }
            }
        }
        Ok(log_det)
    }

    /// The partition chosen by the last successful elimination.
    pub(crate) fn partition(&self) -> Partition {
        let r = self.rows.len() - self.redundant;
        let mut dependent = self.cols[..r].to_vec();
        let mut independent = self.cols[r..].to_vec();
        let mut equations = self.rows[..r].to_vec();
        dependent.sort_unstable();
        independent.sort_unstable();
        equations.sort_unstable();
        Partition {
            independent,
            dependent,
            equations,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_model::models::parallelogram_four_bar;

    /// On the flat start every dependent block is singular: `auto` refuses it, the
    /// provisional partition has the shape `auto` gives a step later (9 coordinates, 8
    /// equations: 1 independent); a model that does not start flat has none.
    #[test]
    fn a_flat_start_gets_a_provisional_partition_of_the_right_shape() {
        let sys = parallelogram_four_bar(0.4, 1.0, 0.0, 6.0, false).unwrap();
        let (q0, _) = sys.initial_guess();
        assert!(Partition::auto(&sys, q0.as_slice(), 0.0).is_err());
        let p = Partition::at_singular_start(&sys, q0.as_slice(), 0.0).unwrap();
        assert_eq!((p.independent.len(), p.dependent.len()), (1, 8));
        assert_eq!(p.equations, (0..8).collect::<Vec<_>>());
        let regular = parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, false).unwrap();
        let (r0, _) = regular.initial_guess();
        assert!(Partition::at_singular_start(&regular, r0.as_slice(), 0.0).is_none());
        assert!(Partition::auto(&regular, r0.as_slice(), 0.0).is_ok());
    }
}

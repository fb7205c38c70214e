//! The index-1 acceleration solve for large systems: the Schur complement
//! `S = Phi_q M^-1 Phi_q^T` is assembled directly in compressed sparse column form (its pattern
//! couples two constraint equations only when they act on a common body) and factored by faer's
//! sparse Cholesky. The symbolic analysis (fill-reducing ordering, elimination tree) is done once
//! in [`SparseAccelerationSolver::new`]; each solve refills the values and runs the numeric
//! factorisation into preallocated storage, so a solve allocates nothing. For a chain of `N`
//! bodies `S` is block tridiagonal and a solve costs `O(N)`, against `O(N^3)` for the dense path.

use crate::error::SolveError;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use mbd_model::{JointHandle, System};

struct Scratch(MemBuffer);
impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Scratch")
    }
}

/// One contribution to an entry of `S`: rows `r1 >= r2` both act on `body`; `o1`, `o2` are the
/// offsets (0 or 3) of that body in the rows' local gradients; `idx` is the value slot.
#[derive(Clone, Copy, Debug)]
struct Contribution {
    r1: usize,
    r2: usize,
    o1: usize,
    o2: usize,
    body: usize,
    idx: usize,
}

/// Sparse index-1 solver (see the module documentation).
#[derive(Debug)]
pub struct SparseAccelerationSolver {
    n: usize,
    m: usize,
    /// Element-local rows of `Phi_q` at the last solve.
    pub grads: Vec<[f64; 6]>,
    /// `gamma` at the last solve (callers may modify it before [`SparseAccelerationSolver::finish`]).
    pub gamma: Vec<f64>,
    /// Applied forces `Q` at the last solve.
    pub forces: Vec<f64>,
    row_bodies: Vec<(Option<usize>, Option<usize>)>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    contributions: Vec<Contribution>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    mem: Scratch,
    w: Vec<f64>,
}

impl SparseAccelerationSolver {
    /// Analyses the pattern of `S` for `sys` (allocates; done once).
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let mut row_bodies = vec![(None, None); m];
        for j in 0..sys.joints().len() {
            let jb = sys.joint_bodies(JointHandle(j));
            for r in sys.joint_rows(JointHandle(j)) {
                row_bodies[r] = jb;
            }
        }
        // rows touching each body, with the offset of the body in the row's local gradient
        let nb = n / 3;
        let mut by_body: Vec<Vec<(usize, usize)>> = vec![Vec::new(); nb];
        for (r, &(a, b)) in row_bodies.iter().enumerate() {
            if let Some(a) = a {
                by_body[a].push((r, 0));
            }
            if let Some(b) = b {
                by_body[b].push((r, 3));
            }
        }
        // lower-triangular pattern: (col = r2, row = r1) with r1 >= r2, plus the diagonal
        let mut entries: Vec<(usize, usize)> = (0..m).map(|r| (r, r)).collect();
        for rows in &by_body {
            for &(r1, _) in rows {
                for &(r2, _) in rows {
                    if r1 >= r2 {
                        entries.push((r2, r1));
                    }
                }
            }
        }
        entries.sort_unstable();
        entries.dedup();
        let mut col_ptr = vec![0usize; m + 1];
        let mut row_idx = Vec::with_capacity(entries.len());
        for &(c, r) in &entries {
            col_ptr[c + 1] += 1;
            row_idx.push(r);
        }
        for c in 0..m {
            col_ptr[c + 1] += col_ptr[c];
        }
        let slot = |c: usize, r: usize| -> usize {
            let s = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            col_ptr[c] + s.binary_search(&r).unwrap_or(0)
        };
        let mut contributions = Vec::new();
        for (body, rows) in by_body.iter().enumerate() {
            for &(r1, o1) in rows {
                for &(r2, o2) in rows {
                    if r1 >= r2 {
                        contributions.push(Contribution {
                            r1,
                            r2,
                            o1,
                            o2,
                            body,
                            idx: slot(r2, r1),
                        });
                    }
                }
            }
        }
        let nnz = row_idx.len();
        let sym = SymbolicSparseColMat::<usize>::new_checked(
            m,
            m,
            col_ptr.clone(),
            None,
            row_idx.clone(),
        );
        let symbolic = factorize_symbolic_cholesky(
            sym.as_ref(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| SolveError::Unsupported(format!("sparse symbolic analysis failed: {e:?}")))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let l_values = vec![0.0; symbolic.len_val()];
        Ok(SparseAccelerationSolver {
            n,
            m,
            grads: vec![[0.0; 6]; m],
            gamma: vec![0.0; m],
            forces: vec![0.0; n],
            row_bodies,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            contributions,
            symbolic,
            l_values,
            mem: Scratch(MemBuffer::new(req)),
            w: vec![0.0; n],
        })
    }

    /// Non-zeros stored for the lower triangle of `S`.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Accelerations `a` and multipliers `lambda` at `(q, v, t)`.
    pub fn solve(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        if q.len() != self.n || v.len() != self.n || a.len() != self.n || lambda.len() != self.m {
            return Err(SolveError::Dimension {
                what: "sparse acceleration solve arguments",
                expected: self.n,
                got: q.len(),
            });
        }
        sys.forces_into(q, v, t, &mut self.forces);
        sys.phi_q_local_gamma(q, v, t, &mut self.grads, &mut self.gamma);
        self.finish(sys, t, a, lambda)
    }

    /// Completes the solve from `grads`, `gamma` and `forces` already set.
    pub fn finish(
        &mut self,
        sys: &System,
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        let minv = sys.inv_mass_diag().as_slice();
        for ((w, &mi), &f) in self.w.iter_mut().zip(minv).zip(&self.forces) {
            *w = mi * f;
        }
        if self.m == 0 {
            a.copy_from_slice(&self.w);
            return Ok(());
        }
        self.values.fill(0.0);
        for c in &self.contributions {
            let (g1, g2) = (&self.grads[c.r1], &self.grads[c.r2]);
            let mut acc = 0.0;
            for l in 0..3 {
                acc += g1[c.o1 + l] * minv[3 * c.body + l] * g2[c.o2 + l];
            }
            self.values[c.idx] += acc;
        }
        // rhs = Phi_q M^-1 Q - gamma
        for (r, lr) in lambda.iter_mut().enumerate() {
            let g = &self.grads[r];
            let (ba, bb) = self.row_bodies[r];
            let mut x = -self.gamma[r];
            if let Some(b) = ba {
                for l in 0..3 {
                    x += g[l] * self.w[3 * b + l];
                }
            }
            if let Some(b) = bb {
                for l in 0..3 {
                    x += g[3 + l] * self.w[3 * b + l];
                }
            }
            *lr = x;
        }
        let m = self.m;
        let sym = SymbolicSparseColMatRef::new_checked(m, m, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &self.values);
        let stack = MemStack::new(&mut self.mem.0);
        let llt = self
            .symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                mat,
                Side::Lower,
                Default::default(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .map_err(|e| SolveError::Singular {
                t,
                what: "sparse constraint matrix Phi_q M^-1 Phi_q^T",
                detail: format!("{e:?}"),
            })?;
        let llt: LltRef<'_, usize, f64> = llt;
        let stack = MemStack::new(&mut self.mem.0);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(lambda, m, 1),
            Par::Seq,
            stack,
        );
        // a = M^-1 (Q - Phi_q^T lambda)
        a.copy_from_slice(&self.w);
        for (r, &lr) in lambda.iter().enumerate() {
            let g = &self.grads[r];
            let (ba, bb) = self.row_bodies[r];
            if let Some(b) = ba {
                for l in 0..3 {
                    a[3 * b + l] -= minv[3 * b + l] * g[l] * lr;
                }
            }
            if let Some(b) = bb {
                for l in 0..3 {
                    a[3 * b + l] -= minv[3 * b + l] * g[3 + l] * lr;
                }
            }
        }
        if !lambda.iter().all(|x| x.is_finite()) {
            return Err(SolveError::Singular {
                t,
                what: "sparse constraint matrix Phi_q M^-1 Phi_q^T",
                detail: "non-finite multipliers".into(),
            });
        }
        Ok(())
    }
}

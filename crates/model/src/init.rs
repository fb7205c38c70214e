//! Redundant equations and the rank check of the constraint Jacobian (consistent initial states are
//! `mbd_solve::consistent_state`, on the solver core's projection).

use crate::error::ModelError;
use crate::system::System;
use faer::{Mat, Side};
use mbd_linalg::{max_abs, SparseCholesky};
use nalgebra::{DMatrix, DVector};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Above this many constraint equations [`System::check_rank`] factors the Schur complement
/// `Phi_q M^-1 Phi_q^T` as a sparse matrix (memory and time linear in the size of a chain)
/// instead of forming `Phi_q` densely.
pub const SPARSE_RANK_THRESHOLD: usize = 200;

/// What [`crate::SystemBuilder::build`] does with constraint equations that are combinations
/// of others at the initial configuration (a double parallelogram's third crank, a
/// pantograph's extra bar: the mechanism moves, but `Phi_q` has fewer independent rows than
/// equations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum RedundantConstraints {
    /// Build the system and report the dependent equations
    /// ([`System::redundant_equations`]); every solver then drops, at each factorisation, the
    /// equations that depend on earlier ones (their multipliers are zero).
    #[default]
    Allow,
    /// Refuse the model with [`ModelError::Redundant`] naming the first dependent equation.
    Reject,
}

/// A constraint equation that is a combination of the equations before it (at the
/// configuration where [`System::redundant_at`] looked).
#[derive(Clone, Debug, PartialEq)]
pub struct RedundantEquation {
    /// Its row in `Phi`.
    pub row: usize,
    /// Its name (`joint.label`, see [`System::equation_name`]).
    pub equation: String,
    /// The joints whose equations it combines (its own first): with the dense test those
    /// whose equations enter the combination, with the sparse test those sharing a body with
    /// it.
    pub joints: Vec<String>,
}

impl RedundantEquation {
    fn into_error(self) -> ModelError {
        ModelError::Redundant {
            equation: self.equation,
            joints: self.joints,
        }
    }
}

impl System {
    /// The redundant equations, in row order (empty for a mechanism whose equations are
    /// independent): those that depend on earlier ones at the build configuration and still
    /// do at configurations of the manifold near it (a structural dependence, which holds
    /// along the motion). An equation dependent at the build configuration only is not
    /// redundant: the mechanism starts on a singular configuration
    /// ([`System::singular_start_equations`]).
    pub fn redundant_equations(&self) -> &[RedundantEquation] {
        &self.redundant
    }

    /// The number of redundant equations, `m - rank(Phi_q)` near the build configuration.
    pub fn n_redundant(&self) -> usize {
        self.redundant.len()
    }

    /// The equations that depend on the others at the build configuration but not near it on
    /// the manifold: the mechanism starts on a singular configuration (a parallelogram
    /// four-bar with its cranks in line with the ground). Empty when the build configuration
    /// is regular, and above [`SPARSE_RANK_THRESHOLD`] equations (the test is dense).
    pub fn singular_start_equations(&self) -> &[RedundantEquation] {
        &self.singular_start
    }

    /// A note on a singular initial configuration for the user (`None` on a regular one):
    /// which equations depend on the others there, and what that means for the solvers and
    /// the outputs at the start.
    pub fn singular_start_note(&self) -> Option<String> {
        if self.singular_start.is_empty() {
            return None;
        }
        let names: Vec<&str> = self
            .singular_start
            .iter()
            .map(|e| e.equation.as_str())
            .collect();
        Some(format!(
            "the initial configuration is singular: {} equation(s) ({}) depend on the others \
             there but not along the motion; the solvers that keep the constraints pass it (the \
             tangent-chart solvers, symplectic (1,1) and FA-DAE by a first step of projected RK, \
             their own steps having no solution there), the consistent start velocity \
             is the nearest on a branch of the motion (give the motion's velocities to choose \
             the branch), and the multipliers (reactions, drivers' torques) at the start are not \
             determined",
            names.len(),
            names.join(", ")
        ))
    }

    /// The dependent rows a solver's factorisation may drop: the redundant equations and, on a
    /// singular initial configuration, the equations dependent there only, so that the solvers
    /// that factor `Phi_q M^-1 Phi_q^T` (or their own systems with `Phi_q`) pass the start
    /// (the accelerations are determined there; the multipliers are not). A configuration
    /// where the rank falls further is singular.
    pub fn dependency_budget(&self) -> usize {
        self.redundant.len() + self.singular_start.len()
    }

    /// The equations of `Phi_q(q, t)` that depend on the ones before them, in row order (the rows
    /// a factorisation in the natural order drops). Below [`SPARSE_RANK_THRESHOLD`] equations
    /// a Gram-Schmidt pass over the rows (a row is dependent when its part outside the span of
    /// the earlier rows is below `1e-9` of the largest row norm); above, a semidefinite sparse
    /// Cholesky factorisation of `Phi_q M^-1 Phi_q^T` (pivot ratios below
    /// [`mbd_linalg::DEPENDENT_PIVOT_TOL`]), linear in the size of a chain.
    pub fn redundant_at(&self, q: &[f64], t: f64) -> Result<Vec<RedundantEquation>, ModelError> {
        self.check_len("q", q, self.n)?;
        if self.m == 0 {
            return Ok(Vec::new());
        }
        if self.m > SPARSE_RANK_THRESHOLD {
            return self.redundant_sparse(q, t);
        }
        let mut jac = DMatrix::zeros(self.m, self.n);
        self.phi_q(q, t, &mut jac);
        // Fast path: a well-conditioned Cholesky factor of Phi_q M^-1 Phi_q^T proves full rank.
        if self.schur_well_conditioned(&jac) {
            return Ok(Vec::new());
        }
        Ok(self.redundant_dense(&jac, 1e-9))
    }

    /// Positive weights, one per coordinate, for rank tests of `Phi_q` that depend neither on
    /// the units of the coordinates nor on how the mass is shared between the bodies: 1 on a
    /// body's (or point mass's) position coordinates, `m / J` on a planar body's angle and
    /// `m / J_max` on a spatial body's directors (`M^-1` of each body scaled by its mass; for
    /// a spatial body, whose `M` may be singular with a zero `E_i`, the largest moment stands
    /// in for the director masses). `Phi_q W Phi_q^T` has the rank of `Phi_q` for any positive
    /// `W`; with these, a relative tolerance on `Phi_q W^(1/2)` compares a joint's angle
    /// columns with its position columns as the body's radius of gyration does (an angle
    /// column is a lever arm), so a mechanism measured in millimetres is not "near singular"
    /// because its lever arms are small numbers in metres, and a gram-light link carrying a
    /// tonne is not because `M^-1` would weigh its columns a million times above the load's.
    /// Allocates.
    pub fn rank_weights(&self) -> Vec<f64> {
        let mut w = vec![1.0; self.n];
        for (i, b) in self.bodies.iter().enumerate() {
            w[3 * i + 2] = b.mass / b.inertia;
        }
        for (k, b) in self.spatial.bodies.iter().enumerate() {
            let o = self.spatial.q0 + 12 * k;
            let j = b.inertia.moments();
            let jmax = j[0].max(j[1]).max(j[2]);
            // a point mass has no directors (and no moments)
            if jmax > 0.0 && o + 12 <= w.len() {
                w[o + 3..o + 12].fill(b.inertia.mass() / jmax);
            }
        }
        w
    }

    /// The equations of `Phi_q(q)` nearest to dependence, for a report at a near-singular
    /// configuration: those whose gradient lies within an angle `asin(rel_tol)` of the span of
    /// the earlier ones (Gram-Schmidt, as [`System::redundant_at`], on the rows scaled to unit
    /// norm), with the columns weighted by the square roots of [`System::rank_weights`]: the
    /// test depends neither on the units of lengths nor on those of the equations. Without the
    /// equations found redundant at build time. Empty above [`SPARSE_RANK_THRESHOLD`]
    /// equations (the sparse factorisation reports exact dependence only).
    pub fn nearly_dependent_at(&self, q: &[f64], t: f64, rel_tol: f64) -> Vec<RedundantEquation> {
        if q.len() != self.n || self.m == 0 || self.m > SPARSE_RANK_THRESHOLD {
            return Vec::new();
        }
        let jac = self.unit_free_jacobian(q, t);
        let mut found = self.redundant_dense(&jac, rel_tol);
        found.retain(|e| !self.redundant.iter().any(|r| r.row == e.row));
        found
    }

    /// The condition of `Phi_q(q)` in the unit-free measure of [`System::nearly_dependent_at`]:
    /// `1 / sin^2` of the smallest angle between an equation's gradient and the span of the
    /// earlier ones (columns weighted by [`System::rank_weights`], rows scaled to unit norm),
    /// without the equations found redundant at build time; infinite when an equation depends
    /// on the earlier ones. The same quantity as the index-1 solves' condition estimate
    /// (`max_j S_jj / L_jj^2` of `S = Phi_q M^-1 Phi_q^T`) on a planar model whose bodies
    /// have equal masses (the weights are then `M^-1` up to a common factor); unlike the
    /// estimate it does not grow with the ratio of the bodies' masses, and on spatial bodies
    /// it weighs the directors by `m / J_max` instead of the inverse director masses `1/E_i`,
    /// which a slender or flat body (a small `E_i`) makes large without any joint being near
    /// dependence. `None` without constraints or above
    /// [`SPARSE_RANK_THRESHOLD`] equations (a dense `O(m^2 n)` test). Allocates.
    pub fn dependence_condition(&self, q: &[f64], t: f64) -> Option<f64> {
        if q.len() != self.n || self.m == 0 || self.m > SPARSE_RANK_THRESHOLD {
            return None;
        }
        let jac = self.unit_free_jacobian(q, t);
        // Gram-Schmidt as the dependence test's; the known redundant rows are left out
        let mut basis: Vec<DVector<f64>> = Vec::new();
        let mut smallest = 1.0f64;
        for r in 0..self.m {
            if self.redundant.iter().any(|e| e.row == r) {
                continue;
            }
            let mut w: DVector<f64> = jac.row(r).transpose();
            if w.norm() == 0.0 {
                continue;
            }
            orthogonalise(&basis, &mut w, |_, _| {});
            let norm = w.norm();
            smallest = smallest.min(norm);
            if norm > 0.0 {
                basis.push(w / norm);
            }
        }
        Some(if smallest > 0.0 {
            1.0 / (smallest * smallest)
        } else {
            f64::INFINITY
        })
    }

    /// `Phi_q(q)` with its columns weighted by the square roots of [`System::rank_weights`]
    /// and its rows scaled to unit norm (each equation in its own unit: a dependence is an
    /// angle, not a small row).
    fn unit_free_jacobian(&self, q: &[f64], t: f64) -> DMatrix<f64> {
        let mut jac = DMatrix::zeros(self.m, self.n);
        self.phi_q(q, t, &mut jac);
        for (k, w) in self.rank_weights().iter().enumerate() {
            jac.column_mut(k).scale_mut(w.sqrt());
        }
        for mut row in jac.row_iter_mut() {
            let norm = row.norm();
            if norm > 0.0 {
                row /= norm;
            }
        }
        jac
    }

    /// Checks that `Phi_q(q)` has no more dependent rows than the solvers may drop
    /// ([`System::dependency_budget`]): full row rank for a mechanism without redundancy that
    /// does not start on a singular configuration.
    /// On failure returns [`ModelError::Redundant`] naming a dependent equation (the first one
    /// not found at build time) and the joints whose equations it combines.
    pub fn check_rank(&self, q: &[f64], t: f64) -> Result<(), ModelError> {
        let found = self.redundant_at(q, t)?;
        if found.len() <= self.dependency_budget() {
            return Ok(());
        }
        let known = |r: usize| {
            self.redundant
                .iter()
                .chain(&self.singular_start)
                .any(|e| e.row == r)
        };
        let pick = found.iter().position(|e| !known(e.row)).unwrap_or(0);
        match found.into_iter().nth(pick) {
            Some(e) => Err(e.into_error()),
            None => Ok(()),
        }
    }

    /// Gram-Schmidt on the rows (twice for stability), tracking each basis vector as a
    /// combination of the original rows so a dependency can be traced to its joints.
    pub(crate) fn redundant_dense(
        &self,
        jac: &DMatrix<f64>,
        rel_tol: f64,
    ) -> Vec<RedundantEquation> {
        let m = self.m;
        let scale = (0..m)
            .map(|r| jac.row(r).norm())
            .fold(0.0, f64::max)
            .max(1e-300);
        let tol = rel_tol * scale;
        let mut basis: Vec<DVector<f64>> = Vec::new();
        let mut combo: Vec<DVector<f64>> = Vec::new();
        let mut found = Vec::new();
        for r in 0..m {
            let row: DVector<f64> = jac.row(r).transpose();
            let mut w = row.clone();
            let mut c = DVector::zeros(m);
            c[r] = 1.0;
            let mut proj = vec![0.0; basis.len()];
            orthogonalise(&basis, &mut w, |k, p| {
                proj[k] += p;
                c -= &combo[k] * p;
            });
            let norm = w.norm();
            if norm <= tol {
                // row r = sum_k proj_k basis_k = sum_k proj_k sum_j combo_k[j] row_j
                let mut coef = DVector::zeros(m);
                for (k, p) in proj.iter().enumerate() {
                    coef += &combo[k] * *p;
                }
                let cmax = max_abs(coef.as_slice()).max(1e-300);
                // (the owning element of a row, planar or spatial: `eq_joint` covers the planar
                // joints' rows only)
                let mut joints: Vec<String> = vec![self.equation_element(r)];
                for j in 0..m {
                    if coef[j].abs() > 1e-8 * cmax {
                        let name = self.equation_element(j);
                        if !joints.contains(&name) {
                            joints.push(name);
                        }
                    }
                }
                found.push(RedundantEquation {
                    row: r,
                    equation: self.equation_name(r),
                    joints,
                });
                continue;
            }
            basis.push(w / norm);
            combo.push(c / norm);
        }
        found
    }

    /// The sparse test of [`System::redundant_at`]: `S = Phi_q W Phi_q^T` from the
    /// element-local rows over the body blocks (planar and spatial), its pattern from the
    /// blocks the rows share (O(m) entries for a chain), factored by [`SparseCholesky`]
    /// allowing every row to be dropped. `W` is [`System::rank_weights`]: any positive weight
    /// gives `S` the rank of `Phi_q`, and these make its scaling independent of the units and
    /// of the bodies' masses.
    fn redundant_sparse(&self, q: &[f64], t: f64) -> Result<Vec<RedundantEquation>, ModelError> {
        let m = self.m;
        let w = self.rank_weights();
        // each row's sides: (block, first coordinate, offset of its gradient in `grads`)
        let mut sides: Vec<[Option<(usize, usize, usize)>; 2]> = vec![[None; 2]; m];
        let mut grads: Vec<f64> = Vec::new();
        self.local_rows_gamma(q, None, t, |r, s, _| {
            for (k, side) in s.iter().enumerate() {
                if let Some((block, g)) = side {
                    let col = self.body_block(*block).map_or(0, |(c, _)| c);
                    sides[r][k] = Some((*block, col, grads.len()));
                    grads.extend_from_slice(g);
                }
            }
        });
        let width = |block: usize| self.body_block(block).map_or(0, |(_, w)| w);
        // per block, the rows that touch it and the side of the block in each row
        let mut touching: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.n_body_blocks()];
        for (r, s) in sides.iter().enumerate() {
            for (k, side) in s.iter().enumerate() {
                if let Some((block, _, _)) = side {
                    touching[*block].push((r, k));
                }
            }
        }
        let mut pattern = Vec::new();
        for rows in &touching {
            for (a, &(r, _)) in rows.iter().enumerate() {
                for &(s, _) in &rows[..a] {
                    if r != s {
                        pattern.push((r.max(s), r.min(s)));
                    }
                }
            }
        }
        let mut chol =
            SparseCholesky::new(m, &pattern).map_err(|e| ModelError::InvalidElement {
                element: "constraint Jacobian".into(),
                message: format!("the sparse rank check could not analyse its pattern: {e}"),
            })?;
        chol.set_max_dependent(m);
        for (block, rows) in touching.iter().enumerate() {
            let wd = width(block);
            for (a, &(r, kr)) in rows.iter().enumerate() {
                for &(s, ks) in &rows[..=a] {
                    let (Some((_, col, gr)), Some((_, _, gs))) = (sides[r][kr], sides[s][ks])
                    else {
                        continue;
                    };
                    let v: f64 = (0..wd)
                        .map(|l| w[col + l] * grads[gr + l] * grads[gs + l])
                        .sum();
                    let (hi, lo) = (r.max(s), r.min(s));
                    if let Some(k) = chol.slot(hi, lo) {
                        chol.values_mut()[k] += v;
                    }
                }
            }
        }
        let dependent: Vec<usize> = match chol.factor() {
            Ok(()) => chol.dependent().to_vec(),
            // (a non-finite or zero entry on the diagonal: that row)
            Err(mbd_linalg::FactorError::NotPositiveDefinite(r))
            | Err(mbd_linalg::FactorError::Singular(r)) => vec![r],
        };
        let mut found: Vec<RedundantEquation> = dependent
            .into_iter()
            .map(|r| {
                let mut joints: Vec<String> = vec![self.equation_element(r)];
                for (block, _, _) in sides[r].iter().flatten() {
                    for &(s, _) in &touching[*block] {
                        let name = self.equation_element(s);
                        if !joints.contains(&name) {
                            joints.push(name);
                        }
                    }
                }
                RedundantEquation {
                    row: r,
                    equation: self.equation_name(r),
                    joints,
                }
            })
            .collect();
        found.sort_by_key(|e| e.row);
        Ok(found)
    }

    /// The element equation `row` of `Phi` belongs to: its planar or spatial joint, or the
    /// spatial body whose internal (director) constraint it is (the part of
    /// [`System::equation_name`] before its last dot).
    pub fn equation_element(&self, row: usize) -> String {
        match self.eq_joint.get(row) {
            Some(&ji) => self.joints[ji].name.clone(),
            None => {
                let name = self.equation_name(row);
                match name.rsplit_once('.') {
                    Some((element, _)) => element.to_string(),
                    None => name,
                }
            }
        }
    }

    /// `S = Phi_q M^-1 Phi_q^T` (dense), accumulated column by column over the few non-zeros of
    /// each column of `Phi_q`, so building it costs `O(n k^2)` for `k` non-zeros per column.
    fn schur_matrix(&self, jac: &DMatrix<f64>) -> Mat<f64> {
        let m = self.m;
        let mut s = Mat::<f64>::zeros(m, m);
        let mut nz: Vec<(usize, f64)> = Vec::with_capacity(8);
        for k in 0..self.n {
            nz.clear();
            let col = jac.column(k);
            for (r, &x) in col.iter().enumerate() {
                if x != 0.0 {
                    nz.push((r, x));
                }
            }
            let w = self.inv_mass[k];
            for &(i, xi) in &nz {
                for &(j, xj) in &nz {
                    s[(i, j)] += w * xi * xj;
                }
            }
        }
        s
    }

    /// Whether `S` has a Cholesky factor with pivots above `1e-7` of the largest (`S` condition
    /// below ~1e14): the fast full-rank test of [`System::check_rank`].
    fn schur_well_conditioned(&self, jac: &DMatrix<f64>) -> bool {
        let Ok(llt) = self.schur_matrix(jac).llt(Side::Lower) else {
            return false;
        };
        let l = llt.L();
        let d: Vec<f64> = (0..self.m).map(|i| l[(i, i)].abs()).collect();
        let dmax = d.iter().cloned().fold(0.0, f64::max);
        d.iter().all(|&x| x > 1e-7 * dmax)
    }
}

/// Removes from `w` its components along the orthonormal `basis`, twice over (modified
/// Gram-Schmidt with reorthogonalisation, for the rank tests' accuracy), reporting each
/// projection `(k, w . basis_k)` removed to `removed`.
fn orthogonalise(
    basis: &[DVector<f64>],
    w: &mut DVector<f64>,
    mut removed: impl FnMut(usize, f64),
) {
    for _ in 0..2 {
        for (k, b) in basis.iter().enumerate() {
            let p = b.dot(w);
            *w -= b * p;
            removed(k, p);
        }
    }
}

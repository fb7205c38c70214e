//! The two linear-algebra paths of [`TangentRk`](super::TangentRk): the dense chart (QR of
//! `Df^T`, orthonormal tangent basis, dense index-1 solve) for small systems and the sparse
//! chart (redundant tangent coordinates, sparse Cholesky of `Df Df^T`, sparse index-1 solve)
//! for large ones. One enum dispatch per chart operation; the dense arm runs exactly the code
//! it ran before the sparse path existed.

use crate::chart::{ChartFailure, MapStats, NewtonSettings, TangentChart};
use crate::sparse_chart::SparseChart;
use mbd_model::System;
use mbd_solve::{AccelerationSolver, ConstraintRows, SolveError, SparseAccelerationSolver};

/// The chart and the index-1 solver of one path.
// one `Path` per solver, built once: the size difference costs nothing, and the dense arm
// stays unboxed so that its hot path does not gain an indirection
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub(super) enum Path {
    /// Dense chart `x_c + U xi + Q1 zeta`; chart coordinates `xi` (`2 (n - m)`), normal
    /// coordinates `zeta` (`2m`).
    Dense {
        chart: TangentChart,
        acc: AccelerationSolver,
    },
    /// Sparse chart `x_c + y + Df^T eta`; chart coordinates `y` (`2n`, in `ker Df(x_c)`),
    /// normal coordinates `eta` (`2m`).
    Sparse(Box<SparseParts>),
}

/// The sparse path's parts (boxed: the enum stays the size of the dense arm).
#[derive(Debug)]
pub(super) struct SparseParts {
    pub(super) chart: SparseChart,
    pub(super) acc: SparseAccelerationSolver,
}

impl Path {
    /// Length of the chart coordinates the Runge-Kutta method integrates.
    pub(super) fn coord_dim(&self) -> usize {
        match self {
            Path::Dense { chart, .. } => chart.dim(),
            Path::Sparse(p) => p.chart.ambient_dim(),
        }
    }

    /// Dimension of the manifold, `2 (n - m)`.
    pub(super) fn dim(&self) -> usize {
        match self {
            Path::Dense { chart, .. } => chart.dim(),
            Path::Sparse(p) => p.chart.dim(),
        }
    }

    #[inline]
    pub(super) fn centre(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
    ) -> Result<(), SolveError> {
        match self {
            Path::Dense { chart, .. } => chart.centre(sys, q, v, t),
            Path::Sparse(p) => p.chart.centre(sys, q, v, t),
        }
    }

    /// The velocity weight `tau` of the chart's metric from the next centre on.
    #[inline]
    pub(super) fn set_velocity_weight(&mut self, tau: f64) {
        match self {
            Path::Dense { chart, .. } => chart.set_velocity_weight(tau),
            Path::Sparse(p) => p.chart.set_velocity_weight(tau),
        }
    }

    #[inline]
    pub(crate) fn rcond(&self) -> f64 {
        match self {
            Path::Dense { chart, .. } => chart.rcond(),
            Path::Sparse(p) => p.chart.rcond(),
        }
    }

    #[inline]
    pub(super) fn centre_point(&self) -> &[f64] {
        match self {
            Path::Dense { chart, .. } => chart.centre_point(),
            Path::Sparse(p) => p.chart.centre_point(),
        }
    }

    /// The dense chart's interpolated iteration matrix (the sparse path has only the
    /// centre's; [`super::TangentRk::new`] rejects the other choices there).
    #[inline]
    pub(super) fn set_secondary_point(&mut self, sys: &System, x_e: &[f64], t_e: f64) {
        if let Path::Dense { chart, .. } = self {
            chart.set_secondary_point(sys, x_e, t_e);
        }
    }

    /// The dense chart's predicted stop after the first correction (the sparse chart has
    /// none).
    #[inline]
    pub(super) fn set_contraction_prior(&mut self, follows: bool) {
        if let Path::Dense { chart, .. } = self {
            chart.set_contraction_prior(follows);
        }
    }

    #[inline]
    pub(super) fn select_iteration_matrix(&mut self, s: f64) {
        if let Path::Dense { chart, .. } = self {
            chart.select_iteration_matrix(s);
        }
    }

    /// The chart's normal coordinates from coordinates in a basis that does not depend on how
    /// the chart was factored, the quantity the step history extrapolates: the dense chart's
    /// canonical basis (`TangentChart::canonical_from_zeta`), the sparse chart's `eta` (its
    /// normal coordinates are the coefficients of `Df(x_c)^T eta` themselves).
    #[inline]
    pub(super) fn zeta_from_canonical(&self, canonical: &[f64], zeta: &mut [f64]) {
        match self {
            Path::Dense { chart, .. } => chart.zeta_from_canonical(canonical, zeta),
            Path::Sparse(_) => zeta.copy_from_slice(canonical),
        }
    }

    /// The inverse of [`Path::zeta_from_canonical`].
    #[inline]
    pub(super) fn canonical_from_zeta(&self, zeta: &[f64], canonical: &mut [f64]) {
        match self {
            Path::Dense { chart, .. } => chart.canonical_from_zeta(zeta, canonical),
            Path::Sparse(_) => canonical.copy_from_slice(zeta),
        }
    }

    /// The chart map, verifying the residual (`predicted = false`) or allowed to stop on the
    /// predicted one (stage points).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn map(
        &mut self,
        sys: &System,
        y: &[f64],
        t: f64,
        zeta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        match (self, predicted) {
            (Path::Dense { chart, .. }, false) => chart.map(sys, y, t, zeta, x, newton),
            (Path::Dense { chart, .. }, true) => chart.map_predicted(sys, y, t, zeta, x, newton),
            (Path::Sparse(p), false) => p.chart.map(sys, y, t, zeta, x, newton),
            (Path::Sparse(p), true) => p.chart.map_predicted(sys, y, t, zeta, x, newton),
        }
    }

    /// The index-1 accelerations at `(q, v, t)`, a point the chart has just mapped (or its
    /// centre): the dense path takes the bodies' `sin`/`cos` from the chart's last residual.
    #[inline]
    pub(super) fn accel(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        match self {
            Path::Dense { chart, acc } => {
                // the chart's sin/cos of its last residual, rotated to q (at the centre: the
                // end-point map's verified residual was evaluated there, nothing to rotate)
                acc.solve_accelerations(sys, q, v, t, Some(chart.angles_mut()), a, lambda)
            }
            Path::Sparse(p) => p.acc.solve(sys, q, v, t, a, lambda),
        }
    }

    /// The index-1 accelerations at the dense chart's centre from its own QR
    /// ([`TangentChart::centre_accelerations`]; scleronomic constraints); `false` where that
    /// does not apply (the sparse path, or see there): solve with [`Path::accel`] then.
    #[inline]
    pub(super) fn centre_accel(&mut self, sys: &System, a: &mut [f64]) -> bool {
        match self {
            Path::Dense { chart, .. } => chart.centre_accelerations(sys, a),
            Path::Sparse(_) => false,
        }
    }

    /// The constraint rows of the last index-1 solve (for the bridge).
    pub(super) fn rows(&self) -> &dyn ConstraintRows {
        match self {
            Path::Dense { acc, .. } => acc,
            Path::Sparse(p) => &p.acc,
        }
    }

    /// Condition estimate of the last index-1 solve.
    #[inline]
    pub(super) fn condition_estimate(&self) -> f64 {
        match self {
            Path::Dense { acc, .. } => acc.condition_estimate(),
            Path::Sparse(p) => p.acc.condition_estimate(),
        }
    }

    /// Splits `F` into its normal coordinates `g` (`2m`) and the state equation's right-hand
    /// side `dy` (dense: `U^T F`; sparse: `P F`).
    #[inline]
    pub(super) fn split(&mut self, fx: &[f64], g: &mut [f64], dy: &mut [f64]) {
        match self {
            Path::Dense { chart, .. } => chart.split_coordinates(fx, g, dy),
            Path::Sparse(p) => p.chart.split(fx, g, dy),
        }
    }

    /// A vector in chart coordinates mapped to `x` (dense: `U e`; sparse: `e` itself; both
    /// with the velocity half divided by the chart's velocity weight).
    pub(super) fn tangent_to_ambient(&mut self, e: &[f64], out: &mut [f64]) {
        match self {
            Path::Dense { chart, .. } => chart.tangent_to_ambient(e, out),
            Path::Sparse(p) => p.chart.tangent_to_ambient(e, out),
        }
    }

    /// `||f(x, t)||_inf` with `f` into `out`.
    pub(super) fn residual(&mut self, sys: &System, x: &[f64], t: f64, out: &mut [f64]) -> f64 {
        match self {
            Path::Dense { chart, .. } => chart.residual(sys, x, t, out),
            Path::Sparse(p) => p.chart.residual(sys, x, t, out),
        }
    }

    /// The rank report at the chart's centre.
    pub(super) fn singular_error(
        &mut self,
        sys: &System,
        t: f64,
        rel_tol: f64,
    ) -> Option<SolveError> {
        match self {
            Path::Dense { chart, .. } => chart.singular_error(sys, t, rel_tol),
            Path::Sparse(p) => p.chart.singular_error(sys, t, rel_tol),
        }
    }

    /// The rank report at the configuration `q`.
    pub(super) fn singular_error_at(
        &mut self,
        sys: &System,
        q: &[f64],
        t: f64,
        rel_tol: f64,
    ) -> Option<SolveError> {
        match self {
            Path::Dense { chart, .. } => chart.singular_error_at(sys, q, t, rel_tol),
            Path::Sparse(p) => p.chart.singular_error_at(sys, q, t, rel_tol),
        }
    }
}

//! The sparse stage solve: the stage Jacobian assembled on its fixed pattern from the
//! element-local constraint rows and factored by [`SparseLu`]; the end-of-step momentum
//! projection by [`ConstraintSchur`] and the first-step predictor by
//! [`SparseAccelerationSolver`]. Every operation of a step is `O(N)` for a chain of `N`
//! bodies (see `docs/symplectic.md`, "Sparse stage solve").

use super::{with_time, Galerkin};
use mbd_model::{BodyRef, System};
use mbd_solve::linalg::LuError;
use mbd_solve::sparse::{ConstraintSchur, RowIncidence, SparseLu};
use mbd_solve::{SolveError, SparseAccelerationSolver};

/// No slot: the entry belongs to ground.
const NONE: usize = usize::MAX;

/// Pattern, slot tables and workspaces of the sparse stage solve.
#[derive(Debug)]
pub(super) struct SparseStage {
    /// The stage Jacobian on its pattern, and its LU.
    pub(super) lu: SparseLu,
    /// The bodies `(first, second)` of each constraint row (`None` = ground).
    pub(super) row_bodies: Vec<(Option<usize>, Option<usize>)>,
    /// `Phi_q M^-1 Phi_q^T` for the end-of-step momentum projection.
    pub(super) schur: ConstraintSchur,
    /// Index-1 accelerations for the first step's predictor.
    pub(super) acc: SparseAccelerationSolver,
    /// `k_slot[(nu s + mu - 1) n + i]`: entry (momentum row `(nu, i)`, `Z_mu,i`).
    k_slot: Vec<usize>,
    /// `lam_slot[nu m + r][a]`: entry (momentum row `(nu, coord(a))`, multiplier `(nu, r)`).
    lam_slot: Vec<[usize; 6]>,
    /// `diag_slot[(nu - 1) m + r]`: entry (constraint `(nu, r)`, multiplier `(nu - 1, r)`),
    /// only for a model with redundant equations (else empty).
    diag_slot: Vec<usize>,
    /// `con_slot[(nu - 1) m + r][c]`: entry (constraint `(nu, r)`, `Z_nu,coord(c)`).
    con_slot: Vec<[usize; 6]>,
    /// `curv_slot[(nu - 1) m + r][a][c]` (`nu = 1..s-1`): entry (momentum row
    /// `(nu, coord(a))`, `Z_nu,coord(c)`), the constraint curvature.
    curv_slot: Vec<[[usize; 6]; 6]>,
    /// Colour of each body: bodies sharing a joint have different colours.
    color: Vec<usize>,
    /// Bodies of each colour.
    color_bodies: Vec<Vec<usize>>,
    /// Workspaces of the curvature (a seed direction, and `Phi_q`, `(Phi_q v)_q` rows).
    vdir: Vec<f64>,
    gscratch: Vec<[f64; 6]>,
    dgrads: Vec<[f64; 6]>,
    /// Force-Hessian entries `(row coordinate, column coordinate)`: every body that a force
    /// element acts on, with itself and with each body it shares an element with.
    fent: Vec<(usize, usize)>,
    /// `fent_slot[(nu s + mu - 1) E + e]`: the slot of entry `e` in block (momentum row `nu`,
    /// `Z_mu`).
    fent_slot: Vec<usize>,
    /// `fseed[3 k + l]`: the entries whose column is coordinate `l` of a body of force colour
    /// `k` (a distance-2 colouring of the force graph: no row sees two bodies of one colour).
    fseed: Vec<Vec<usize>>,
    /// Bodies of each force colour.
    fcolor_bodies: Vec<Vec<usize>>,
    /// Values of the entries at one Gauss point: `d(grad V - Qnc)/dq` and `-dQnc/dv`.
    hq: Vec<f64>,
    hv: Vec<f64>,
    /// Workspaces of the force differences.
    qp: Vec<f64>,
    vp: Vec<f64>,
    gp: Vec<f64>,
    gm: Vec<f64>,
    /// `Phi_q^T lambda` (scratch of the residual and the end momentum).
    pub(super) al: Vec<f64>,
    /// `Phi_q v` (scratch of the projection).
    pub(super) pv: Vec<f64>,
}

/// Coordinate of local entry `a` (0..6) of a row acting on `bodies`, if not ground.
#[inline]
fn coord(bodies: (Option<usize>, Option<usize>), a: usize) -> Option<usize> {
    let b = if a < 3 { bodies.0 } else { bodies.1 };
    b.map(|b| 3 * b + a % 3)
}

/// `out += Phi_q^T y` from element-local rows.
pub(super) fn add_transpose(
    grads: &[[f64; 6]],
    row_bodies: &[(Option<usize>, Option<usize>)],
    y: &[f64],
    out: &mut [f64],
) {
    for ((g, &(ba, bb)), &yr) in grads.iter().zip(row_bodies).zip(y) {
        if let Some(b) = ba {
            for l in 0..3 {
                out[3 * b + l] += g[l] * yr;
            }
        }
        if let Some(b) = bb {
            for l in 0..3 {
                out[3 * b + l] += g[3 + l] * yr;
            }
        }
    }
}

impl SparseStage {
    /// Pattern and symbolic analysis of the stage Jacobian of the `(s,s)` scheme on `sys`
    /// (allocates; once per integrator).
    pub(super) fn new(sys: &System, s: usize) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let nb = n / 3;
        let dim = s * (n + m);
        let row_bodies = RowIncidence::new(sys).row_bodies;
        let mut entries: Vec<(usize, usize)> = Vec::new();
        for nu in 0..s {
            for mu in 1..=s {
                for i in 0..n {
                    entries.push((nu * n + i, (mu - 1) * n + i));
                }
            }
            for (r, &rb) in row_bodies.iter().enumerate() {
                for a in 0..6 {
                    if let Some(i) = coord(rb, a) {
                        entries.push((nu * n + i, s * n + nu * m + r));
                    }
                }
            }
        }
        for nu in 1..=s {
            for (r, &rb) in row_bodies.iter().enumerate() {
                for c in 0..6 {
                    if let Some(l) = coord(rb, c) {
                        entries.push((s * n + (nu - 1) * m + r, (nu - 1) * n + l));
                        if nu < s {
                            for a in 0..6 {
                                if let Some(i) = coord(rb, a) {
                                    entries.push((nu * n + i, (nu - 1) * n + l));
                                }
                            }
                        }
                    }
                }
            }
        }
        // force graph: closed neighbourhoods of the bodies with a force element
        let mut fnbr: Vec<Vec<usize>> = vec![Vec::new(); nb];
        for f in sys.forces() {
            let idx = |r: BodyRef| match r {
                BodyRef::Body(h) if h.index() < nb => Some(h.index()),
                _ => None,
            };
            let (a, b) = f.bodies();
            let (a, b) = (idx(a), idx(b));
            for x in [a, b].into_iter().flatten() {
                fnbr[x].push(x);
                for y in [a, b].into_iter().flatten() {
                    fnbr[x].push(y);
                }
            }
        }
        for v in &mut fnbr {
            v.sort_unstable();
            v.dedup();
        }
        let mut fent = Vec::new();
        for (a, nbrs) in fnbr.iter().enumerate() {
            for &b in nbrs {
                for r in 0..3 {
                    for c in 0..3 {
                        fent.push((3 * a + r, 3 * b + c));
                    }
                }
            }
        }
        for nu in 0..s {
            for mu in 1..=s {
                for &(i, l) in &fent {
                    entries.push((nu * n + i, (mu - 1) * n + l));
                }
            }
        }
        // a model with redundant equations: each constraint row (nu, r) pairs with its
        // multiplier (nu - 1, r) on a diagonal entry, which a dropped row sets to 1
        let redundant = sys.n_redundant() > 0;
        if redundant {
            for nu in 1..=s {
                for r in 0..m {
                    let k = s * n + (nu - 1) * m + r;
                    entries.push((k, k));
                }
            }
        }
        let lu = SparseLu::new(dim, &entries)?;
        let slot = |r: usize, c: usize| lu.slot(r, c).unwrap_or(NONE);
        let mut k_slot = vec![NONE; s * s * n];
        for nu in 0..s {
            for mu in 1..=s {
                for i in 0..n {
                    k_slot[(nu * s + mu - 1) * n + i] = slot(nu * n + i, (mu - 1) * n + i);
                }
            }
        }
        let mut lam_slot = vec![[NONE; 6]; s * m];
        let mut con_slot = vec![[NONE; 6]; s * m];
        let mut curv_slot = vec![[[NONE; 6]; 6]; s.saturating_sub(1) * m];
        for (r, &rb) in row_bodies.iter().enumerate() {
            for nu in 0..s {
                for a in 0..6 {
                    if let Some(i) = coord(rb, a) {
                        lam_slot[nu * m + r][a] = slot(nu * n + i, s * n + nu * m + r);
                    }
                }
            }
            for nu in 1..=s {
                for c in 0..6 {
                    if let Some(l) = coord(rb, c) {
                        con_slot[(nu - 1) * m + r][c] =
                            slot(s * n + (nu - 1) * m + r, (nu - 1) * n + l);
                        if nu < s {
                            for a in 0..6 {
                                if let Some(i) = coord(rb, a) {
                                    curv_slot[(nu - 1) * m + r][a][c] =
                                        slot(nu * n + i, (nu - 1) * n + l);
                                }
                            }
                        }
                    }
                }
            }
        }
        // greedy colouring of the bodies: two bodies sharing a joint differ
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); nb];
        for &(a, b) in &row_bodies {
            if let (Some(a), Some(b)) = (a, b) {
                adj[a].push(b);
                adj[b].push(a);
            }
        }
        let mut color = vec![usize::MAX; nb];
        let mut color_bodies: Vec<Vec<usize>> = Vec::new();
        for b in 0..nb {
            let mut k = 0;
            while adj[b].iter().any(|&o| color[o] == k) {
                k += 1;
            }
            color[b] = k;
            if color_bodies.len() <= k {
                color_bodies.resize(k + 1, Vec::new());
            }
            color_bodies[k].push(b);
        }
        let mut fent_slot = vec![NONE; s * s * fent.len()];
        for nu in 0..s {
            for mu in 1..=s {
                let base = (nu * s + mu - 1) * fent.len();
                for (e, &(i, l)) in fent.iter().enumerate() {
                    fent_slot[base + e] = slot(nu * n + i, (mu - 1) * n + l);
                }
            }
        }
        // distance-2 colouring of the bodies with force elements
        let mut fcolor = vec![usize::MAX; nb];
        let mut fcolor_bodies: Vec<Vec<usize>> = Vec::new();
        for b in 0..nb {
            if fnbr[b].is_empty() {
                continue;
            }
            let mut k = 0;
            let clash = |k: usize| {
                fnbr[b]
                    .iter()
                    .any(|&x| fcolor[x] == k || fnbr[x].iter().any(|&y| fcolor[y] == k))
            };
            while clash(k) {
                k += 1;
            }
            fcolor[b] = k;
            if fcolor_bodies.len() <= k {
                fcolor_bodies.resize(k + 1, Vec::new());
            }
            fcolor_bodies[k].push(b);
        }
        let mut fseed = vec![Vec::new(); 3 * fcolor_bodies.len()];
        for (e, &(_, l)) in fent.iter().enumerate() {
            fseed[3 * fcolor[l / 3] + l % 3].push(e);
        }
        let ne = fent.len();
        let diag_slot = if redundant {
            (0..s * m).map(|k| slot(s * n + k, s * n + k)).collect()
        } else {
            Vec::new()
        };
        Ok(SparseStage {
            diag_slot,
            lu,
            row_bodies,
            schur: ConstraintSchur::new(sys)?,
            acc: SparseAccelerationSolver::new(sys)?,
            k_slot,
            lam_slot,
            con_slot,
            curv_slot,
            color,
            color_bodies,
            vdir: vec![0.0; n],
            gscratch: vec![[0.0; 6]; m],
            dgrads: vec![[0.0; 6]; m],
            fent,
            fent_slot,
            fseed,
            fcolor_bodies,
            hq: vec![0.0; ne],
            hv: vec![0.0; ne],
            qp: vec![0.0; n],
            vp: vec![0.0; n],
            gp: vec![0.0; n],
            gm: vec![0.0; n],
            al: vec![0.0; n],
            pv: vec![0.0; m],
        })
    }
}

impl Galerkin {
    /// The sparse Jacobian of the stage equations at `self.x` (after `residual` at the same
    /// point), factored. Same entries as the dense `jacobian`, written into the slots of the
    /// fixed pattern; the constraint curvature `sum_r lt_r Hess(Phi_r)` at the interior control
    /// points comes from `System::phi_q_dot_local` along coloured seed directions (one per
    /// colour and body coordinate: `v^T Hess(Phi_r)` for `v` the unit vector of that
    /// coordinate of every body of one colour, which a row of a joint between two bodies of
    /// different colours sees for one body only).
    pub(super) fn jacobian_sparse(
        &mut self,
        sys: &System,
        t: f64,
        h: f64,
    ) -> Result<(), SolveError> {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        let s1 = s + 1;
        let Some(sp) = self.sparse.as_deref_mut() else {
            return Ok(());
        };
        sys.phi_q_local(&self.qn[s * n..(s + 1) * n], &mut self.grads[s]);
        let h2 = h * h;
        let tab = &self.tab;
        let minv = &self.minv;
        sp.lu.clear();
        {
            let vals = sp.lu.values_mut();
            for nu in 0..s {
                for mu in 1..=s {
                    let kk = tab.k[nu * s1 + mu];
                    let ks = &sp.k_slot[(nu * s + mu - 1) * n..(nu * s + mu) * n];
                    for &k in ks {
                        vals[k] += kk;
                    }
                }
                for (r, &rb) in sp.row_bodies.iter().enumerate() {
                    let g = &self.grads[nu][r];
                    let sl = &sp.lam_slot[nu * m + r];
                    for a in 0..6 {
                        if let Some(i) = coord(rb, a) {
                            vals[sl[a]] = -h2 * minv[i] * g[a];
                        }
                    }
                }
            }
            for nu in 1..=s {
                for r in 0..m {
                    let g = &self.grads[nu][r];
                    for (&k, &v) in sp.con_slot[(nu - 1) * m + r].iter().zip(g) {
                        if k != NONE {
                            vals[k] = v;
                        }
                    }
                }
            }
        }
        // force Hessians at the Gauss points (coloured central differences)
        if !sp.fent.is_empty() {
            let nonconservative = self.nonconservative;
            for j in 0..s {
                let qj = &self.qj[j * n..(j + 1) * n];
                let tj = t + tab.c[j] * h;
                for (v, &hv) in sp.vp.iter_mut().zip(&self.hvj[j * n..(j + 1) * n]) {
                    *v = hv / h;
                }
                sp.qp.copy_from_slice(qj);
                // the generalised force with the sign of grad V: grad V - Qnc
                let grad = |q: &[f64], v: &[f64], out: &mut [f64], tmp: &mut [f64]| {
                    sys.potential_gradient(q, out);
                    if nonconservative {
                        sys.nonconservative_forces(q, v, tj, tmp);
                        for (o, &f) in out.iter_mut().zip(tmp.iter()) {
                            *o -= f;
                        }
                    }
                };
                for (k, bodies) in sp.fcolor_bodies.iter().enumerate() {
                    for l in 0..3 {
                        let seeds = &sp.fseed[3 * k + l];
                        for (wrt_v, active) in [(false, true), (true, nonconservative)] {
                            if !active {
                                continue;
                            }
                            let x = if wrt_v { &mut sp.vp } else { &mut sp.qp };
                            for &b in bodies {
                                let c = 3 * b + l;
                                x[c] += 1e-6 * (1.0 + x[c].abs());
                            }
                            grad(&sp.qp, &sp.vp, &mut sp.gp, &mut sp.al);
                            let x = if wrt_v { &mut sp.vp } else { &mut sp.qp };
                            for &b in bodies {
                                let c = 3 * b + l;
                                let x0 = if wrt_v {
                                    self.hvj[j * n + c] / h
                                } else {
                                    qj[c]
                                };
                                x[c] = x0 - 1e-6 * (1.0 + x0.abs());
                            }
                            grad(&sp.qp, &sp.vp, &mut sp.gm, &mut sp.al);
                            let x = if wrt_v { &mut sp.vp } else { &mut sp.qp };
                            for &b in bodies {
                                let c = 3 * b + l;
                                x[c] = if wrt_v {
                                    self.hvj[j * n + c] / h
                                } else {
                                    qj[c]
                                };
                            }
                            let out = if wrt_v { &mut sp.hv } else { &mut sp.hq };
                            for &e in seeds {
                                let (i, c) = sp.fent[e];
                                let x0 = if wrt_v {
                                    self.hvj[j * n + c] / h
                                } else {
                                    qj[c]
                                };
                                let d = 1e-6 * (1.0 + x0.abs());
                                out[e] = (sp.gp[i] - sp.gm[i]) / ((x0 + d) - (x0 - d));
                            }
                        }
                    }
                }
                let vals = sp.lu.values_mut();
                let ne = sp.fent.len();
                for nu in 0..s {
                    for mu in 1..=s {
                        let ca = tab.b[j] * tab.a[j * s1 + nu] * tab.a[j * s1 + mu];
                        let cv = tab.b[j] * tab.a[j * s1 + nu] * tab.d[j * s1 + mu] / h;
                        let base = (nu * s + mu - 1) * ne;
                        for (e, &(i, _)) in sp.fent.iter().enumerate() {
                            let mut v = ca * sp.hq[e];
                            if nonconservative {
                                v += cv * sp.hv[e];
                            }
                            vals[sp.fent_slot[base + e]] += -(h2 * minv[i] * v);
                        }
                    }
                }
            }
        }
        // constraint curvature at the interior control points
        for nu in 1..s {
            let q = &self.qn[nu * n..(nu + 1) * n];
            let lam = &self.x[s * n + nu * m..s * n + (nu + 1) * m];
            for (k, bodies) in sp.color_bodies.iter().enumerate() {
                for l in 0..3 {
                    for &b in bodies {
                        sp.vdir[3 * b + l] = 1.0;
                    }
                    sys.phi_q_dot_local(q, &sp.vdir, &mut sp.gscratch, &mut sp.dgrads);
                    for &b in bodies {
                        sp.vdir[3 * b + l] = 0.0;
                    }
                    let vals = sp.lu.values_mut();
                    for (r, &(ba, bb)) in sp.row_bodies.iter().enumerate() {
                        let lr = lam[r];
                        if lr == 0.0 {
                            continue;
                        }
                        for (p, body) in [(0, ba), (1, bb)] {
                            let Some(b) = body else { continue };
                            if sp.color[b] != k {
                                continue;
                            }
                            let a = 3 * p + l;
                            let f = -h2 * minv[3 * b + l] * lr;
                            let sl = &sp.curv_slot[(nu - 1) * m + r][a];
                            for (&slot, &d) in sl.iter().zip(&sp.dgrads[r]) {
                                if slot != NONE {
                                    vals[slot] += f * d;
                                }
                            }
                        }
                    }
                }
            }
        }
        if let Some(ml) = self.ml.first_mut().filter(|_| s == 1) {
            // the s = 1 modified Lagrangian: the diagonals of the blocks of galerkin/dense.rs,
            // -h^2/12 (2 B) and -h^4/48 A M^-1 A, on the entries (i, Z_1,i) (docs/symplectic.md
            // section 5a: the dense parts through S^-1 are left out)
            let [wd, ad] = &mut self.mldiag;
            ml.modified_newton_diagonals(sys, &self.mlmid, &self.mlvel, wd, ad)
                .map_err(|e| with_time(e, t))?;
            let (cw, ch) = (-h2 / 12.0, -(h2 * h2) / 48.0);
            let vals = sp.lu.values_mut();
            for i in 0..n {
                vals[sp.k_slot[i]] += minv[i] * (cw * 2.0 * wd[i] + ch * ad[i]);
            }
        }
        if !sp.diag_slot.is_empty() {
            // the equations dependent at the step's end configuration are left out: their
            // rows become the identity on their multipliers, which then stay put (Newton
            // moves them by the residual of an equation the others imply)
            sp.schur.update(sys, &self.qn[s * n..(s + 1) * n]);
            sp.schur
                .factor(&self.minv)
                .map_err(|_| SolveError::Singular {
                    t: t + h,
                    what: "constraint matrix Phi_q M^-1 Phi_q^T of the stage equations",
                    detail: "more dependent equations than the model's redundant ones".into(),
                })?;
            let vals = sp.lu.values_mut();
            for &r in sp.schur.dependent() {
                for nu in 1..=s {
                    for &k in &sp.con_slot[(nu - 1) * m + r] {
                        if k != NONE {
                            vals[k] = 0.0;
                        }
                    }
                    for &k in &sp.lam_slot[(nu - 1) * m + r] {
                        if k != NONE {
                            vals[k] = 0.0;
                        }
                    }
                    vals[sp.diag_slot[(nu - 1) * m + r]] = 1.0;
                }
            }
        }
        self.jacobians += 1;
        self.jac_valid = false;
        let res = sp.lu.factor();
        self.stage_error(sys, t, h, res)
    }

    /// The stage error (if any) of a factorisation, with the unknown and equation named.
    pub(super) fn stage_error(
        &self,
        sys: &System,
        t: f64,
        h: f64,
        res: Result<(), LuError>,
    ) -> Result<(), SolveError> {
        match res {
            Ok(()) => Ok(()),
            Err(LuError::Singular { row, col }) => Err(SolveError::Singular {
                t,
                what: "Jacobian of the symplectic stage equations",
                detail: format!(
                    "no pivot for the {} in the {} (h = {h}; redundant constraints or a \
                     singular configuration)",
                    self.unknown_name(sys, col),
                    self.equation_name(sys, row)
                ),
            }),
            Err(LuError::NonFinite { .. }) => Err(SolveError::NonFinite {
                t,
                what: "Jacobian of the symplectic stage equations",
            }),
        }
    }
}

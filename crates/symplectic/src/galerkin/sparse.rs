//! The sparse stage solve: the stage Jacobian assembled on its fixed pattern from the
//! element-local constraint rows over body blocks of any width (planar bodies 3 coordinates,
//! spatial bodies 12: `mbd_solve::sparse::BlockRows`) and factored by [`SparseLu`]; the
//! end-of-step momentum projection by [`ConstraintSchur`] (planar models) or the constrained
//! solve (spatial bodies, `EndSolve`), and the first-step predictor by
//! [`SparseAccelerationSolver`]. Every operation of a step is `O(N)` for a chain of `N`
//! bodies (see `docs/symplectic.md`, "Sparse stage solve").

use super::{with_time, Galerkin};

mod curvature;
pub(super) mod projected;
use mbd_model::{BodyRef, System};
use mbd_solve::linalg::LuError;
use mbd_solve::sparse::{BlockRows, ConstraintSchur, SparseLu};
use mbd_solve::{SolveError, SparseAccelerationSolver};

/// No slot: the entry belongs to ground.
const NONE: usize = usize::MAX;

/// Pattern, slot tables and workspaces of the sparse stage solve.
#[derive(Debug)]
pub(super) struct SparseStage {
    /// The stage Jacobian on its pattern, and its LU.
    pub(super) lu: SparseLu,
    /// Every constraint row over body blocks (its local gradients side after side, row after
    /// row: row `r`'s values are `rstart[r]..rstart[r + 1]` of a flat array).
    pub(super) rows: BlockRows,
    /// The coordinate of each local value.
    vcol: Vec<usize>,
    /// Each row's first local value (one more entry: the total).
    rstart: Vec<usize>,
    /// `Phi_q M^-1 Phi_q^T` for the end-of-step momentum projection and the rows a redundant
    /// model drops (planar models; `None` with spatial bodies, whose end velocity is the
    /// constrained solve).
    pub(super) schur: Option<ConstraintSchur>,
    /// Index-1 accelerations for the first step's predictor.
    pub(super) acc: SparseAccelerationSolver,
    /// `k_slot[(nu s + mu - 1) n + i]`: entry (momentum row `(nu, i)`, `Z_mu,i`).
    k_slot: Vec<usize>,
    /// `lam_slot[nu nv + k]`: entry (momentum row `(nu, vcol[k])`, multiplier `(nu, r)`) for
    /// local value `k` of row `r`.
    lam_slot: Vec<usize>,
    /// `diag_slot[(nu - 1) m + r]`: entry (constraint `(nu, r)`, multiplier `(nu - 1, r)`),
    /// only for a model with redundant equations (else empty).
    diag_slot: Vec<usize>,
    /// `con_slot[(nu - 1) nv + k]`: entry (constraint `(nu, r)`, `Z_nu,vcol[k]`).
    con_slot: Vec<usize>,
    /// `curv_slot[(nu - 1) nc + cstart[r] + a len_r + c]` (`nu = 1..s-1`): entry (momentum
    /// row `(nu, vcol[a])`, `Z_nu,vcol[c]`) of row `r`'s local values `a`, `c`, the constraint
    /// curvature; `nc = cstart[m]`.
    curv_slot: Vec<usize>,
    cstart: Vec<usize>,
    /// Rows whose Hessian is constant ([`System::constant_hessian_rows`]), their local
    /// Hessians in the layout of `curv_slot` (`hess[cstart[r] + a len_r + c]`) once
    /// `hess_ready`, and whether some row's Hessian varies (then the seed passes run at every
    /// Jacobian, for those rows).
    hess_const: Vec<bool>,
    hess: Vec<f64>,
    hess_ready: bool,
    hess_varies: bool,
    /// Colour of each block: blocks sharing a row have different colours.
    color: Vec<usize>,
    /// Blocks of each colour, and the widest block.
    color_blocks: Vec<Vec<usize>>,
    max_width: usize,
    /// Each block's first coordinate and width.
    blocks: Vec<(usize, usize)>,
    /// The equations dependent at the last Jacobian's end configuration (a redundant model).
    dep: Vec<usize>,
    /// Workspaces of the curvature: a seed direction, the rows of `Phi_q` and of
    /// `(Phi_q v + Phi_t)_q` along it, and (rheonomic models) the rows of `Phi_tq` alone,
    /// which the curvature leaves out.
    vdir: Vec<f64>,
    zero: Vec<f64>,
    gscratch: Vec<f64>,
    dgrads: Vec<f64>,
    dtime: Vec<f64>,
    /// Force-Hessian entries `(row coordinate, column coordinate)`: every block that a force
    /// element acts on, with itself and with each block it shares an element with.
    fent: Vec<(usize, usize)>,
    /// `fent_slot[(nu s + mu - 1) E + e]`: the slot of entry `e` in block (momentum row `nu`,
    /// `Z_mu`).
    fent_slot: Vec<usize>,
    /// `fseed[max_width k + l]`: the entries whose column is coordinate `l` of a block of
    /// force colour `k` (a distance-2 colouring of the force graph: no row sees two blocks of
    /// one colour).
    fseed: Vec<Vec<usize>>,
    /// Blocks of each force colour.
    fcolor_blocks: Vec<Vec<usize>>,
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
    /// The (1,1) scheme's projected stiffness block (the modified Lagrangian's position block
    /// or `W_1`'s Newton Hessian), as `n + m` more unknowns (`projected.rs`).
    pub(super) proj: Option<Box<projected::ProjectedStiffness>>,
    /// `Phi_q v` (scratch of the projection).
    pub(super) pv: Vec<f64>,
}

/// `out += Phi_q^T y` from the element-local rows `vals` (the layout of `rows`).
pub(super) fn add_transpose(rows: &BlockRows, vals: &[f64], y: &[f64], out: &mut [f64]) {
    rows.add_transpose(vals, y, out);
}

/// A greedy colouring of `adj`'s vertices (`skip`: vertices left uncoloured, `usize::MAX`) in
/// which no vertex shares a colour with one for which `clash(v, colour)` holds.
fn colour(
    count: usize,
    skip: impl Fn(usize) -> bool,
    clash: impl Fn(usize, usize, &[usize]) -> bool,
) -> (Vec<usize>, Vec<Vec<usize>>) {
    let mut color = vec![usize::MAX; count];
    let mut members: Vec<Vec<usize>> = Vec::new();
    for b in 0..count {
        if skip(b) {
            continue;
        }
        let mut k = 0;
        while clash(b, k, &color) {
            k += 1;
        }
        color[b] = k;
        if members.len() <= k {
            members.resize(k + 1, Vec::new());
        }
        members[k].push(b);
    }
    (color, members)
}

impl SparseStage {
    /// Pattern and symbolic analysis of the stage Jacobian of the `(s,s)` scheme on `sys`
    /// (allocates; once per integrator); `projected`: with the (1,1) scheme's projected
    /// stiffness block (`projected.rs`: the modified Lagrangian's position block, `W_1`'s).
    pub(super) fn new(sys: &System, s: usize, projected: bool) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let nblocks = sys.n_body_blocks();
        let blocks: Vec<(usize, usize)> = (0..nblocks)
            .map(|b| sys.body_block(b).unwrap_or((0, 0)))
            .collect();
        let max_width = blocks.iter().map(|b| b.1).max().unwrap_or(0);
        let dim = s * (n + m);
        let rows = BlockRows::new(sys, |_| true)?;
        let nv = rows.n_values();
        // each row's local values and their coordinates
        let mut vcol = vec![0; nv];
        let mut rstart = Vec::with_capacity(m + 1);
        let mut at = 0;
        for sides in rows.sides() {
            rstart.push(at);
            for side in sides.iter().flatten() {
                if side.off != at {
                    return Err(SolveError::Unsupported(
                        "sparse stage: row sides not stored in order".into(),
                    ));
                }
                for l in 0..side.width {
                    vcol[at + l] = side.col + l;
                }
                at += side.width;
            }
        }
        rstart.push(at);
        let row_vals = |r: usize| rstart[r]..rstart[r + 1];
        let mut entries: Vec<(usize, usize)> = Vec::new();
        for nu in 0..s {
            for mu in 1..=s {
                for i in 0..n {
                    entries.push((nu * n + i, (mu - 1) * n + i));
                }
            }
            for r in 0..m {
                for k in row_vals(r) {
                    entries.push((nu * n + vcol[k], s * n + nu * m + r));
                }
            }
        }
        for nu in 1..=s {
            for r in 0..m {
                for c in row_vals(r) {
                    let l = vcol[c];
                    entries.push((s * n + (nu - 1) * m + r, (nu - 1) * n + l));
                    if nu < s {
                        for a in row_vals(r) {
                            entries.push((nu * n + vcol[a], (nu - 1) * n + l));
                        }
                    }
                }
            }
        }
        // force graph over blocks: closed neighbourhoods of the blocks with a force element
        let planar = sys.bodies().len();
        let mut fnbr: Vec<Vec<usize>> = vec![Vec::new(); nblocks];
        let mut link = |a: Option<usize>, b: Option<usize>| {
            for x in [a, b].into_iter().flatten() {
                fnbr[x].push(x);
                for y in [a, b].into_iter().flatten() {
                    fnbr[x].push(y);
                }
            }
        };
        for f in sys.forces() {
            let idx = |r: BodyRef| match r {
                BodyRef::Body(h) if h.index() < planar => Some(h.index()),
                _ => None,
            };
            let (a, b) = f.bodies();
            link(idx(a), idx(b));
        }
        for f in sys.spatial_forces() {
            link(sys.spatial_block(f.a), sys.spatial_block(f.b));
        }
        for v in &mut fnbr {
            v.sort_unstable();
            v.dedup();
        }
        let mut fent = Vec::new();
        for (a, nbrs) in fnbr.iter().enumerate() {
            let (ca, wa) = blocks[a];
            for &b in nbrs {
                let (cb, wb) = blocks[b];
                for r in 0..wa {
                    for c in 0..wb {
                        fent.push((ca + r, cb + c));
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
        let redundant = sys.dependency_budget() > 0;
        if redundant {
            for nu in 1..=s {
                for r in 0..m {
                    let k = s * n + (nu - 1) * m + r;
                    entries.push((k, k));
                }
            }
        }
        let lu = SparseLu::new(dim, &entries)?;
        let proj = if projected && s == 1 {
            Some(Box::new(projected::ProjectedStiffness::new(
                sys,
                (&vcol, &rstart),
                &fent,
                &entries,
                &lu,
            )?))
        } else {
            None
        };
        let slot = |r: usize, c: usize| lu.slot(r, c).unwrap_or(NONE);
        let mut k_slot = vec![NONE; s * s * n];
        for nu in 0..s {
            for mu in 1..=s {
                for i in 0..n {
                    k_slot[(nu * s + mu - 1) * n + i] = slot(nu * n + i, (mu - 1) * n + i);
                }
            }
        }
        let mut lam_slot = vec![NONE; s * nv];
        let mut con_slot = vec![NONE; s * nv];
        let mut cstart = Vec::with_capacity(m + 1);
        let mut nc = 0;
        for r in 0..m {
            cstart.push(nc);
            nc += row_vals(r).len().pow(2);
        }
        cstart.push(nc);
        let mut curv_slot = vec![NONE; s.saturating_sub(1) * nc];
        for r in 0..m {
            let vals = row_vals(r);
            let len = vals.len();
            for k in vals.clone() {
                for nu in 0..s {
                    lam_slot[nu * nv + k] = slot(nu * n + vcol[k], s * n + nu * m + r);
                }
            }
            for nu in 1..=s {
                for (c, kc) in vals.clone().enumerate() {
                    let l = vcol[kc];
                    con_slot[(nu - 1) * nv + kc] = slot(s * n + (nu - 1) * m + r, (nu - 1) * n + l);
                    if nu < s {
                        for (a, ka) in vals.clone().enumerate() {
                            curv_slot[(nu - 1) * nc + cstart[r] + a * len + c] =
                                slot(nu * n + vcol[ka], (nu - 1) * n + l);
                        }
                    }
                }
            }
        }
        // greedy colouring of the blocks: two blocks sharing a row differ
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); nblocks];
        for sides in rows.sides() {
            if let [Some(a), Some(b)] = sides {
                adj[a.block].push(b.block);
                adj[b.block].push(a.block);
            }
        }
        let (color, color_blocks) = colour(
            nblocks,
            |_| false,
            |b, k, color| adj[b].iter().any(|&o| color[o] == k),
        );
        let mut fent_slot = vec![NONE; s * s * fent.len()];
        for nu in 0..s {
            for mu in 1..=s {
                let base = (nu * s + mu - 1) * fent.len();
                for (e, &(i, l)) in fent.iter().enumerate() {
                    fent_slot[base + e] = slot(nu * n + i, (mu - 1) * n + l);
                }
            }
        }
        // distance-2 colouring of the blocks with force elements
        let (fcolor, fcolor_blocks) = colour(
            nblocks,
            |b| fnbr[b].is_empty(),
            |b, k, color| {
                fnbr[b]
                    .iter()
                    .any(|&x| color[x] == k || fnbr[x].iter().any(|&y| color[y] == k))
            },
        );
        // the block of each coordinate, for the seeds
        let mut block_of = vec![0; n];
        for (b, &(c0, w)) in blocks.iter().enumerate() {
            for x in &mut block_of[c0..c0 + w] {
                *x = b;
            }
        }
        let mut fseed = vec![Vec::new(); max_width * fcolor_blocks.len()];
        for (e, &(_, l)) in fent.iter().enumerate() {
            let b = block_of[l];
            fseed[max_width * fcolor[b] + (l - blocks[b].0)].push(e);
        }
        let ne = fent.len();
        let diag_slot = if redundant {
            (0..s * m).map(|k| slot(s * n + k, s * n + k)).collect()
        } else {
            Vec::new()
        };
        let schur = if sys.has_spatial() {
            None
        } else {
            Some(ConstraintSchur::new(sys)?)
        };
        let hess_const = sys.constant_hessian_rows();
        let hess_varies = hess_const.iter().any(|c| !c);
        Ok(SparseStage {
            hess: vec![0.0; nc],
            hess_const,
            hess_ready: false,
            hess_varies,
            diag_slot,
            lu,
            vcol,
            rstart,
            schur,
            acc: SparseAccelerationSolver::new(sys)?,
            k_slot,
            lam_slot,
            con_slot,
            curv_slot,
            cstart,
            color,
            color_blocks,
            max_width,
            blocks,
            dep: Vec::with_capacity(sys.dependency_budget()),
            vdir: vec![0.0; n],
            zero: vec![0.0; n],
            gscratch: vec![0.0; nv],
            dgrads: vec![0.0; nv],
            dtime: vec![0.0; nv],
            fent,
            fent_slot,
            fseed,
            fcolor_blocks,
            hq: vec![0.0; ne],
            hv: vec![0.0; ne],
            qp: vec![0.0; n],
            vp: vec![0.0; n],
            gp: vec![0.0; n],
            gm: vec![0.0; n],
            al: vec![0.0; n],
            pv: vec![0.0; m],
            proj,
            rows,
        })
    }

    /// The local gradients of every row at `(q, t)` into `vals` (the layout of `rows`).
    pub(super) fn gather(&self, sys: &System, q: &[f64], t: f64, vals: &mut [f64]) {
        self.rows.gather(sys, q, None, t, vals, None);
    }
}

impl Galerkin {
    /// The sparse Jacobian of the stage equations at `self.x` (after `residual` at the same
    /// point), factored. Same entries as the dense `jacobian`, written into the slots of the
    /// fixed pattern; the constraint curvature `sum_r lt_r Hess(Phi_r)` at the interior control
    /// points comes from `System::local_rows_tan` along coloured seed directions (one per
    /// colour and block coordinate: `v^T Hess(Phi_r)` for `v` the unit vector of that
    /// coordinate of every block of one colour, which a row between two blocks of different
    /// colours sees for one block only).
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
        let ts = t + self.tab.tau[s] * h;
        sp.gather(sys, &self.qn[s * n..(s + 1) * n], ts, &mut self.grads[s]);
        let h2 = h * h;
        let tab = &self.tab;
        let (minv, unit) = (&self.minv, &self.unit);
        let nv = sp.rows.n_values();
        sp.lu.clear();
        {
            let vals = sp.lu.values_mut();
            for nu in 0..s {
                for mu in 1..=s {
                    let kk = tab.k[nu * s1 + mu];
                    let ks = &sp.k_slot[(nu * s + mu - 1) * n..(nu * s + mu) * n];
                    for (&k, &u) in ks.iter().zip(unit) {
                        vals[k] += kk * u;
                    }
                }
                let g = &self.grads[nu];
                let sl = &sp.lam_slot[nu * nv..(nu + 1) * nv];
                for (k, (&slot, &gk)) in sl.iter().zip(g).enumerate() {
                    vals[slot] = -h2 * minv[sp.vcol[k]] * gk;
                }
            }
            for nu in 1..=s {
                let g = &self.grads[nu];
                let sl = &sp.con_slot[(nu - 1) * nv..nu * nv];
                for (&slot, &gk) in sl.iter().zip(g) {
                    vals[slot] = gk;
                }
            }
        }
        // force Hessians at the Gauss points (coloured central differences)
        if !sp.fent.is_empty() {
            let nonconservative = self.nonconservative;
            let wmax = sp.max_width;
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
                for (k, blocks) in sp.fcolor_blocks.iter().enumerate() {
                    for l in 0..wmax {
                        let seeds = &sp.fseed[wmax * k + l];
                        if seeds.is_empty() {
                            continue;
                        }
                        for (wrt_v, active) in [(false, true), (true, nonconservative)] {
                            if !active {
                                continue;
                            }
                            let base = |c: usize| {
                                if wrt_v {
                                    self.hvj[j * n + c] / h
                                } else {
                                    qj[c]
                                }
                            };
                            let cols = blocks
                                .iter()
                                .map(|&b| sp.blocks[b])
                                .filter(|&(_, w)| l < w)
                                .map(|(c0, _)| c0 + l);
                            let x = if wrt_v { &mut sp.vp } else { &mut sp.qp };
                            for c in cols.clone() {
                                x[c] += 1e-6 * (1.0 + x[c].abs());
                            }
                            grad(&sp.qp, &sp.vp, &mut sp.gp, &mut sp.al);
                            let x = if wrt_v { &mut sp.vp } else { &mut sp.qp };
                            for c in cols.clone() {
                                let x0 = base(c);
                                x[c] = x0 - 1e-6 * (1.0 + x0.abs());
                            }
                            grad(&sp.qp, &sp.vp, &mut sp.gm, &mut sp.al);
                            let x = if wrt_v { &mut sp.vp } else { &mut sp.qp };
                            for c in cols {
                                x[c] = base(c);
                            }
                            let out = if wrt_v { &mut sp.hv } else { &mut sp.hq };
                            for &e in seeds {
                                let (i, c) = sp.fent[e];
                                let x0 = base(c);
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
        // paper A's W_s at the Gauss points: gk times the diagonal stand-in of its Newton
        // Hessian A (Pi A)^s on the entries (momentum row (nu, i), Z_mu,i), as the force
        // Hessians enter (the dense block would fill the LU: S^-1 couples every pair of bodies)
        // (s = 1 with the projected block available: W_1's block A Pi A may be taken exactly
        // below, once the dependent rows are known; its diagonal is added there otherwise)
        let mut w1_rho = None;
        for (j, pre) in self.pre.iter_mut().enumerate() {
            let qj = &self.qj[j * n..(j + 1) * n];
            pre.set_time(t + tab.c[j] * h);
            let wd = &mut self.wdiag;
            let rho = pre
                .newton_diagonal(sys, qj, minv, wd)
                .map_err(|e| with_time(e, t))?;
            if s == 1 && sp.proj.is_some() {
                w1_rho = Some(rho);
                continue;
            }
            let vals = sp.lu.values_mut();
            for nu in 0..s {
                for mu in 1..=s {
                    let ca = tab.b[j] * tab.a[j * s1 + nu] * tab.a[j * s1 + mu];
                    let c = -h2 * ca * self.gk;
                    let ks = &sp.k_slot[(nu * s + mu - 1) * n..(nu * s + mu) * n];
                    for ((&k, &mi), &d) in ks.iter().zip(minv).zip(wd.iter()) {
                        vals[k] += c * mi * d;
                    }
                }
            }
        }
        curvature::add(sp, sys, &self.qn, &self.x, tab, minv, (n, m), (t, h));
        if !sp.diag_slot.is_empty() {
            // the equations dependent at the step's end configuration are left out: their
            // rows become the identity on their multipliers, which then stay put (Newton
            // moves them by the residual of an equation the others imply); found by the
            // planar Schur complement, or with spatial bodies by the body-eliminated one of
            // the end velocity's constrained solve
            let q_end = &self.qn[s * n..(s + 1) * n];
            let more = || SolveError::Singular {
                t: t + h,
                what: "constraint matrix Phi_q M^-1 Phi_q^T of the stage equations",
                detail: "more dependent equations than the model's redundant ones".into(),
            };
            match (sp.schur.as_mut(), self.end_solve.as_deref_mut()) {
                (Some(schur), _) => {
                    schur.update(sys, q_end);
                    schur.factor(&self.minv).map_err(|_| more())?;
                    sp.dep.clear();
                    sp.dep.extend_from_slice(schur.dependent());
                }
                (None, Some(es)) => {
                    es.solve.factor(sys, q_end, t + h)?;
                    es.solve.dependent_rows(&mut sp.dep);
                }
                (None, None) => {}
            }
            let vals = sp.lu.values_mut();
            for &r in &sp.dep {
                let rv = sp.rstart[r]..sp.rstart[r + 1];
                for nu in 1..=s {
                    for k in rv.clone() {
                        for slot in [
                            sp.con_slot[(nu - 1) * nv + k],
                            sp.lam_slot[(nu - 1) * nv + k],
                        ] {
                            if slot != NONE {
                                vals[slot] = 0.0;
                            }
                        }
                    }
                    vals[sp.diag_slot[(nu - 1) * m + r]] = 1.0;
                }
            }
        }
        // the (1,1) scheme's projected blocks, after the dependent rows are known
        // (projected.rs): this Jacobian factors the augmented matrix only if one takes it
        let mut augmented = false;
        if let Some(p) = sp.proj.as_deref_mut() {
            p.deactivate();
        }
        if let (Some(rho), Some(pre)) = (w1_rho, self.pre.first_mut()) {
            // paper A's W_1 (s = 1): gk A Pi A at the Gauss point, exact through the augmented
            // unknowns where |c| rho^2 reaches the threshold, else its diagonal A_ii^2 / m_i
            let c = -h2 * tab.b[0] * tab.a[0] * tab.a[1] * self.gk;
            augmented = projected::takes_block(sp, rho, c);
            if augmented {
                let (nmu0, mass_inv) = pre.paper_stiffness_weights();
                let at = (&self.qj[..n], t + tab.c[0] * h);
                projected::fill(sp, sys, at, nmu0, mass_inv, minv, &self.grads[s], c);
            } else {
                let vals = sp.lu.values_mut();
                for ((&k, &mi), &d) in sp.k_slot[..n].iter().zip(minv).zip(&self.wdiag) {
                    vals[k] += c * mi * d;
                }
            }
        }
        if let Some(ml) = self.ml.first_mut().filter(|_| s == 1) {
            // the s = 1 modified Lagrangian: the diagonal of the velocity block of
            // galerkin/dense.rs, -h^2/12 (2 B), on the entries (i, Z_1,i) (its dense part
            // through S^-1 is left out), and the position block -h^4/48 A_s Pi A_s, exact
            // through the augmented unknowns where it is not small, else the diagonal of
            // A M^-1 A (docs/symplectic.md section 5a)
            let [wd, sd, ad] = &mut self.mldiag;
            ml.set_time(t + 0.5 * h);
            let rho = ml
                .modified_newton_diagonals(sys, &self.mlmid, &self.mlvel, [wd, sd, ad])
                .map_err(|e| with_time(e, t))?;
            let (cw, c) = (-h2 / 12.0, -(h2 * h2) / 48.0);
            let (cm, mass_inv) = ml.modified_stiffness_weights();
            augmented = projected::takes_block(sp, rho, c);
            let vals = sp.lu.values_mut();
            for i in 0..n {
                let pos = if augmented { 0.0 } else { c * ad[i] };
                vals[sp.k_slot[i]] += minv[i] * (cw * 2.0 * wd[i] + pos);
            }
            if augmented {
                let mid = (self.mlmid.as_slice(), t + 0.5 * h);
                projected::fill(sp, sys, mid, cm, mass_inv, minv, &self.grads[s], c);
            }
        }
        self.jacobians += 1;
        self.jac_valid = false;
        let res = match sp.proj.as_deref_mut().filter(|_| augmented) {
            Some(p) => p.factor(),
            None => sp.lu.factor(),
        };
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

//! The assembled multibody system and its builder.

use crate::body::{Body, BodyHandle, BodyRef};
use crate::error::ModelError;
use crate::force::{Force, ForceKind};
use crate::jet::{DirJet, Dual, Frame, HessJet, Scalar, TanJet, NV};
use crate::joint::{Joint, JointKind};
use nalgebra::{DMatrix, DVector, Vector2};

/// Handle of a joint inside a [`System`] (its index, in insertion order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointHandle(pub usize);

/// Handle of a force element inside a [`System`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ForceHandle(pub usize);

/// Collects bodies, joints and forces; [`SystemBuilder::build`] validates them into a [`System`].
#[derive(Clone, Debug, Default)]
pub struct SystemBuilder {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) forces: Vec<Force>,
    pub(crate) gravity: [f64; 2],
}

impl SystemBuilder {
    /// An empty model with zero gravity.
    pub fn new() -> Self {
        Self::default()
    }
    /// Sets the gravity vector (m/s^2), e.g. `[0.0, -9.81]`. It may be zero.
    pub fn set_gravity(&mut self, g: [f64; 2]) -> &mut Self {
        self.gravity = g;
        self
    }
    /// Adds a body and returns its handle.
    pub fn add_body(&mut self, body: Body) -> BodyHandle {
        self.bodies.push(body);
        BodyHandle(self.bodies.len() - 1)
    }
    /// Adds a joint and returns its handle.
    pub fn add_joint(&mut self, joint: Joint) -> JointHandle {
        self.joints.push(joint);
        JointHandle(self.joints.len() - 1)
    }
    /// Adds a force element and returns its handle.
    pub fn add_force(&mut self, force: Force) -> ForceHandle {
        self.forces.push(force);
        ForceHandle(self.forces.len() - 1)
    }
    /// Validates the model and assembles it. Checks names, parameters, attachments, and the rank
    /// of `Phi_q` at the bodies' initial positions (redundant constraints are an error naming the
    /// joints involved).
    pub fn build(self) -> Result<System, ModelError> {
        System::new(self)
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Attach {
    pub(crate) a: Option<usize>,
    pub(crate) b: Option<usize>,
}

/// A validated planar multibody system in absolute coordinates `q = (x_i, y_i, theta_i)_i`.
///
/// All evaluation methods take slices of length [`System::n_coords`] (`q`, `v`) or
/// [`System::n_constraints`] (`lambda`) and write into caller-provided buffers, so hot loops
/// allocate nothing.
#[derive(Clone, Debug)]
pub struct System {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) forces: Vec<Force>,
    pub(crate) gravity: [f64; 2],
    pub(crate) joint_attach: Vec<Attach>,
    pub(crate) force_attach: Vec<Attach>,
    pub(crate) row_offset: Vec<usize>,
    pub(crate) n: usize,
    pub(crate) m: usize,
    pub(crate) mass: DVector<f64>,
    pub(crate) inv_mass: DVector<f64>,
    pub(crate) eq_joint: Vec<usize>,
}

fn check_finite(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be finite",
        })
    }
}

fn check_positive(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be positive and finite",
        })
    }
}

fn check_nonneg(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be non-negative and finite",
        })
    }
}

fn check_point(element: &str, parameter: &'static str, p: [f64; 2]) -> Result<(), ModelError> {
    check_finite(element, parameter, p[0])?;
    check_finite(element, parameter, p[1])
}

fn check_timefn(
    element: &str,
    parameter: &'static str,
    f: &crate::TimeFunction,
) -> Result<(), ModelError> {
    if f.is_finite() {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value: f64::NAN,
            reason: "time function coefficients must be finite",
        })
    }
}

/// `sin` and `cos` of every body's angle from the last evaluation, for repeated evaluations
/// at nearby configurations (Newton iterations): [`System::phi_and_phi_dot_cached`] rotates
/// the cached values by the angle increment `delta` (`|delta| <= 1e-3`, with `cos delta` and
/// `sin delta` from their Taylor series, exact to rounding there) instead of calling `sin_cos`,
/// and recomputes them exactly after [`AngleCache::MAX_ROTATIONS`] rotations, for a larger
/// increment, or after [`AngleCache::invalidate`]. The rotated values differ from exact ones by
/// a few units in the last place.
#[derive(Clone, Debug)]
pub struct AngleCache {
    /// Per body: the angle, its sine and cosine, and the rotations since the exact evaluation.
    entries: Vec<AngleEntry>,
    valid: bool,
}

#[derive(Clone, Copy, Debug, Default)]
struct AngleEntry {
    theta: f64,
    s: f64,
    c: f64,
    rotations: u32,
}

impl AngleCache {
    /// Rotations allowed between two exact evaluations of one body's `sin_cos`.
    pub const MAX_ROTATIONS: u32 = 8;

    /// A cache for the bodies of `sys` (empty: the first evaluation is exact).
    pub fn new(sys: &System) -> Self {
        AngleCache {
            entries: vec![AngleEntry::default(); sys.bodies.len()],
            valid: false,
        }
    }

    /// Forgets the cached values: the next evaluation computes `sin_cos` exactly.
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// `(sin, cos)` of body `i`'s angle `theta`, updating the cache. For `|d| <= 1e-3` the
    /// truncated series `cos d = 1 - d^2/2 + d^4/24`, `sin d = d - d^3/6 + d^5/120` are exact to
    /// rounding (the next terms are below 1.4e-21).
    #[inline]
    fn sin_cos(&mut self, i: usize, theta: f64) -> (f64, f64) {
        let valid = self.valid;
        let e = &mut self.entries[i];
        let d = theta - e.theta;
        if valid && d.abs() <= 1e-3 && e.rotations < Self::MAX_ROTATIONS {
            if d != 0.0 {
                let d2 = d * d;
                let cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0));
                let sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)));
                let (s, c) = (e.s, e.c);
                e.s = s * cd + c * sd;
                e.c = c * cd - s * sd;
                e.theta = theta;
                e.rotations += 1;
            }
        } else {
            (e.s, e.c) = theta.sin_cos();
            e.theta = theta;
            e.rotations = 0;
        }
        (e.s, e.c)
    }
}

impl System {
    fn new(b: SystemBuilder) -> Result<System, ModelError> {
        let SystemBuilder {
            bodies,
            mut joints,
            forces,
            gravity,
        } = b;
        if bodies.is_empty() {
            return Err(ModelError::Empty);
        }
        check_finite("gravity", "gravity", gravity[0])?;
        check_finite("gravity", "gravity", gravity[1])?;
        let mut names = std::collections::HashSet::new();
        for body in &bodies {
            if body.name.eq_ignore_ascii_case("ground") {
                return Err(ModelError::DuplicateName {
                    kind: "body (reserved for the ground)",
                    name: body.name.clone(),
                });
            }
            if !names.insert(body.name.as_str()) {
                return Err(ModelError::DuplicateName {
                    kind: "body",
                    name: body.name.clone(),
                });
            }
            check_positive(&body.name, "mass", body.mass)?;
            check_positive(&body.name, "inertia", body.inertia)?;
            for &p in &body.position {
                check_finite(&body.name, "position", p)?;
            }
            for &v in &body.velocity {
                check_finite(&body.name, "velocity", v)?;
            }
        }
        let nb = bodies.len();
        let resolve = |element: &str, r: BodyRef| -> Result<Option<usize>, ModelError> {
            match r {
                BodyRef::Ground => Ok(None),
                BodyRef::Body(h) if h.0 < nb => Ok(Some(h.0)),
                BodyRef::Body(h) => Err(ModelError::UnknownBody {
                    element: element.to_string(),
                    body: format!("#{} (the model has {} bodies)", h.0, nb),
                }),
            }
        };
        let body_name = |i: Option<usize>| -> String {
            i.map_or_else(|| "ground".to_string(), |i| bodies[i].name.clone())
        };

        let mut jnames = std::collections::HashSet::new();
        let mut joint_attach = Vec::with_capacity(joints.len());
        for j in joints.iter_mut() {
            if !jnames.insert(j.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "joint",
                    name: j.name.clone(),
                });
            }
            let (ra, rb) = j.bodies();
            let a = resolve(&j.name, ra)?;
            let bb = resolve(&j.name, rb)?;
            let single = matches!(j.kind, JointKind::Absolute { .. });
            if a == bb && !(single && a.is_some()) {
                return Err(ModelError::SameBody {
                    joint: j.name.clone(),
                    body: body_name(a),
                });
            }
            let name = j.name.clone();
            match &mut j.kind {
                JointKind::Revolute { pa, pb, .. } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                }
                JointKind::Weld { pa, pb, angle, .. } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                    check_finite(&name, "angle", *angle)?;
                }
                JointKind::Prismatic {
                    pa,
                    pb,
                    axis,
                    angle,
                    ..
                } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                    check_point(&name, "axis", *axis)?;
                    check_finite(&name, "angle", *angle)?;
                    let len = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
                    check_positive(&name, "axis length", len)?;
                    *axis = [axis[0] / len, axis[1] / len];
                }
                JointKind::Distance { pa, pb, length, .. } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                    check_positive(&name, "length", *length)?;
                }
                JointKind::Absolute { point, value, .. } => {
                    check_point(&name, "point", *point)?;
                    check_finite(&name, "value", *value)?;
                }
                JointKind::AngleDriver { f, .. } => check_timefn(&name, "f", f)?,
            }
            joint_attach.push(Attach { a, b: bb });
        }

        let mut fnames = std::collections::HashSet::new();
        let mut force_attach = Vec::with_capacity(forces.len());
        for f in &forces {
            if !fnames.insert(f.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "force",
                    name: f.name.clone(),
                });
            }
            let (ra, rb) = f.bodies();
            let a = resolve(&f.name, ra)?;
            let bb = resolve(&f.name, rb)?;
            let single = matches!(f.kind, ForceKind::Force { .. } | ForceKind::Torque { .. });
            if single && a.is_none() {
                return Err(ModelError::SameBody {
                    joint: f.name.clone(),
                    body: "ground".into(),
                });
            }
            if !single && a == bb {
                return Err(ModelError::SameBody {
                    joint: f.name.clone(),
                    body: body_name(a),
                });
            }
            match &f.kind {
                ForceKind::SpringDamper {
                    pa,
                    pb,
                    stiffness,
                    damping,
                    rest_length,
                    ..
                } => {
                    check_point(&f.name, "point_a", *pa)?;
                    check_point(&f.name, "point_b", *pb)?;
                    check_nonneg(&f.name, "stiffness", *stiffness)?;
                    check_nonneg(&f.name, "damping", *damping)?;
                    check_nonneg(&f.name, "rest_length", *rest_length)?;
                }
                ForceKind::RotarySpringDamper {
                    stiffness,
                    damping,
                    rest_angle,
                    ..
                } => {
                    check_nonneg(&f.name, "stiffness", *stiffness)?;
                    check_nonneg(&f.name, "damping", *damping)?;
                    check_finite(&f.name, "rest_angle", *rest_angle)?;
                }
                ForceKind::Force { point, fx, fy, .. } => {
                    check_point(&f.name, "point", *point)?;
                    check_timefn(&f.name, "fx", fx)?;
                    check_timefn(&f.name, "fy", fy)?;
                }
                ForceKind::Torque { torque, .. } => check_timefn(&f.name, "torque", torque)?,
            }
            force_attach.push(Attach { a, b: bb });
        }

        let n = 3 * nb;
        let mut row_offset = Vec::with_capacity(joints.len());
        let mut eq_joint = Vec::new();
        let mut m = 0;
        for (ji, j) in joints.iter().enumerate() {
            row_offset.push(m);
            for _ in 0..j.n_equations() {
                eq_joint.push(ji);
            }
            m += j.n_equations();
        }
        let mass =
            DVector::from_iterator(n, bodies.iter().flat_map(|b| [b.mass, b.mass, b.inertia]));
        let inv_mass = mass.map(|x| 1.0 / x);
        let sys = System {
            bodies,
            joints,
            forces,
            gravity,
            joint_attach,
            force_attach,
            row_offset,
            n,
            m,
            mass,
            inv_mass,
            eq_joint,
        };
        sys.check_inertia_scale()?;
        let (q0, _) = sys.initial_guess();
        sys.check_rank(q0.as_slice(), 0.0)?;
        Ok(sys)
    }

    // ---------------------------------------------------------------- layout and names

    /// Number of coordinates `n = 3 * bodies`.
    pub fn n_coords(&self) -> usize {
        self.n
    }
    /// Number of scalar constraint equations `m`.
    pub fn n_constraints(&self) -> usize {
        self.m
    }
    /// Degrees of freedom `n - m` (the rank check at build guarantees independent equations).
    pub fn dof(&self) -> usize {
        self.n - self.m
    }
    /// The bodies, in handle order.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }
    /// The joints, in handle order.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }
    /// The force elements.
    pub fn forces(&self) -> &[Force] {
        &self.forces
    }
    /// The gravity vector.
    pub fn gravity(&self) -> [f64; 2] {
        self.gravity
    }
    /// The handle of the body called `name`.
    pub fn body_handle(&self, name: &str) -> Option<BodyHandle> {
        self.bodies
            .iter()
            .position(|b| b.name == name)
            .map(BodyHandle)
    }
    /// The handle of the joint called `name`.
    pub fn joint_handle(&self, name: &str) -> Option<JointHandle> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .map(JointHandle)
    }
    /// Names of the coordinates: `body.x`, `body.y`, `body.theta`.
    pub fn coordinate_names(&self) -> Vec<String> {
        self.bodies
            .iter()
            .flat_map(|b| ["x", "y", "theta"].map(|c| format!("{}.{}", b.name, c)))
            .collect()
    }
    /// Names of the constraint equations: `joint.label`.
    pub fn equation_names(&self) -> Vec<String> {
        self.joints
            .iter()
            .flat_map(|j| {
                j.equation_labels()
                    .iter()
                    .map(move |l| format!("{}.{}", j.name, l))
            })
            .collect()
    }
    /// The name of equation `row`.
    pub fn equation_name(&self, row: usize) -> String {
        match self.eq_joint.get(row) {
            Some(&ji) => {
                let j = &self.joints[ji];
                format!(
                    "{}.{}",
                    j.name,
                    j.equation_labels()[row - self.row_offset[ji]]
                )
            }
            None => format!("equation #{row}"),
        }
    }
    /// The joint that owns equation `row`.
    pub fn equation_joint(&self, row: usize) -> Option<JointHandle> {
        self.eq_joint.get(row).map(|&j| JointHandle(j))
    }
    /// First row of each joint's equations in `Phi`.
    pub fn joint_rows(&self, j: JointHandle) -> std::ops::Range<usize> {
        let o = self.row_offset[j.0];
        o..o + self.joints[j.0].n_equations()
    }
    /// Whether some constraint depends explicitly on time.
    pub fn is_rheonomic(&self) -> bool {
        self.joints.iter().any(|j| j.is_rheonomic())
    }
    /// Whether all applied forces derive from the potential [`System::potential`] (no damping, no
    /// time-dependent loads).
    pub fn is_conservative(&self) -> bool {
        !self.forces.iter().any(|f| f.is_nonconservative())
    }

    /// The diagonal of the (constant, diagonal) mass matrix `M = diag(m_i, m_i, J_i)`.
    pub fn mass_diag(&self) -> &DVector<f64> {
        &self.mass
    }
    /// The diagonal of `M^-1`.
    pub fn inv_mass_diag(&self) -> &DVector<f64> {
        &self.inv_mass
    }
    /// The mass matrix as a dense matrix.
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_diagonal(&self.mass)
    }

    /// The initial guess stored in the bodies: `(q, v)`.
    pub fn initial_guess(&self) -> (DVector<f64>, DVector<f64>) {
        let q = DVector::from_iterator(self.n, self.bodies.iter().flat_map(|b| b.position));
        let v = DVector::from_iterator(self.n, self.bodies.iter().flat_map(|b| b.velocity));
        (q, v)
    }

    pub(crate) fn check_len(
        &self,
        what: &'static str,
        x: &[f64],
        expected: usize,
    ) -> Result<(), ModelError> {
        if x.len() == expected {
            Ok(())
        } else {
            Err(ModelError::Dimension {
                what,
                expected,
                got: x.len(),
            })
        }
    }

    // ---------------------------------------------------------------- local jets

    #[inline(always)]
    fn loc_f64(q: &[f64], i: Option<usize>) -> [f64; 3] {
        match i {
            Some(i) => [q[3 * i], q[3 * i + 1], q[3 * i + 2]],
            None => [0.0; 3],
        }
    }
    #[inline(always)]
    fn frm_f64(q: &[f64], i: Option<usize>) -> Frame<f64> {
        match i {
            Some(i) => Frame::new([q[3 * i], q[3 * i + 1], q[3 * i + 2]]),
            None => Frame::fixed(),
        }
    }
    #[inline(always)]
    fn loc_dir(q: &[f64], v: Option<&[f64]>, i: Option<usize>, slot: usize) -> Frame<DirJet> {
        match i {
            Some(i) => Frame::new(std::array::from_fn(|k| {
                DirJet::var(slot + k, q[3 * i + k], v.map_or(0.0, |v| v[3 * i + k]))
            })),
            None => Frame::fixed(),
        }
    }
    #[inline(always)]
    fn loc_tan(q: &[f64], v: &[f64], i: Option<usize>, slot: usize) -> Frame<TanJet> {
        match i {
            Some(i) => Frame::new(std::array::from_fn(|k| {
                TanJet::var(slot + k, q[3 * i + k], v[3 * i + k])
            })),
            None => Frame::fixed(),
        }
    }
    #[inline(always)]
    fn loc_hess(q: &[f64], i: Option<usize>, slot: usize) -> Frame<HessJet> {
        match i {
            Some(i) => Frame::new(std::array::from_fn(|k| {
                HessJet::var(slot + k, q[3 * i + k])
            })),
            None => Frame::fixed(),
        }
    }
    // ---------------------------------------------------------------- constraints

    /// `Phi(q, t)` into `out` (length m).
    pub fn phi(&self, q: &[f64], t: f64, out: &mut [f64]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let qa = Self::frm_f64(q, at.a);
            let qb = Self::frm_f64(q, at.b);
            let mut e = [0.0; 3];
            j.eval(&qa, &qb, &mut e);
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                out[o + k] = e[k] - j.time_part(k, t)[0];
            }
        }
    }

    /// `Phi_t(q, t)` into `out` (length m).
    pub fn phi_t(&self, t: f64, out: &mut [f64]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                out[o + k] = -j.time_part(k, t)[1];
            }
        }
    }

    #[inline(always)]
    fn joint_dir(&self, ji: usize, q: &[f64], v: Option<&[f64]>) -> [DirJet; 3] {
        let at = self.joint_attach[ji];
        let qa = Self::loc_dir(q, v, at.a, 0);
        let qb = Self::loc_dir(q, v, at.b, 3);
        let mut e = [DirJet::cst(0.0); 3];
        self.joints[ji].eval(&qa, &qb, &mut e);
        e
    }

    #[inline(always)]
    fn scatter_row(&self, ji: usize, row: usize, g: &[f64; NV], out: &mut DMatrix<f64>) {
        let at = self.joint_attach[ji];
        if let Some(i) = at.a {
            for l in 0..3 {
                out[(row, 3 * i + l)] += g[l];
            }
        }
        if let Some(i) = at.b {
            for l in 0..3 {
                out[(row, 3 * i + l)] += g[3 + l];
            }
        }
    }

    /// The constraint Jacobian `Phi_q` (m x n, dense) into `out` (overwritten).
    pub fn phi_q(&self, q: &[f64], out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        for ji in 0..self.joints.len() {
            let e = self.joint_dir(ji, q, None);
            let o = self.row_offset[ji];
            for k in 0..self.joints[ji].n_equations() {
                self.scatter_row(ji, o + k, &e[k].g, out);
            }
        }
    }

    /// `Phi_q` and the acceleration right-hand side
    /// `gamma = -(Phi_q v)_q v - 2 Phi_qt v - Phi_tt` in one pass.
    pub fn phi_q_gamma(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi_q: &mut DMatrix<f64>,
        gamma: &mut [f64],
    ) {
        phi_q.as_mut_slice().fill(0.0);
        for (ji, j) in self.joints.iter().enumerate() {
            let e = self.joint_dir(ji, q, Some(v));
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                self.scatter_row(ji, o + k, &e[k].g, phi_q);
                gamma[o + k] = -e[k].d2 + j.time_part(k, t)[2];
            }
        }
    }

    /// `Phi_q` and the Jacobian of the velocity constraint with respect to `q`,
    /// `(Phi_q v)_q = d/dq (Phi_q(q) v)` (m x n; row `k` is `v^T Hess(Phi_k)`), in one pass.
    /// Together they form the Jacobian `[[Phi_q, 0], [(Phi_q v)_q, Phi_q]]` of the first-order
    /// constraints `(Phi, Phi_q v + Phi_t)` in `(q, v)` (`Phi_qt = 0` for every joint, so
    /// `Phi_t` adds nothing). Exact (Hessian jets), both outputs overwritten.
    pub fn phi_q_dot_jacobian(
        &self,
        q: &[f64],
        v: &[f64],
        phi_q: &mut DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) {
        phi_q.as_mut_slice().fill(0.0);
        out.fill(0.0);
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let qa = Self::loc_tan(q, v, at.a, 0);
            let qb = Self::loc_tan(q, v, at.b, 3);
            let mut e = [TanJet::cst(0.0); 3];
            j.eval(&qa, &qb, &mut e);
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                self.scatter_row(ji, o + k, &e[k].g, phi_q);
                self.scatter_row(ji, o + k, &e[k].dg, out);
            }
        }
    }

    /// [`System::phi_q_dot_jacobian`] in element-local form (see [`System::phi_q_local`]):
    /// `grads[r]` is row `r` of `Phi_q`, `dgrads[r]` row `r` of `(Phi_q v)_q`, each six numbers
    /// in the columns of the joint's two bodies ([`System::joint_bodies`]).
    pub fn phi_q_dot_local(
        &self,
        q: &[f64],
        v: &[f64],
        grads: &mut [[f64; 6]],
        dgrads: &mut [[f64; 6]],
    ) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let qa = Self::loc_tan(q, v, at.a, 0);
            let qb = Self::loc_tan(q, v, at.b, 3);
            let mut e = [TanJet::cst(0.0); 3];
            j.eval(&qa, &qb, &mut e);
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                grads[o + k] = e[k].g;
                dgrads[o + k] = e[k].dg;
            }
        }
    }

    /// The bodies a joint attaches, as coordinate-block indices (`None` = ground).
    pub fn joint_bodies(&self, j: JointHandle) -> (Option<usize>, Option<usize>) {
        let at = self.joint_attach[j.0];
        (at.a, at.b)
    }

    /// `Phi_q` in element-local form alone (see [`System::phi_q_local_gamma`]): row `r` is
    /// `grads[r][0..3]` in the columns of the joint's first body and `grads[r][3..6]` in those
    /// of its second ([`System::joint_bodies`]).
    pub fn phi_q_local(&self, q: &[f64], grads: &mut [[f64; 6]]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let e = self.joint_dir(ji, q, None);
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                grads[o + k] = e[k].g;
            }
        }
    }

    /// `Phi_q` in element-local form and `gamma`, for sparse assembly: row `r` of `Phi_q` is
    /// `grads[r][0..3]` in the columns of the joint's first body and `grads[r][3..6]` in those of
    /// its second ([`System::joint_bodies`]; entries for ground are zero).
    pub fn phi_q_local_gamma(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        grads: &mut [[f64; 6]],
        gamma: &mut [f64],
    ) {
        for (ji, j) in self.joints.iter().enumerate() {
            let e = self.joint_dir(ji, q, Some(v));
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                grads[o + k] = e[k].g;
                gamma[o + k] = -e[k].d2 + j.time_part(k, t)[2];
            }
        }
    }

    /// `gamma(q, v, t)` alone.
    pub fn gamma(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let e = self.joint_dir(ji, q, Some(v));
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                out[o + k] = -e[k].d2 + j.time_part(k, t)[2];
            }
        }
    }

    /// The velocity constraint `Phi_q v + Phi_t` into `out`.
    pub fn phi_dot(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let e = self.joint_dir(ji, q, Some(v));
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                out[o + k] = e[k].d1 - j.time_part(k, t)[1];
            }
        }
    }

    /// Joint `ji`'s rows of `Phi` and `Phidot` from its bodies' frames.
    #[inline(always)]
    fn eval_phi_phi_dot(
        &self,
        ji: usize,
        fa: &Frame<Dual>,
        fb: &Frame<Dual>,
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
    ) {
        let j = &self.joints[ji];
        let mut e = [Dual::cst(0.0); 3];
        j.eval(fa, fb, &mut e);
        let o = self.row_offset[ji];
        for k in 0..j.n_equations() {
            let tp = j.time_part(k, t);
            phi[o + k] = e[k].v - tp[0];
            phi_dot[o + k] = e[k].d - tp[1];
        }
    }

    /// `Phi(q, t)` and the velocity constraint `Phi_q v + Phi_t` in one pass with dual numbers
    /// (no gradients formed): the cheapest evaluation of both constraint levels, e.g. for the
    /// residual of a Newton iteration on the first-order manifold.
    pub fn phi_and_phi_dot(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
    ) {
        let loc = |i: usize| -> Frame<Dual> {
            Frame::new(std::array::from_fn(|k| {
                Dual::var(q[3 * i + k], v[3 * i + k])
            }))
        };
        let fixed = Frame::fixed();
        let mut eval = |ji: usize, fa: &Frame<Dual>, fb: &Frame<Dual>| {
            self.eval_phi_phi_dot(ji, fa, fb, t, phi, phi_dot);
        };
        // each body's sin/cos once (not once per joint) for models of up to 16 bodies
        const STACK: usize = 16;
        let nb = self.bodies.len();
        if nb <= STACK {
            let mut frames = [fixed; STACK];
            for (i, f) in frames.iter_mut().enumerate().take(nb) {
                *f = loc(i);
            }
            for ji in 0..self.joints.len() {
                let at = self.joint_attach[ji];
                let fa = at.a.map_or(&fixed, |i| &frames[i]);
                let fb = at.b.map_or(&fixed, |i| &frames[i]);
                eval(ji, fa, fb);
            }
        } else {
            for ji in 0..self.joints.len() {
                let at = self.joint_attach[ji];
                let fa = at.a.map_or(fixed, loc);
                let fb = at.b.map_or(fixed, loc);
                eval(ji, &fa, &fb);
            }
        }
    }

    /// [`System::phi_and_phi_dot`] with the bodies' `sin`/`cos` from `cache` (see
    /// [`AngleCache`]): the same values to a few units in the last place, cheaper when called
    /// repeatedly at nearby configurations.
    pub fn phi_and_phi_dot_cached(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
        cache: &mut AngleCache,
    ) {
        let nb = self.bodies.len();
        if cache.entries.len() != nb {
            self.phi_and_phi_dot(q, v, t, phi, phi_dot);
            return;
        }
        for i in 0..nb {
            cache.sin_cos(i, q[3 * i + 2]);
        }
        cache.valid = true;
        let entries = &cache.entries;
        let frame = |i: Option<usize>| -> Frame<Dual> {
            match i {
                Some(i) => {
                    let e = entries[i];
                    let w = v[3 * i + 2];
                    Frame {
                        q: std::array::from_fn(|k| Dual::var(q[3 * i + k], v[3 * i + k])),
                        c: Dual {
                            v: e.c,
                            d: -e.s * w,
                        },
                        s: Dual { v: e.s, d: e.c * w },
                    }
                }
                None => Frame::fixed(),
            }
        };
        for ji in 0..self.joints.len() {
            let at = self.joint_attach[ji];
            self.eval_phi_phi_dot(ji, &frame(at.a), &frame(at.b), t, phi, phi_dot);
        }
    }

    /// `Phi_q` as (row, column, value) triplets of its structural non-zeros, for sparse
    /// factorisations. `out` is cleared first; its capacity is reused.
    pub fn phi_q_triplets(&self, q: &[f64], out: &mut Vec<(usize, usize, f64)>) {
        out.clear();
        for (ji, j) in self.joints.iter().enumerate() {
            let e = self.joint_dir(ji, q, None);
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                if let Some(i) = at.a {
                    for l in 0..3 {
                        out.push((o + k, 3 * i + l, e[k].g[l]));
                    }
                }
                if let Some(i) = at.b {
                    for l in 0..3 {
                        out.push((o + k, 3 * i + l, e[k].g[3 + l]));
                    }
                }
            }
        }
    }

    /// The lambda-weighted constraint Hessian `sum_k lambda_k d^2 Phi_k / dq^2` (n x n) into `out`
    /// (overwritten).
    pub fn constraint_hessian(&self, q: &[f64], lambda: &[f64], out: &mut DMatrix<f64>) {
        out.fill(0.0);
        self.add_constraint_hessian(q, lambda, 1.0, out);
    }

    /// Adds `scale * sum_k lambda_k d^2 Phi_k / dq^2` into `out`.
    pub fn add_constraint_hessian(
        &self,
        q: &[f64],
        lambda: &[f64],
        scale: f64,
        out: &mut DMatrix<f64>,
    ) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let qa = Self::loc_hess(q, at.a, 0);
            let qb = Self::loc_hess(q, at.b, 3);
            let mut e = [HessJet::cst(0.0); 3];
            j.eval(&qa, &qb, &mut e);
            let o = self.row_offset[ji];
            let mut h = [[0.0; NV]; NV];
            for k in 0..j.n_equations() {
                let l = lambda[o + k] * scale;
                for r in 0..NV {
                    for c in 0..NV {
                        h[r][c] += l * e[k].h[r][c];
                    }
                }
            }
            Self::scatter_hess(at, &h, out);
        }
    }

    fn scatter_hess(at: Attach, h: &[[f64; NV]; NV], out: &mut DMatrix<f64>) {
        let cols = |l: usize| -> Option<usize> {
            if l < 3 {
                at.a.map(|i| 3 * i + l)
            } else {
                at.b.map(|i| 3 * i + l - 3)
            }
        };
        for r in 0..NV {
            let Some(gr) = cols(r) else { continue };
            for c in 0..NV {
                let Some(gc) = cols(c) else { continue };
                out[(gr, gc)] += h[r][c];
            }
        }
    }

    // ---------------------------------------------------------------- forces and energy

    /// Potential energy `V(q)`: gravity, springs and constant loads.
    pub fn potential(&self, q: &[f64]) -> f64 {
        let mut v = 0.0;
        for (i, b) in self.bodies.iter().enumerate() {
            v -= b.mass * (self.gravity[0] * q[3 * i] + self.gravity[1] * q[3 * i + 1]);
        }
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            v += f.potential(&Self::frm_f64(q, at.a), &Self::frm_f64(q, at.b));
        }
        v
    }

    /// Kinetic energy `1/2 v^T M v`.
    pub fn kinetic(&self, v: &[f64]) -> f64 {
        0.5 * v
            .iter()
            .zip(self.mass.iter())
            .map(|(v, m)| m * v * v)
            .sum::<f64>()
    }

    /// Total energy `H = T + V`.
    pub fn energy(&self, q: &[f64], v: &[f64]) -> f64 {
        self.kinetic(v) + self.potential(q)
    }

    /// `grad V(q)` into `out` (overwritten).
    pub fn potential_gradient(&self, q: &[f64], out: &mut [f64]) {
        for (i, b) in self.bodies.iter().enumerate() {
            out[3 * i] = -b.mass * self.gravity[0];
            out[3 * i + 1] = -b.mass * self.gravity[1];
            out[3 * i + 2] = 0.0;
        }
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let e = f.potential(
                &Self::loc_dir(q, None, at.a, 0),
                &Self::loc_dir(q, None, at.b, 3),
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] += e.g[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] += e.g[3 + l];
                }
            }
        }
    }

    /// The Hessian of the potential `d^2 V / dq^2` (the stiffness) into `out` (overwritten).
    pub fn potential_hessian(&self, q: &[f64], out: &mut DMatrix<f64>) {
        out.fill(0.0);
        self.add_potential_hessian(q, 1.0, out);
    }

    /// Adds `scale * d^2 V / dq^2` into `out`.
    pub fn add_potential_hessian(&self, q: &[f64], scale: f64, out: &mut DMatrix<f64>) {
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let e = f.potential(&Self::loc_hess(q, at.a, 0), &Self::loc_hess(q, at.b, 3));
            let mut h = e.h;
            for row in h.iter_mut() {
                for x in row.iter_mut() {
                    *x *= scale;
                }
            }
            Self::scatter_hess(at, &h, out);
        }
    }

    /// Non-conservative generalized forces (dampers, time-dependent loads) into `out`
    /// (overwritten).
    pub fn nonconservative_forces(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        out.fill(0.0);
        for (fi, f) in self.forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let at = self.force_attach[fi];
            let mut loc = [0.0; 6];
            f.nonconservative(
                &Self::loc_f64(q, at.a),
                &Self::loc_f64(q, at.b),
                &Self::loc_f64(v, at.a),
                &Self::loc_f64(v, at.b),
                t,
                &mut loc,
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] += loc[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] += loc[3 + l];
                }
            }
        }
    }

    /// All generalized applied forces `Q(q, v, t) = -grad V + Q_nc` into `out` (overwritten).
    pub fn forces_into(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.potential_gradient(q, out);
        for x in out.iter_mut() {
            *x = -*x;
        }
        for (fi, f) in self.forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let at = self.force_attach[fi];
            let mut loc = [0.0; 6];
            f.nonconservative(
                &Self::loc_f64(q, at.a),
                &Self::loc_f64(q, at.b),
                &Self::loc_f64(v, at.a),
                &Self::loc_f64(v, at.b),
                t,
                &mut loc,
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] += loc[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] += loc[3 + l];
                }
            }
        }
    }

    // ---------------------------------------------------------------- points

    /// Global position of the point `local` (body frame) of `body`.
    pub fn point_position(&self, body: BodyHandle, local: [f64; 2], q: &[f64]) -> Vector2<f64> {
        let i = body.0;
        let (s, c) = q[3 * i + 2].sin_cos();
        Vector2::new(
            q[3 * i] + c * local[0] - s * local[1],
            q[3 * i + 1] + s * local[0] + c * local[1],
        )
    }

    /// Global velocity of the point `local` of `body`.
    pub fn point_velocity(
        &self,
        body: BodyHandle,
        local: [f64; 2],
        q: &[f64],
        v: &[f64],
    ) -> Vector2<f64> {
        let i = body.0;
        let (s, c) = q[3 * i + 2].sin_cos();
        let w = v[3 * i + 2];
        Vector2::new(
            v[3 * i] + w * (-s * local[0] - c * local[1]),
            v[3 * i + 1] + w * (c * local[0] - s * local[1]),
        )
    }
}

#[cfg(test)]
mod phi_q_dot_jacobian_tests {
    use crate::{models, Body, BodyRef, Coordinate, Joint, SystemBuilder, TimeFunction};
    use nalgebra::DMatrix;

    fn all_joint_kinds() -> crate::System {
        let mut b = SystemBuilder::new();
        let b1 = b.add_body(Body::new("b1").rod(1.0, 1.0).position(0.3, -0.2, 0.4));
        let b2 = b.add_body(Body::new("b2").rod(2.0, 0.7).position(1.1, 0.5, -0.9));
        let b3 = b.add_body(Body::new("b3").rod(0.5, 0.4).position(-0.6, 1.3, 2.1));
        let b4 = b.add_body(Body::new("b4").rod(0.8, 0.9).position(0.2, 2.0, -0.3));
        b.add_joint(Joint::revolute(
            "r",
            BodyRef::Ground,
            [0.1, 0.2],
            b1,
            [-0.5, 0.1],
        ));
        b.add_joint(Joint::distance("d", b1, [0.5, 0.0], b2, [-0.3, 0.2], 0.8));
        b.add_joint(Joint::prismatic(
            "p",
            b2,
            [0.1, 0.0],
            b3,
            [0.0, 0.1],
            [1.0, 0.5],
            0.2,
        ));
        b.add_joint(Joint::weld("w", b3, [0.2, 0.0], b4, [-0.4, 0.1], 0.3));
        b.add_joint(Joint::absolute("a", b4, [0.3, 0.0], Coordinate::Y, 1.0));
        b.add_joint(Joint::angle_driver(
            "drv",
            BodyRef::Ground,
            b2,
            TimeFunction::linear(0.1, 2.0),
        ));
        b.build().unwrap()
    }

    #[test]
    fn matches_finite_differences_of_phi_q_v() {
        let systems = [
            all_joint_kinds(),
            models::slider_crank().unwrap(),
            models::four_bar().unwrap(),
            models::manipulator().unwrap(),
            // more bodies than phi_and_phi_dot's stack of frames
            models::n_link_chain(20).unwrap(),
        ];
        for sys in &systems {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let q: Vec<f64> = (0..n)
                .map(|i| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64)
                .collect();
            let v: Vec<f64> = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
            let mut jq = DMatrix::zeros(m, n);
            let mut d = DMatrix::zeros(m, n);
            sys.phi_q_dot_jacobian(&q, &v, &mut jq, &mut d);
            let mut jref = DMatrix::zeros(m, n);
            sys.phi_q(&q, &mut jref);
            assert!((&jq - &jref).amax() < 1e-15);
            let (mut p1, mut p2, mut d1, mut d2) =
                (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            sys.phi(&q, 0.7, &mut p1);
            sys.phi_dot(&q, &v, 0.7, &mut d1);
            sys.phi_and_phi_dot(&q, &v, 0.7, &mut p2, &mut d2);
            for r in 0..m {
                assert!((p1[r] - p2[r]).abs() < 1e-15);
                assert!((d1[r] - d2[r]).abs() < 1e-13);
            }
            let eps = 1e-6;
            let mut jp = DMatrix::zeros(m, n);
            let mut jm = DMatrix::zeros(m, n);
            let vv = nalgebra::DVector::from_column_slice(&v);
            for c in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[c] += eps;
                qm[c] -= eps;
                sys.phi_q(&qp, &mut jp);
                sys.phi_q(&qm, &mut jm);
                let fd = (&jp * &vv - &jm * &vv) / (2.0 * eps);
                for r in 0..m {
                    assert!(
                        (fd[r] - d[(r, c)]).abs() < 1e-8 * (1.0 + d[(r, c)].abs()),
                        "row {r} col {c}: fd {} exact {}",
                        fd[r],
                        d[(r, c)]
                    );
                }
            }
        }
    }

    /// The angle cache gives phi and phi_dot to a few ulps of the exact evaluation along a
    /// Newton-like sequence of nearby configurations (rotations, large jumps, invalidation).
    #[test]
    fn angle_cache_matches_exact_evaluation() {
        for sys in [all_joint_kinds(), models::manipulator().unwrap()] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let mut cache = crate::AngleCache::new(&sys);
            let mut q: Vec<f64> = (0..n).map(|i| 0.3 + 0.17 * i as f64).collect();
            // a wound-up angle
            q[2] += 300.0;
            let v: Vec<f64> = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
            let (mut p1, mut p2, mut d1, mut d2) =
                (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            let mut worst = 0.0f64;
            for k in 0..40 {
                // shrinking Newton-like increments, a jump every 13 evaluations
                let step = if k % 13 == 12 {
                    0.1
                } else {
                    1e-4 / (1 + k % 13) as f64
                };
                for (i, qi) in q.iter_mut().enumerate() {
                    *qi += step * ((i + k) as f64 * 0.7).sin();
                }
                if k == 30 {
                    cache.invalidate();
                }
                sys.phi_and_phi_dot(&q, &v, 0.3, &mut p1, &mut d1);
                sys.phi_and_phi_dot_cached(&q, &v, 0.3, &mut p2, &mut d2, &mut cache);
                for r in 0..m {
                    worst = worst.max((p1[r] - p2[r]).abs()).max((d1[r] - d2[r]).abs());
                }
            }
            println!("cached vs exact: {worst:e}");
            assert!(worst < 1e-13, "cached vs exact: {worst:e}");
        }
    }
}

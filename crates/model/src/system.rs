//! The assembled multibody system: its data, sizes, names and handles. Evaluation lives in
//! `constraints.rs` (constraints and derivatives), `dynamics.rs` (energies and forces) and
//! `kinematics.rs` (points); the builder and validation in `builder.rs`.

use crate::body::{Body, BodyHandle};
use crate::error::ModelError;
use crate::forces::Force;
use crate::init::RedundantEquation;
use crate::jet::{DirJet, Frame, HessJet, NV};
use crate::joints::Joint;
use nalgebra::{DMatrix, DVector};

/// Handle of a joint inside a [`System`], given by [`crate::SystemBuilder::add_joint`],
/// [`System::joint_handle`] or [`System::joint_handles`] (opaque, like [`BodyHandle`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointHandle(pub(crate) usize);

impl JointHandle {
    /// The joint's position in [`System::joints`] (insertion order).
    pub fn index(self) -> usize {
        self.0
    }
}

/// Handle of a force element inside a [`System`], given by [`crate::SystemBuilder::add_force`],
/// [`System::force_handle`] or [`System::force_handles`] (opaque, like [`BodyHandle`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ForceHandle(pub(crate) usize);

impl ForceHandle {
    /// The element's position in [`System::forces`] (insertion order).
    pub fn index(self) -> usize {
        self.0
    }
}

/// The bodies an element attaches, as body indices (`None`: ground): the local coordinates of
/// an element are side `a`'s three followed by side `b`'s.
#[derive(Clone, Copy, Debug)]
pub struct Attach {
    /// Body index of side `a` (local slots 0..3), `None` for ground.
    pub a: Option<usize>,
    /// Body index of side `b` (local slots 3..6), `None` for ground.
    pub b: Option<usize>,
}

impl Attach {
    /// `out += h` in the rows and columns of the element's bodies (`h` is the element's local
    /// `6 x 6` block, side `a`'s coordinates then side `b`'s; ground rows and columns dropped;
    /// `out` is `n x n`).
    pub fn scatter_hess(&self, h: &[[f64; NV]; NV], out: &mut DMatrix<f64>) {
        let cols = |l: usize| -> Option<usize> {
            if l < 3 {
                self.a.map(|i| 3 * i + l)
            } else {
                self.b.map(|i| 3 * i + l - 3)
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

    /// `out[row, .] += g` in the columns of the element's bodies (`g` a local row; `out` is
    /// `m x n`).
    ///
    /// # Panics
    ///
    /// If `row` or a body's columns lie outside `out`.
    pub fn scatter_row(&self, row: usize, g: &[f64; NV], out: &mut DMatrix<f64>) {
        // column-major storage: entry (row, c) at row + nrows c (the slice index is checked;
        // a row outside the matrix would land in another column, hence the row check)
        let nr = out.nrows();
        assert!(row < nr, "row {row} outside a matrix of {nr} rows");
        let s = out.as_mut_slice();
        if let Some(i) = self.a {
            for l in 0..3 {
                s[row + nr * (3 * i + l)] += g[l];
            }
        }
        if let Some(i) = self.b {
            for l in 0..3 {
                s[row + nr * (3 * i + l)] += g[3 + l];
            }
        }
    }
}

/// A joint as [`System::joint_elements`] hands it out.
#[derive(Clone, Copy, Debug)]
pub struct JointElement<'a> {
    /// The joint (evaluate it with [`Joint::eval`]).
    pub joint: &'a Joint,
    /// The bodies it attaches.
    pub attach: Attach,
    /// Its first equation row (it has [`Joint::n_equations`] rows).
    pub row: usize,
}

/// A validated multibody system in absolute coordinates: `(x_i, y_i, theta_i)` per planar body,
/// then the centre of mass and three unit directors (12 coordinates) per spatial body and the
/// position (3) per spatial point mass (docs/spatial.md).
///
/// All evaluation methods take slices of length [`System::n_coords`] (`q`, `v`) or
/// [`System::n_constraints`] (`lambda`) and write into caller-provided buffers, so hot loops
/// allocate nothing.
#[derive(Clone, Debug)]
pub struct System {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) forces: Vec<Force>,
    pub(crate) sensors: Vec<crate::sensors::Sensor>,
    pub(crate) gravity: [f64; 2],
    pub(crate) joint_attach: Vec<Attach>,
    pub(crate) force_attach: Vec<Attach>,
    pub(crate) row_offset: Vec<usize>,
    pub(crate) n: usize,
    pub(crate) m: usize,
    pub(crate) mass: DVector<f64>,
    pub(crate) inv_mass: DVector<f64>,
    pub(crate) eq_joint: Vec<usize>,
    /// The generalized gravity forces `(m_i g_x, m_i g_y, 0)` per body: constant, evaluated
    /// once at build instead of at every force evaluation.
    pub(crate) gravity_forces: Vec<f64>,
    /// The equations dependent on earlier ones at build time and near it on the manifold.
    pub(crate) redundant: Vec<RedundantEquation>,
    /// Further equations dependent at the build configuration only (a singular initial
    /// configuration, `generic_rank`).
    pub(crate) singular_start: Vec<RedundantEquation>,
    /// Initial joint coordinates (joint index, values) for assembly.
    pub(crate) joint_initials: Vec<(usize, crate::JointInitial)>,
    /// The spatial bodies and joints (after the planar coordinates and rows).
    pub(crate) spatial: crate::spatial::system::SpatialPart,
    /// A planar model whose joints are all revolute: each joint's bodies, points and first
    /// row, for the residual loop of [`System::phi_and_phi_dot_cached`] (empty otherwise).
    pub(crate) revolute_rows: Vec<crate::constraints::RevoluteRow>,
}

impl System {
    /// Number of coordinates `n = 3 * bodies`.
    pub fn n_coords(&self) -> usize {
        self.n
    }
    /// Number of scalar constraint equations `m`.
    pub fn n_constraints(&self) -> usize {
        self.m
    }
    /// Degrees of freedom `n - rank(Phi_q) = n - m + ` [`System::n_redundant`] (the rank near
    /// the build configuration on the manifold: a singular initial configuration, where the
    /// rank is lower, does not add a degree of freedom).
    pub fn dof(&self) -> usize {
        (self.n + self.redundant.len()).saturating_sub(self.m)
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
    /// Whether the model has spatial bodies (docs/spatial.md): their coordinates follow the
    /// planar bodies' and their rows (internal constraints, then spatial joints) the planar
    /// joints'.
    pub fn has_spatial(&self) -> bool {
        !self.spatial.is_empty()
    }
    /// The spatial bodies, in handle order; body `k`'s natural coordinates are
    /// `q[s + 12 k..s + 12 k + 12]` with `s` = [`System::spatial_offset`].
    pub fn spatial_bodies(&self) -> &[crate::spatial::SpatialBody] {
        &self.spatial.bodies
    }
    /// The spatial point masses, in handle order; point mass `p`'s position is
    /// `q[s + 3 p..s + 3 p + 3]` with `s` = [`System::spatial_point_mass_offset`].
    pub fn spatial_point_masses(&self) -> &[crate::spatial::SpatialPointMass] {
        &self.spatial.points
    }
    /// The first coordinate of the spatial point masses: after the planar bodies' and the
    /// spatial bodies' coordinates.
    pub fn spatial_point_mass_offset(&self) -> usize {
        self.spatial.point_offset()
    }
    /// The spatial force elements (points and load axes in the bodies' frames, as given).
    pub fn spatial_forces(&self) -> &[crate::spatial::SpatialForce] {
        &self.spatial.forces
    }
    /// Every spatial force element with its local columns and its potential over a generic
    /// scalar, in the order of [`System::spatial_forces`]: the hook of the potential's
    /// derivative passes on spatial bodies.
    pub fn spatial_force_elements(
        &self,
    ) -> impl ExactSizeIterator<Item = crate::spatial::SpatialForceElement<'_>> + '_ {
        (0..self.spatial.forces.len())
            .map(|k| crate::spatial::SpatialForceElement::new(&self.spatial, k))
    }
    /// The spatial joints (markers in the bodies' frames, as given).
    pub fn spatial_joints(&self) -> &[crate::spatial::SpatialJointEntry] {
        &self.spatial.joints
    }
    /// The rows of the spatial bodies' internal constraints (six per body, contiguous, after
    /// the planar joints' rows and before the spatial joints').
    pub fn spatial_internal_rows(&self) -> std::ops::Range<usize> {
        self.spatial.r0..self.spatial.r0 + 6 * self.spatial.bodies.len()
    }
    /// The first coordinate of the spatial bodies (`3` times the number of planar bodies).
    pub fn spatial_offset(&self) -> usize {
        self.spatial.q0
    }
    /// The gravity vector of the spatial bodies.
    pub fn spatial_gravity(&self) -> [f64; 3] {
        self.spatial.gravity
    }
    /// The first spatial body whose mass matrix is singular (a second moment `E_i = 0`: a thin
    /// disc or plate, the symmetric top), if any: solvers that divide by the mass matrix's
    /// diagonal refuse such a model by this name.
    pub fn singular_mass_body(&self) -> Option<&str> {
        self.spatial
            .bodies
            .iter()
            .find(|b| b.inertia.has_singular_mass_matrix())
            .map(|b| b.name.as_str())
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
    /// The handle of the force element called `name`.
    pub fn force_handle(&self, name: &str) -> Option<ForceHandle> {
        self.forces
            .iter()
            .position(|f| f.name == name)
            .map(ForceHandle)
    }
    /// Every joint with its attachment and its first equation row, in the order of
    /// [`System::joints`]: with [`Joint::eval`] (generic over the scalar) the one hook through
    /// which derivative passes outside this crate (the symplectic preadjustment's higher
    /// derivatives) evaluate the constraints with their own jet types.
    pub fn joint_elements(&self) -> impl ExactSizeIterator<Item = JointElement<'_>> + '_ {
        self.joints
            .iter()
            .zip(&self.joint_attach)
            .zip(&self.row_offset)
            .map(|((joint, &attach), &row)| JointElement { joint, attach, row })
    }
    /// The sensors, in the order they were added (see [`crate::Sensor`]).
    pub fn sensors(&self) -> &[crate::sensors::Sensor] {
        &self.sensors
    }
    /// Every force element with its attachment, in the order of [`System::forces`]: with
    /// [`Force::potential`] the hook of the potential's derivative passes (gravity, linear in
    /// `q`, is not an element).
    pub fn force_elements(&self) -> impl ExactSizeIterator<Item = (&Force, Attach)> + '_ {
        self.forces.iter().zip(self.force_attach.iter().copied())
    }
    /// The handles of every body, in the order of [`System::bodies`].
    pub fn body_handles(&self) -> impl ExactSizeIterator<Item = BodyHandle> {
        (0..self.bodies.len()).map(BodyHandle)
    }
    /// The handles of every joint, in the order of [`System::joints`].
    pub fn joint_handles(&self) -> impl ExactSizeIterator<Item = JointHandle> {
        (0..self.joints.len()).map(JointHandle)
    }
    /// The handles of every force element, in the order of [`System::forces`].
    pub fn force_handles(&self) -> impl ExactSizeIterator<Item = ForceHandle> {
        (0..self.forces.len()).map(ForceHandle)
    }
    /// Names of the coordinates: `body.x`, `body.y`, `body.theta`.
    pub fn coordinate_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .bodies
            .iter()
            .flat_map(|b| ["x", "y", "theta"].map(|c| format!("{}.{}", b.name, c)))
            .collect();
        self.spatial.coordinate_names(&mut names);
        names
    }
    /// Names of the constraint equations: `joint.label`.
    pub fn equation_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .joints
            .iter()
            .flat_map(|j| {
                j.equation_labels()
                    .iter()
                    .map(move |l| format!("{}.{}", j.name, l))
            })
            .collect();
        let r0 = names.len();
        names.extend((r0..self.m).map(|r| self.equation_name(r)));
        names
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
            None => self
                .spatial
                .equation_name(row)
                .unwrap_or_else(|| format!("equation #{row}")),
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
        self.joints.iter().any(|j| j.is_rheonomic()) || self.spatial.is_rheonomic()
    }

    /// Whether `Phi_q` depends on time (`Phi_qt != 0`): only with a spatial angle driver
    /// (docs/spatial.md, "Drivers"); every other driver subtracts a function of time.
    pub fn jacobian_depends_on_time(&self) -> bool {
        self.spatial.has_angle_driver()
    }

    /// For every constraint row, whether its Hessian `Hess Phi_r` is constant (the same at every
    /// `q` and `t`): the rows of spatial joints and internal constraints, which are quadratic
    /// in the coordinates (docs/spatial.md), except an angle driver's, which turns with
    /// `theta(t)`. Planar rows are not (rotations of angles). A solver may compute such a
    /// row's Hessian once.
    pub fn constant_hessian_rows(&self) -> Vec<bool> {
        let mut out = vec![false; self.n_constraints()];
        self.spatial.mark_constant_hessian_rows(&mut out);
        out
    }
    /// Whether all applied forces derive from the potential [`System::potential`] (no damping, no
    /// time-dependent loads).
    pub fn is_conservative(&self) -> bool {
        !self.forces.iter().any(|f| f.is_nonconservative()) && self.spatial.forces_conservative()
    }
    /// Whether the model has force elements (planar or spatial; gravity is not one).
    pub fn has_force_elements(&self) -> bool {
        !self.forces.is_empty() || self.spatial.has_forces()
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

    /// The initial guess: the bodies' stored state `(q, v)`, with the bodies placed from the
    /// initial joint coordinates where the model gives some ([`System::joint_initials`]; see
    /// [`crate::JointInitial`]).
    pub fn initial_guess(&self) -> (DVector<f64>, DVector<f64>) {
        let (mut q, mut v) = self.stored_state();
        self.assemble(&mut q, &mut v);
        (DVector::from_vec(q), DVector::from_vec(v))
    }

    /// The bodies' stored positions and velocities.
    pub(crate) fn stored_state(&self) -> (Vec<f64>, Vec<f64>) {
        let mut q: Vec<f64> = self.bodies.iter().flat_map(|b| b.position).collect();
        let mut v: Vec<f64> = self.bodies.iter().flat_map(|b| b.velocity).collect();
        q.extend(&self.spatial.q_init);
        v.extend(&self.spatial.v_init);
        (q, v)
    }

    /// The input masks of the initial state (length [`System::n_coords`] each): which
    /// coordinates and velocities of [`System::initial_guess`] the consistent-state solve keeps
    /// (see [`crate::Inputs`]).
    pub fn initial_inputs(&self) -> (Vec<bool>, Vec<bool>) {
        let mut q: Vec<bool> = self.bodies.iter().flat_map(|b| b.inputs.position).collect();
        let mut v: Vec<bool> = self.bodies.iter().flat_map(|b| b.inputs.velocity).collect();
        // spatial bodies have no inputs (yet)
        q.resize(self.n, false);
        v.resize(self.n, false);
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
    pub(crate) fn loc_f64(q: &[f64], i: Option<usize>) -> [f64; 3] {
        match i {
            Some(i) => [q[3 * i], q[3 * i + 1], q[3 * i + 2]],
            None => [0.0; 3],
        }
    }
    #[inline(always)]
    pub(crate) fn frm_f64(q: &[f64], i: Option<usize>) -> Frame<f64> {
        match i {
            Some(i) => Frame::new([q[3 * i], q[3 * i + 1], q[3 * i + 2]]),
            None => Frame::fixed(),
        }
    }
    #[inline(always)]
    pub(crate) fn loc_dir(
        q: &[f64],
        v: Option<&[f64]>,
        i: Option<usize>,
        slot: usize,
    ) -> Frame<DirJet> {
        match i {
            Some(i) => Frame::new(std::array::from_fn(|k| {
                DirJet::var(slot + k, q[3 * i + k], v.map_or(0.0, |v| v[3 * i + k]))
            })),
            None => Frame::fixed(),
        }
    }
    #[inline(always)]
    pub(crate) fn loc_hess(q: &[f64], i: Option<usize>, slot: usize) -> Frame<HessJet> {
        match i {
            Some(i) => Frame::new(std::array::from_fn(|k| {
                HessJet::var(slot + k, q[3 * i + k])
            })),
            None => Frame::fixed(),
        }
    }
    // ---------------------------------------------------------------- constraints
}

//! Spatial joints in natural coordinates: each kind's equations written once over a generic
//! scalar, one file per kind, as functions of the two bodies' frames.
//!
//! A joint holds a [`Marker`] on each body: a point and three axes (the columns `x`, `y`, `z` of
//! a rotation) in the body's principal frame (ground: global axes). In natural coordinates a
//! marker's point is `P = x + p_1 d_1 + p_2 d_2 + p_3 d_3` and its axes are
//! `X = sum_i A_i1 d_i` (likewise `Y`, `Z`): linear in the body's coordinates. Every equation
//! below is a difference of points, or a dot product of two such linear expressions, so every
//! joint is a quadratic polynomial in `q`: its Jacobian is linear and its Hessians constant.
//! At assembly the two markers coincide (points and axes); each kind then frees what its name
//! says:
//!
//! | kind | equations | frees |
//! |---|---|---|
//! | [`SpatialJointKind::Spherical`] | `P_a - P_b` (3) | every rotation |
//! | [`SpatialJointKind::Revolute`] | `P_a - P_b` (3), `Z_b . X_a`, `Z_b . Y_a` | rotation about `Z` |
//! | [`SpatialJointKind::Universal`] | `P_a - P_b` (3), `X_a . Y_b` | rotations about `X_a` and `Y_b` |
//! | [`SpatialJointKind::Cylindrical`] | `Z_b . X_a`, `Z_b . Y_a`, `(P_b - P_a) . X_a`, `(P_b - P_a) . Y_a` | rotation about and slide along `Z` |
//! | [`SpatialJointKind::Prismatic`] | the cylindrical four, `X_a . Y_b` | slide along `Z` |
//! | [`SpatialJointKind::Planar`] | `Z_b . X_a`, `Z_b . Y_a`, `(P_b - P_a) . Z_a` | slides in `X`-`Y`, rotation about `Z` |
//! | [`SpatialJointKind::Weld`] | `P_a - P_b` (3), `X_a . Y_b`, `X_a . Z_b`, `Y_a . Z_b` | nothing |
//! | [`SpatialJointKind::Distance`] | `(|P_b - P_a|^2 - L^2) / (2 L)` | everything but the distance |
//! | [`SpatialJointKind::SlideDriver`] | `(P_b - P_a) . Z_a - s(t)` | everything but the slide along `Z_a` |
//! | [`SpatialJointKind::DistanceDriver`] | `1/2 (|P_b - P_a|^2 - L(t)^2)` | everything but the distance |
//! | [`SpatialJointKind::AngleDriver`] | `cos theta(t) X_b . Y_a - sin theta(t) X_b . X_a` | everything but the turn of `X_b` about `Z_a` |
//!
//! The drivers' motions (`s(t)`, `L(t)`, `theta(t)`) are functions of time the system holds
//! beside the joint ([`crate::SystemBuilder::add_spatial_driver`]). The slide and distance
//! drivers subtract their motion, so their Jacobians do not depend on time; the angle driver's
//! equation is `sin(phi - theta)` for the turn `phi` of `X_b` (with the `z` axes aligned by a
//! revolute or cylindrical joint beside it), whose Jacobian turns with `theta(t)`
//! (`Phi_qt != 0`; docs/spatial.md, "Drivers").
//!
//! The orientation equations are the linearly independent ones at assembly: a small relative
//! rotation `dtheta` of `b` changes `X_a . Y_b` by `-dtheta . Z`, `X_a . Z_b` by `dtheta . Y`,
//! `Y_a . Z_b` by `-dtheta . X`, `Z_b . X_a` by `-dtheta . Y` and `Z_b . Y_a` by `dtheta . X`.

mod angle_driver;
mod cylindrical;
mod distance;
mod planar;
mod prismatic;
mod revolute;
mod slide_driver;
mod spherical;
mod universal;
mod weld;

#[cfg(test)]
mod tests;

use mbd_jet::{DirJetN, Scalar};
use nalgebra::Matrix3;
use thiserror::Error;

/// A body's natural coordinates as an element sees them: the centre of mass `x` and the
/// directors `d_1, d_2, d_3` (ground: the origin and the global axes).
#[derive(Clone, Copy, Debug)]
pub struct SpatialFrame<T> {
    /// Centre of mass.
    pub x: [T; 3],
    /// Directors (principal axes, global components).
    pub d: [[T; 3]; 3],
}

impl<T: Scalar> SpatialFrame<T> {
    /// The frame of a body with coordinates `q = (x, d_1, d_2, d_3)`.
    pub fn new(q: &[T; 12]) -> Self {
        SpatialFrame {
            x: [q[0], q[1], q[2]],
            d: std::array::from_fn(|i| [q[3 + 3 * i], q[4 + 3 * i], q[5 + 3 * i]]),
        }
    }
    /// The ground's frame: the origin and the global axes (constants).
    pub fn ground() -> Self {
        SpatialFrame {
            x: [T::cst(0.0); 3],
            d: std::array::from_fn(|i| {
                std::array::from_fn(|c| T::cst(if i == c { 1.0 } else { 0.0 }))
            }),
        }
    }
    /// The global direction of the body-fixed vector `u` (principal-frame components):
    /// `u_1 d_1 + u_2 d_2 + u_3 d_3`.
    pub fn direction(&self, u: [f64; 3]) -> [T; 3] {
        std::array::from_fn(|c| self.d[0][c] * u[0] + self.d[1][c] * u[1] + self.d[2][c] * u[2])
    }
    /// The global position of the body point `p` (principal frame, from the centre of mass).
    pub fn point(&self, p: [f64; 3]) -> [T; 3] {
        let u = self.direction(p);
        std::array::from_fn(|c| self.x[c] + u[c])
    }
}

/// `a . b`.
pub(crate) fn dot3<T: Scalar>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a - b`.
pub(crate) fn sub3<T: Scalar>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// A joint's frame on one body: a point and axes in the body's principal frame (ground:
/// global).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    /// The point, from the centre of mass (m).
    pub point: [f64; 3],
    /// The axes: the columns `x`, `y`, `z` of a rotation.
    pub axes: Matrix3<f64>,
}

impl Marker {
    /// A marker at `point` with the body's own axes.
    pub fn at(point: [f64; 3]) -> Self {
        Marker {
            point,
            axes: Matrix3::identity(),
        }
    }
    /// A marker at `point` with axes `axes` (a rotation; checked by [`SpatialJoint::new`]).
    pub fn with_axes(point: [f64; 3], axes: Matrix3<f64>) -> Self {
        Marker { point, axes }
    }
    /// The marker's point and, if `axes`, its three axes on the moving `frame` (else zeros:
    /// the ball and distance joints use the point alone).
    fn on<T: Scalar>(&self, frame: &SpatialFrame<T>, axes: bool) -> MarkerAt<T> {
        let axis = |k: usize| {
            if axes {
                frame.direction([self.axes[(0, k)], self.axes[(1, k)], self.axes[(2, k)]])
            } else {
                [T::cst(0.0); 3]
            }
        };
        MarkerAt {
            p: frame.point(self.point),
            x: axis(0),
            y: axis(1),
            z: axis(2),
        }
    }
}

impl Marker {
    /// [`Marker::on`] with the jets of an element's 24 local variables, in closed form (the
    /// point and axes are linear in the side's coordinates, so the generic jet arithmetic is
    /// not needed), written into `out`: side `side` (0 or 1) with local coordinates and
    /// velocities `qv`, or ground (`None`). Without `axes` only the point is written (the
    /// joints that read no axis take no time over them).
    pub(crate) fn on_jets_into(
        &self,
        side: usize,
        qv: Option<(&[f64], &[f64])>,
        axes: bool,
        out: &mut MarkerAt<DirJetN<24>>,
    ) {
        // the global vector `c0 x + sum_i u_i d_i` as three jets
        let linear = |c0: f64, u: [f64; 3], out: &mut [DirJetN<24>; 3]| {
            for (c, jet) in out.iter_mut().enumerate() {
                match qv {
                    // ground: the origin and the global axes
                    None => *jet = DirJetN::cst(u[c]),
                    Some((q, v)) => {
                        let o = 12 * side;
                        jet.g = [0.0; 24];
                        jet.g[o + c] = c0;
                        let (mut val, mut d1) = (c0 * q[c], c0 * v[c]);
                        for i in 0..3 {
                            jet.g[o + 3 + 3 * i + c] = u[i];
                            val += u[i] * q[3 + 3 * i + c];
                            d1 += u[i] * v[3 + 3 * i + c];
                        }
                        (jet.v, jet.d1, jet.d2) = (val, d1, 0.0);
                    }
                }
            }
        };
        linear(1.0, self.point, &mut out.p);
        if axes {
            for (k, axis) in [&mut out.x, &mut out.y, &mut out.z].into_iter().enumerate() {
                linear(
                    0.0,
                    [self.axes[(0, k)], self.axes[(1, k)], self.axes[(2, k)]],
                    axis,
                );
            }
        }
    }
}

/// A marker's point and axes in global components.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MarkerAt<T> {
    pub(crate) p: [T; 3],
    pub(crate) x: [T; 3],
    pub(crate) y: [T; 3],
    pub(crate) z: [T; 3],
}

impl MarkerAt<DirJetN<24>> {
    /// Every component the zero constant (scratch for [`SpatialJoint::eval_jets_with`]).
    pub(crate) const ZERO_JETS: Self = {
        let z = DirJetN {
            v: 0.0,
            g: [0.0; 24],
            d1: 0.0,
            d2: 0.0,
        };
        MarkerAt {
            p: [z; 3],
            x: [z; 3],
            y: [z; 3],
            z: [z; 3],
        }
    };
}

/// The kinds of spatial joint (see the module documentation for their equations).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum SpatialJointKind {
    /// Ball joint: the points coincide (3 equations).
    Spherical,
    /// Hinge about the markers' `z` axis (5 equations).
    Revolute,
    /// Cardan joint: rotations about `x` of `a` and `y` of `b` (4 equations).
    Universal,
    /// Rotation about and slide along the markers' `z` axis (4 equations).
    Cylindrical,
    /// Slide along the markers' `z` axis (5 equations).
    Prismatic,
    /// Plane contact: slides in the markers' `x`-`y` plane and rotation about `z` (3 equations).
    Planar,
    /// Rigid connection (6 equations).
    Weld,
    /// Massless rod of length `length` between the points (1 equation).
    Distance {
        /// The distance (m), positive.
        length: f64,
    },
    /// Driver: the second point's slide along the first marker's `z` axis follows a function
    /// of time (1 equation; a linear actuator along a guide).
    SlideDriver,
    /// Driver: the points' distance follows a function of time (1 equation; a linear
    /// actuator between two pins).
    DistanceDriver,
    /// Driver: the second marker's `x` axis turns about the first marker's `z` axis, from its
    /// `x` axis towards its `y` axis, by a function of time (1 equation; a motor on a hinge,
    /// used beside a revolute or cylindrical joint that aligns the `z` axes).
    AngleDriver,
}

/// Why a spatial joint's parameters are invalid (the field and the reason).
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{field}: {reason}")]
pub struct SpatialJointError {
    /// The parameter at fault (`marker_a.point`, `marker_b.axes`, `length`).
    pub field: &'static str,
    /// What is wrong with it.
    pub reason: String,
}

/// A spatial joint: its kind and its markers on bodies `a` and `b`.
///
/// ```
/// use mbd_model::spatial::{natural_coordinates, Marker, SpatialFrame, SpatialJoint,
///     SpatialJointKind};
/// use nalgebra::{Matrix3, Vector3};
/// // a hinge between the ground's origin and the body point (0, 0, 1), about z
/// let hinge = SpatialJoint::new(
///     SpatialJointKind::Revolute,
///     Marker::at([0.0; 3]),
///     Marker::at([0.0, 0.0, 1.0]),
/// )?;
/// assert_eq!(hinge.n_equations(), 5);
/// // the body with its centre of mass at (0, 0, -1), turned about z: the joint holds
/// let turn = Matrix3::new(0.6, -0.8, 0.0, 0.8, 0.6, 0.0, 0.0, 0.0, 1.0);
/// let q = natural_coordinates(Vector3::new(0.0, 0.0, -1.0), &turn);
/// let mut out = [0.0; 6];
/// hinge.eval(&SpatialFrame::ground(), &SpatialFrame::new(&q), &mut out);
/// assert!(out.iter().all(|e| e.abs() < 1e-15));
/// # Ok::<(), mbd_model::spatial::SpatialJointError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialJoint {
    kind: SpatialJointKind,
    a: Marker,
    b: Marker,
}

impl SpatialJoint {
    /// A joint of `kind` between marker `a` (on the first body) and `b` (on the second).
    /// Errors name the field: a point or an axis that is not finite, axes that are not a
    /// rotation (orthonormal to 1e-9, right-handed), a distance that is not positive.
    pub fn new(kind: SpatialJointKind, a: Marker, b: Marker) -> Result<Self, SpatialJointError> {
        for (m, point, axes) in [
            (&a, "marker_a.point", "marker_a.axes"),
            (&b, "marker_b.point", "marker_b.axes"),
        ] {
            if m.point.iter().any(|x| !x.is_finite()) {
                return Err(SpatialJointError {
                    field: point,
                    reason: format!("{:?} must be finite", m.point),
                });
            }
            let deviation = (m.axes.transpose() * m.axes - Matrix3::identity()).amax();
            if !(deviation <= 1e-9 && m.axes.determinant() > 0.0) {
                return Err(SpatialJointError {
                    field: axes,
                    reason: format!(
                        "the columns must be a rotation (orthonormal and right-handed): \
                         |A^T A - I| = {deviation:e}, det A = {}",
                        m.axes.determinant()
                    ),
                });
            }
        }
        if let SpatialJointKind::Distance { length } = kind {
            if !(length.is_finite() && length > 0.0) {
                return Err(SpatialJointError {
                    field: "length",
                    reason: format!("{length} must be positive and finite"),
                });
            }
        }
        Ok(SpatialJoint { kind, a, b })
    }

    /// The kind as the model file's `type` tag (`spherical`, ..., `distance_driver`).
    pub fn type_name(&self) -> &'static str {
        match self.kind {
            SpatialJointKind::Spherical => "spherical",
            SpatialJointKind::Revolute => "revolute",
            SpatialJointKind::Universal => "universal",
            SpatialJointKind::Cylindrical => "cylindrical",
            SpatialJointKind::Prismatic => "prismatic",
            SpatialJointKind::Planar => "planar",
            SpatialJointKind::Weld => "weld",
            SpatialJointKind::Distance { .. } => "distance",
            SpatialJointKind::SlideDriver => "slide_driver",
            SpatialJointKind::DistanceDriver => "distance_driver",
            SpatialJointKind::AngleDriver => "angle_driver",
        }
    }

    /// Whether the joint is a driver (its motion a function of time the system holds).
    pub fn is_driver(&self) -> bool {
        matches!(
            self.kind,
            SpatialJointKind::SlideDriver
                | SpatialJointKind::DistanceDriver
                | SpatialJointKind::AngleDriver
        )
    }

    /// The kind.
    pub fn kind(&self) -> SpatialJointKind {
        self.kind
    }
    /// The markers on `a` and `b`.
    pub fn markers(&self) -> (&Marker, &Marker) {
        (&self.a, &self.b)
    }

    /// The number of equations.
    pub fn n_equations(&self) -> usize {
        match self.kind {
            SpatialJointKind::Spherical | SpatialJointKind::Planar => 3,
            SpatialJointKind::Universal | SpatialJointKind::Cylindrical => 4,
            SpatialJointKind::Revolute | SpatialJointKind::Prismatic => 5,
            SpatialJointKind::Weld => 6,
            SpatialJointKind::Distance { .. }
            | SpatialJointKind::SlideDriver
            | SpatialJointKind::DistanceDriver
            | SpatialJointKind::AngleDriver => 1,
        }
    }

    /// The physical dimension of equation `k` as a power of length: 0 for the orientation
    /// equations (dot products of unit axes), 1 for positions (the distance joint's
    /// `(|r|^2 - L^2) / (2 L)` among them), 2 for the distance driver's `1/2 (|r|^2 - L(t)^2)`.
    /// Scales tolerances on the equation.
    pub fn length_power(&self, k: usize) -> i32 {
        use SpatialJointKind::*;
        match self.kind {
            Spherical | Weld | Revolute | Universal => i32::from(k < 3),
            Cylindrical | Prismatic => i32::from((2..4).contains(&k)),
            Planar => i32::from(k == 2),
            AngleDriver => 0,
            SlideDriver => 1,
            Distance { .. } => 1,
            DistanceDriver => 2,
        }
    }

    /// The equations at the frames `fa`, `fb` into `out[..n_equations]` (the rest untouched),
    /// a driver's without its motion: an angle driver writes its two components `X_b . Y_a`
    /// and `X_b . X_a` into `out[0]` and `out[1]` (its equation at `theta = 0` is `out[0]`; the
    /// system combines them at `theta(t)`).
    pub fn eval<T: Scalar>(&self, fa: &SpatialFrame<T>, fb: &SpatialFrame<T>, out: &mut [T; 6]) {
        let axes = self.uses_axes();
        let (ma, mb) = (self.a.on(fa, axes), self.b.on(fb, axes));
        self.eval_at(&ma, &mb, out);
    }

    /// Whether the equations use the axes of the marker on side `side` (0: `a`, 1: `b`):
    /// never for the ball, distance and distance-driver joints, only on `a` for the slide
    /// driver (`(P_b - P_a) . Z_a`), on both sides for every other kind. A spatial point mass
    /// (a point without axes) takes a joint on the sides where this is `false`.
    pub fn needs_axes(&self, side: usize) -> bool {
        match self.kind {
            SpatialJointKind::SlideDriver => side == 0,
            _ => self.uses_axes(),
        }
    }

    /// Whether the equations use the markers' axes (all but the ball and distance joints).
    fn uses_axes(&self) -> bool {
        !matches!(
            self.kind,
            SpatialJointKind::Spherical
                | SpatialJointKind::Distance { .. }
                | SpatialJointKind::DistanceDriver
        )
    }

    /// [`SpatialJoint::eval`] with the jets of the two sides' 24 local variables, the markers
    /// built in closed form ([`Marker::on_jets`]); `a`, `b`: each side's local coordinates
    /// and velocities, `None` for ground.
    pub(crate) fn eval_jets(
        &self,
        a: Option<(&[f64], &[f64])>,
        b: Option<(&[f64], &[f64])>,
        out: &mut [DirJetN<24>; 6],
    ) {
        let mut markers = [MarkerAt::ZERO_JETS; 2];
        self.eval_jets_with(a, b, &mut markers, out);
    }

    /// [`SpatialJoint::eval_jets`] with the markers' jets in `markers` (scratch a caller that
    /// evaluates many joints keeps, so that they are not built anew for each): a joint that
    /// reads no axis writes only the points, and its equations read only those.
    pub(crate) fn eval_jets_with(
        &self,
        a: Option<(&[f64], &[f64])>,
        b: Option<(&[f64], &[f64])>,
        markers: &mut [MarkerAt<DirJetN<24>>; 2],
        out: &mut [DirJetN<24>; 6],
    ) {
        let axes = self.uses_axes();
        let [ma, mb] = markers;
        self.a.on_jets_into(0, a, axes, ma);
        self.b.on_jets_into(1, b, axes, mb);
        self.eval_at(ma, mb, out);
    }

    /// The equations at the markers `ma`, `mb` (global components).
    fn eval_at<T: Scalar>(&self, ma: &MarkerAt<T>, mb: &MarkerAt<T>, out: &mut [T; 6]) {
        match self.kind {
            SpatialJointKind::Spherical => spherical::eval(ma, mb, out),
            SpatialJointKind::Revolute => revolute::eval(ma, mb, out),
            SpatialJointKind::Universal => universal::eval(ma, mb, out),
            SpatialJointKind::Cylindrical => cylindrical::eval(ma, mb, out),
            SpatialJointKind::Prismatic => prismatic::eval(ma, mb, out),
            SpatialJointKind::Planar => planar::eval(ma, mb, out),
            SpatialJointKind::Weld => weld::eval(ma, mb, out),
            SpatialJointKind::Distance { length } => distance::eval(ma, mb, length, out),
            SpatialJointKind::SlideDriver => slide_driver::eval(ma, mb, out),
            // the system subtracts 1/2 L(t)^2
            SpatialJointKind::DistanceDriver => distance::eval_driver(ma, mb, out),
            SpatialJointKind::AngleDriver => angle_driver::eval(ma, mb, out),
        }
    }
}

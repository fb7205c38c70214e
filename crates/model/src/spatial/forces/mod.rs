//! Force elements on spatial bodies: spring-dampers between body points, and applied forces
//! and torques in global or body axes, one file per kind.
//!
//! Each element's potential is written once over a generic scalar on the two bodies' frames
//! ([`SpatialFrame`]), so the gradient and the stiffness come from the jets. The generalised
//! forces follow from virtual work in natural coordinates (docs/spatial.md, "Forces"):
//!
//! * a force `F` (global components) at the body point with principal-frame coordinates `p`
//!   does work `F . (dx + sum_i p_i dd_i)`, so its generalised force on `(x, d_1, d_2, d_3)`
//!   is `(F, p_1 F, p_2 F, p_3 F)`;
//! * a torque `tau` does work `tau . dtheta` on a rotation `dd_i = dtheta x d_i`; the
//!   generalised force `(0, 1/2 tau x d_1, 1/2 tau x d_2, 1/2 tau x d_3)` does the same work
//!   on every rigid motion, since `sum_i 1/2 (tau x d_i) . (dtheta x d_i)
//!   = 1/2 (3 tau . dtheta - sum_i (tau . d_i)(d_i . dtheta)) = tau . dtheta` for orthonormal
//!   directors (its component normal to the motions is taken up by the internal constraints'
//!   multipliers).

mod assemble;
mod element;
mod load;
mod spring_damper;

pub use element::{SpatialForceElement, SPATIAL_LOCAL_WIDTH};
pub use load::{Axes, SpatialLoad};
pub use spring_damper::SpatialSpringDamper;

use super::joints::SpatialFrame;
use super::SpatialBodyRef;
use crate::error::ModelError;
use crate::timefn::TimeFunction;
use mbd_jet::{DirJetN, Scalar};
use nalgebra::Matrix3;

/// The local width of a spatial element (two bodies' natural coordinates).
const SW: usize = super::system::SW;

/// The kinds of spatial force element.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SpatialForceKind {
    /// Linear spring-damper between a point of each body.
    SpringDamper(SpatialSpringDamper),
    /// A force at a body point.
    Force(SpatialLoad),
    /// A torque on a body.
    Torque(SpatialLoad),
}

/// A named force element on spatial bodies.
///
/// ```
/// use mbd_model::spatial::{Axes, SpatialBody, SpatialForce, SpatialInertia};
/// use mbd_model::{SystemBuilder, TimeFunction};
/// let mut b = SystemBuilder::new();
/// let body = b.add_spatial_body(SpatialBody::new("box", SpatialInertia::principal(2.0, [0.1, 0.2, 0.25])?));
/// let spin = [0.0, 0.0, 0.5].map(TimeFunction::constant);
/// b.add_spatial_force(SpatialForce::torque("motor", body, spin, Axes::Body));
/// let sys = b.build()?;
/// assert!(!sys.is_conservative());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialForce {
    /// Unique name (among all force elements).
    pub name: String,
    /// The first body (the loaded body of a force or torque).
    pub a: SpatialBodyRef,
    /// The second body (ground for a force or torque).
    pub b: SpatialBodyRef,
    /// Kind and parameters (points and load axes in the bodies' frames).
    pub kind: SpatialForceKind,
}

impl SpatialForce {
    /// A spring-damper between `point_a` on `a` and `point_b` on `b` (body frames; ground:
    /// global): force `k (l - rest_length) + c l'` along the line between the points.
    #[allow(clippy::too_many_arguments)]
    pub fn spring_damper(
        name: impl Into<String>,
        a: impl Into<SpatialBodyRef>,
        point_a: [f64; 3],
        b: impl Into<SpatialBodyRef>,
        point_b: [f64; 3],
        stiffness: f64,
        damping: f64,
        rest_length: f64,
    ) -> Self {
        SpatialForce {
            name: name.into(),
            a: a.into(),
            b: b.into(),
            kind: SpatialForceKind::SpringDamper(SpatialSpringDamper {
                point_a,
                point_b,
                stiffness,
                damping,
                rest_length,
            }),
        }
    }

    /// A force with components `components` (N, functions of time) in `frame`, applied at
    /// `point` (body frame, from the centre of mass) of `body`. A constant force in global
    /// axes is conservative (potential `-F . P`).
    #[allow(clippy::self_named_constructors)] // `SpatialForce::force` next to `::torque`
    pub fn force(
        name: impl Into<String>,
        body: impl Into<SpatialBodyRef>,
        point: [f64; 3],
        components: [TimeFunction; 3],
        frame: Axes,
    ) -> Self {
        SpatialForce {
            name: name.into(),
            a: body.into(),
            b: SpatialBodyRef::Ground,
            kind: SpatialForceKind::Force(SpatialLoad::new(point, components, frame)),
        }
    }

    /// A torque with components `components` (N m, functions of time) in `frame` on `body`.
    /// Torques are never conservative in 3D (rotations do not commute): they enter the
    /// generalised force and the energy balance's external work.
    pub fn torque(
        name: impl Into<String>,
        body: impl Into<SpatialBodyRef>,
        components: [TimeFunction; 3],
        frame: Axes,
    ) -> Self {
        SpatialForce {
            name: name.into(),
            a: body.into(),
            b: SpatialBodyRef::Ground,
            kind: SpatialForceKind::Torque(SpatialLoad::new([0.0; 3], components, frame)),
        }
    }

    /// The kind as the model file's `type` tag.
    pub fn kind_name(&self) -> &'static str {
        match self.kind {
            SpatialForceKind::SpringDamper(_) => "spring_damper",
            SpatialForceKind::Force(_) => "force",
            SpatialForceKind::Torque(_) => "torque",
        }
    }

    /// Whether the element has a part that does not derive from a potential (damping, a
    /// time-dependent or body-fixed load, any torque).
    pub fn is_nonconservative(&self) -> bool {
        match &self.kind {
            SpatialForceKind::SpringDamper(s) => s.damping != 0.0,
            SpatialForceKind::Force(l) => !l.is_constant_global(),
            SpatialForceKind::Torque(_) => true,
        }
    }

    /// Whether the non-conservative part only dissipates (dampers) rather than doing external
    /// work (loads).
    pub fn dissipative(&self) -> bool {
        matches!(self.kind, SpatialForceKind::SpringDamper(_))
    }

    /// Checks the parameters; errors name the element and the field.
    pub(crate) fn validate(&self) -> Result<(), ModelError> {
        let element = format!("spatial force '{}'", self.name);
        match &self.kind {
            SpatialForceKind::SpringDamper(s) => s.validate(&element),
            SpatialForceKind::Force(l) => l.validate(&element, true),
            SpatialForceKind::Torque(l) => l.validate(&element, false),
        }
    }

    /// The element with its points and load axes taken from the bodies' frames to their
    /// principal frames (`axes_a`, `axes_b`: the principal axes in the body frames; ground:
    /// `None`).
    pub(crate) fn lowered(
        &self,
        axes_a: Option<&Matrix3<f64>>,
        axes_b: Option<&Matrix3<f64>>,
    ) -> Self {
        let lower = |axes: Option<&Matrix3<f64>>, p: [f64; 3]| match axes {
            None => p,
            Some(a) => (a.transpose() * nalgebra::Vector3::from(p)).into(),
        };
        let mut out = self.clone();
        match &mut out.kind {
            SpatialForceKind::SpringDamper(s) => {
                s.point_a = lower(axes_a, s.point_a);
                s.point_b = lower(axes_b, s.point_b);
            }
            SpatialForceKind::Force(l) | SpatialForceKind::Torque(l) => {
                l.point = lower(axes_a, l.point);
                if let (Axes::Body, Some(a)) = (l.frame, axes_a) {
                    l.to_principal = a.transpose();
                }
            }
        }
        out
    }

    /// The potential of the conservative part at the frames of the two bodies (lowered
    /// element).
    pub(crate) fn potential<T: Scalar>(&self, fa: &SpatialFrame<T>, fb: &SpatialFrame<T>) -> T {
        match &self.kind {
            SpatialForceKind::SpringDamper(s) => s.potential(fa, fb),
            SpatialForceKind::Force(l) => l.force_potential(fa),
            SpatialForceKind::Torque(_) => T::cst(0.0),
        }
    }

    /// Adds the local generalised force of the non-conservative part (24 entries: body a's
    /// coordinates, then b's) at frames whose jets carry the velocities as their direction
    /// (lowered element).
    pub(crate) fn nonconservative(
        &self,
        fa: &SpatialFrame<DirJetN<SW>>,
        fb: &SpatialFrame<DirJetN<SW>>,
        t: f64,
        out: &mut [f64; SW],
    ) {
        match &self.kind {
            SpatialForceKind::SpringDamper(s) => s.damping_force(fa, fb, out),
            SpatialForceKind::Force(l) => {
                if !l.is_constant_global() {
                    l.add_force(&values(fa), t, out);
                }
            }
            SpatialForceKind::Torque(l) => l.add_torque(&values(fa), t, out),
        }
    }
}

/// The values of a frame of jets.
fn values(f: &SpatialFrame<DirJetN<SW>>) -> SpatialFrame<f64> {
    SpatialFrame {
        x: f.x.map(|c| c.v),
        d: f.d.map(|d| d.map(|c| c.v)),
    }
}

//! Force elements, one file per kind. Gravity is a system-wide vector (see
//! [`crate::SystemBuilder::set_gravity`]).
//!
//! Springs and constant loads are conservative and contribute to the potential `V(q)`; dampers
//! and time-dependent loads are non-conservative and enter only the generalized force. Each kind
//! is a struct implementing the crate-internal trait `ForceType`: its potential written once over a generic
//! scalar (so the gradient, the stiffness matrix and higher derivatives come from the jets),
//! its non-conservative generalized force, its body-fixed points, its parameter checks, its
//! drawing and its model-file form. [`ForceKind`] lists the kinds and `each_force!` dispatches
//! to them; docs/architecture.md ("How to add a force") walks through adding one.

mod custom;
mod point_force;
mod rotary_spring_damper;
mod spring_damper;
mod torque;

pub use custom::{CustomForce, CustomForceSpec, ForceInput, ForceLaw, ForceLawFactory, ForceLaws};
pub use point_force::{PointForce, PointForceSpec};
pub use rotary_spring_damper::{RotarySpringDamper, RotarySpringDamperSpec};
pub use spring_damper::{SpringDamper, SpringDamperSpec};
pub use torque::{Torque, TorqueSpec};

use crate::body::BodyRef;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::ForceSpec;
use crate::jet::{Frame, Scalar};
use crate::timefn::TimeFunction;

/// What every force kind provides (implemented once per file).
pub(crate) trait ForceType {
    /// The kind as a lower-case word: the model file's `type` tag.
    const KIND: &'static str;
    /// Whether the element loads one body (its second side is always ground).
    const SINGLE_BODY: bool = false;
    /// The two attachments (`b` is ground for single-body loads).
    fn bodies(&self) -> (BodyRef, BodyRef);
    /// Potential energy of the conservative part, generic over the scalar type.
    fn potential<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>) -> T;
    /// Whether the element has a non-conservative part (damping or a time-dependent load).
    fn is_nonconservative(&self) -> bool;
    /// Whether the non-conservative part only dissipates (the energy balance's
    /// `E_dissipated`), rather than doing external work (`W_external`).
    fn dissipative(&self) -> bool {
        false
    }
    /// Adds the local generalized force of the non-conservative part (6 entries: body a then
    /// body b) at local coordinates `qa`, `qb`, velocities `va`, `vb` and time `t`.
    fn nonconservative(&self, local: &LocalState, t: f64, out: &mut [f64; 6]);
    /// The body-fixed points, for body-frame lowering and the point-mass check.
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2];
    /// A length of the element (a spring's rest length), for the point masses' nominal length.
    fn length(&self) -> Option<f64> {
        None
    }
    /// A description of the element when it acts on its bodies' rotation (point masses have
    /// none), e.g. `"torque"`.
    fn rotation_use(&self) -> Option<&'static str> {
        None
    }
    /// Checks the parameters; errors name the element.
    fn validate(&self, element: &str) -> Result<(), ModelError>;
    /// How the element is drawn, if it is drawn.
    fn sketch(&self) -> Option<Sketch> {
        None
    }
    /// The model-file form, bodies named by `name_of`.
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec;
}

/// The local coordinates and velocities of an element's two bodies (zeros for ground).
pub(crate) struct LocalState<'a> {
    /// Coordinates of body a.
    pub(crate) qa: &'a [f64; 3],
    /// Coordinates of body b.
    pub(crate) qb: &'a [f64; 3],
    /// Velocities of body a.
    pub(crate) va: &'a [f64; 3],
    /// Velocities of body b.
    pub(crate) vb: &'a [f64; 3],
}

/// The kinds of force element.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ForceKind {
    /// Linear point-to-point spring-damper.
    SpringDamper(SpringDamper),
    /// Rotational spring-damper on a relative angle.
    RotarySpringDamper(RotarySpringDamper),
    /// Force in global axes at a body point.
    Force(PointForce),
    /// Torque on a body.
    Torque(Torque),
    /// A user's force law (see [`ForceLaw`]).
    Custom(CustomForce),
}

macro_rules! force_from {
    ($($variant:ident => $ty:ident),*) => {
        $(impl From<$ty> for ForceKind {
            fn from(f: $ty) -> Self {
                ForceKind::$variant(f)
            }
        })*
    };
}
force_from!(
    SpringDamper => SpringDamper,
    RotarySpringDamper => RotarySpringDamper,
    Force => PointForce,
    Torque => Torque,
    Custom => CustomForce
);

/// `each_force!(kind, f => expr)`: `expr` with `f` bound to the element struct of whatever kind
/// `kind` holds.
macro_rules! each_force {
    ($kind:expr, $f:ident => $body:expr) => {
        match $kind {
            ForceKind::SpringDamper($f) => $body,
            ForceKind::RotarySpringDamper($f) => $body,
            ForceKind::Force($f) => $body,
            ForceKind::Torque($f) => $body,
            ForceKind::Custom($f) => $body,
        }
    };
}

/// A named force element.
#[derive(Clone, Debug, PartialEq)]
pub struct Force {
    /// Unique name.
    pub name: String,
    /// Kind and parameters.
    pub kind: ForceKind,
}

impl Force {
    /// Point-to-point spring-damper.
    #[allow(clippy::too_many_arguments)]
    pub fn spring_damper(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        stiffness: f64,
        damping: f64,
        rest_length: f64,
    ) -> Self {
        let kind = SpringDamper {
            a: a.into(),
            pa,
            b: b.into(),
            pb,
            stiffness,
            damping,
            rest_length,
        };
        Self::new(name, ForceKind::SpringDamper(kind))
    }
    /// Rotational spring-damper on `theta_b - theta_a`.
    pub fn rotary_spring_damper(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        b: impl Into<BodyRef>,
        stiffness: f64,
        damping: f64,
        rest_angle: f64,
    ) -> Self {
        let kind = RotarySpringDamper {
            a: a.into(),
            b: b.into(),
            stiffness,
            damping,
            rest_angle,
        };
        Self::new(name, ForceKind::RotarySpringDamper(kind))
    }
    /// Applied force (global axes) at a body point.
    #[allow(clippy::self_named_constructors)] // `Force::force` next to `Force::torque`
    pub fn force(
        name: impl Into<String>,
        body: impl Into<BodyRef>,
        point: [f64; 2],
        fx: TimeFunction,
        fy: TimeFunction,
    ) -> Self {
        let kind = PointForce {
            body: body.into(),
            point,
            fx,
            fy,
        };
        Self::new(name, ForceKind::Force(kind))
    }
    /// Applied torque.
    pub fn torque(name: impl Into<String>, body: impl Into<BodyRef>, torque: TimeFunction) -> Self {
        let kind = Torque {
            body: body.into(),
            torque,
        };
        Self::new(name, ForceKind::Torque(kind))
    }
    /// A force element with a user's law between `a` and `b` (`BodyRef::Ground` for a law
    /// on one body); see [`ForceLaw`].
    pub fn custom(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        b: impl Into<BodyRef>,
        law: std::sync::Arc<dyn ForceLaw>,
    ) -> Self {
        let kind = CustomForce {
            a: a.into(),
            b: b.into(),
            law,
        };
        Self::new(name, ForceKind::Custom(kind))
    }
    /// A force element of any kind, from its kind's struct with named fields (no stiffness
    /// and damping to swap, as in the positional [`Force::spring_damper`]):
    ///
    /// ```
    /// use mbd_model::forces::SpringDamper;
    /// use mbd_model::{BodyRef, Force, SystemBuilder, Body};
    /// let mut b = SystemBuilder::new();
    /// let mass = b.add_body(Body::new("mass").position(0.0, -1.0, 0.0));
    /// b.add_force(Force::new(
    ///     "suspension",
    ///     SpringDamper {
    ///         a: BodyRef::Ground,
    ///         pa: [0.0, 0.0],
    ///         b: mass.into(),
    ///         pb: [0.0, 0.0],
    ///         stiffness: 100.0,
    ///         damping: 2.0,
    ///         rest_length: 0.8,
    ///     },
    /// ));
    /// assert_eq!(b.build()?.forces()[0].kind_name(), "spring_damper");
    /// # Ok::<(), mbd_model::ModelError>(())
    /// ```
    pub fn new(name: impl Into<String>, kind: impl Into<ForceKind>) -> Self {
        Force {
            name: name.into(),
            kind: kind.into(),
        }
    }

    /// The two attachments (`b` is ground for single-body loads).
    pub fn bodies(&self) -> (BodyRef, BodyRef) {
        each_force!(&self.kind, f => f.bodies())
    }

    /// The kind as a lower-case word (the model file's `type`).
    pub fn kind_name(&self) -> &'static str {
        fn kind<F: ForceType>(_: &F) -> &'static str {
            F::KIND
        }
        each_force!(&self.kind, f => kind(f))
    }

    /// Whether the element has a non-conservative part (damping or a time-dependent load).
    pub fn is_nonconservative(&self) -> bool {
        each_force!(&self.kind, f => f.is_nonconservative())
    }

    /// How the element is drawn, `None` for elements the drawings leave out (loads).
    pub fn sketch(&self) -> Option<Sketch> {
        each_force!(&self.kind, f => f.sketch())
    }

    /// Whether the element loads one body only.
    pub(crate) fn is_single_body(&self) -> bool {
        fn single<F: ForceType>(_: &F) -> bool {
            F::SINGLE_BODY
        }
        each_force!(&self.kind, f => single(f))
    }

    /// Potential energy of the conservative part, generic over the scalar type: the hook
    /// through which every derivative pass of the potential evaluates the element (with the
    /// bodies' frames from [`crate::jet::Frame`] and the attachments from
    /// [`crate::System::force_elements`]).
    #[inline]
    pub fn potential<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>) -> T {
        each_force!(&self.kind, f => f.potential(qa, qb))
    }

    /// Local generalized force of the non-conservative part, given local coordinates and
    /// velocities; added into `out` (6 entries: body a then body b).
    pub(crate) fn nonconservative(
        &self,
        qa: &[f64; 3],
        qb: &[f64; 3],
        va: &[f64; 3],
        vb: &[f64; 3],
        t: f64,
        out: &mut [f64; 6],
    ) {
        let local = LocalState { qa, qb, va, vb };
        each_force!(&self.kind, f => f.nonconservative(&local, t, out))
    }

    /// See [`ForceType::dissipative`].
    pub(crate) fn dissipative(&self) -> bool {
        each_force!(&self.kind, f => f.dissipative())
    }

    /// The Jacobians of the local non-conservative force (6 entries) with respect to the local
    /// coordinates (`dq`) and velocities (`dv`), both overwritten: a custom law's own, else
    /// central differences with step `1e-6 (1 + |x|)`.
    pub(crate) fn nonconservative_jacobian(
        &self,
        x: [[f64; 3]; 4],
        t: f64,
        dq: &mut [[f64; 6]; 6],
        dv: &mut [[f64; 6]; 6],
    ) {
        if let ForceKind::Custom(c) = &self.kind {
            let local = LocalState {
                qa: &x[0],
                qb: &x[1],
                va: &x[2],
                vb: &x[3],
            };
            if c.analytic_jacobian(&local, t, dq, dv) {
                return;
            }
        }
        let mut x = x;
        for (block, jac) in [(0usize, &mut *dq), (2, &mut *dv)] {
            for j in 0..6 {
                let (side, l) = (block + j / 3, j % 3);
                let x0 = x[side][l];
                let d = 1e-6 * (1.0 + x0.abs());
                let mut fp = [0.0; 6];
                let mut fm = [0.0; 6];
                x[side][l] = x0 + d;
                self.nonconservative(&x[0], &x[1], &x[2], &x[3], t, &mut fp);
                x[side][l] = x0 - d;
                self.nonconservative(&x[0], &x[1], &x[2], &x[3], t, &mut fm);
                x[side][l] = x0;
                for i in 0..6 {
                    jac[i][j] = (fp[i] - fm[i]) / (2.0 * d);
                }
            }
        }
    }

    /// See [`ForceType::anchors`].
    pub(crate) fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        each_force!(&mut self.kind, f => f.anchors())
    }

    /// See [`ForceType::length`].
    pub(crate) fn length(&self) -> Option<f64> {
        each_force!(&self.kind, f => f.length())
    }

    /// See [`ForceType::rotation_use`].
    pub(crate) fn rotation_use(&self) -> Option<&'static str> {
        each_force!(&self.kind, f => f.rotation_use())
    }

    /// Checks the element's parameters; errors name it.
    pub(crate) fn validate(&self) -> Result<(), ModelError> {
        each_force!(&self.kind, f => f.validate(&self.name))
    }

    /// The model-file form.
    pub(crate) fn to_spec(&self, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec {
        each_force!(&self.kind, f => f.to_spec(self.name.clone(), name_of))
    }
}

impl ForceSpec {
    /// The element this entry describes, bodies found by `find` (which names the element in
    /// its errors).
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
        laws: &ForceLaws,
    ) -> Result<Force, ModelError> {
        match self {
            ForceSpec::SpringDamper(s) => s.to_force(find),
            ForceSpec::RotarySpringDamper(s) => s.to_force(find),
            ForceSpec::Force(s) => s.to_force(find),
            ForceSpec::Torque(s) => s.to_force(find),
            ForceSpec::Custom(s) => s.to_force(find, laws),
        }
    }
}

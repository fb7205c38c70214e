//! Joints: holonomic constraints between two bodies (or a body and ground), one file per kind.
//!
//! Every planar joint equation has the form `Phi_k(q, t) = g_k(q_a, q_b) - f_k(t)`: time enters
//! only additively, through a driver's function. So its `Phi_q` does not depend on `t`,
//! `Phi_qt = 0`, `Phi_t = -f'(t)` and `Phi_tt = -f''(t)`. (The spatial angle driver's Jacobian
//! does depend on `t`: `crate::spatial`, and the model's Jacobian passes take `t`.)
//!
//! Each kind is a struct in its own file implementing the crate-internal trait `JointType`: its
//! equations `g(q_a, q_b)` written once over a generic scalar (every derivative pass of the
//! model evaluates them with its own jet type), its equation labels, its body-fixed points (for body-frame lowering,
//! the scale estimate and point-mass checks), its parameter checks, its drawing and its
//! model-file form (a spec struct beside it). [`JointKind`] lists the kinds and `each_joint!`
//! dispatches to them; docs/architecture.md ("How to add a joint") walks through adding one.

mod absolute;
mod angle_driver;
mod distance;
mod distance_driver;
mod prismatic;
mod revolute;
mod slide_driver;
mod weld;

pub use absolute::{Absolute, AbsoluteSpec, Coordinate};
pub use angle_driver::{AngleDriver, AngleDriverSpec};
pub use distance::{Distance, DistanceSpec};
pub use distance_driver::{DistanceDriver, DistanceDriverSpec};
pub use prismatic::{Prismatic, PrismaticSpec};
pub use revolute::{Revolute, RevoluteSpec};
pub use slide_driver::{SlideDriver, SlideDriverSpec};
pub use weld::{Weld, WeldSpec};

use crate::body::BodyRef;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{Frame, Scalar};
use crate::system::Attach;
use crate::timefn::TimeFunction;

/// What every joint kind provides (implemented once per file).
pub(crate) trait JointType {
    /// The kind as a lower-case word: the model file's `type` tag and [`Joint::kind_name`].
    const KIND: &'static str;
    /// Whether the joint acts on one body only (its second side is always ground).
    const SINGLE_BODY: bool = false;
    /// The two attachments `(a, b)`.
    fn bodies(&self) -> (BodyRef, BodyRef);
    /// Short labels of the equations (their number is the joint's equation count; an equation
    /// labelled `"angle"` is measured in radians, the others in lengths).
    fn labels(&self) -> &'static [&'static str];
    /// The time-free part `g(q_a, q_b)` of the equations, written once for every scalar type.
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]);
    /// The driver `f(t)` subtracted from equation 0, if the joint has one.
    fn driver(&self) -> Option<&TimeFunction> {
        None
    }
    /// The body-fixed points, for body-frame lowering and the point-mass check.
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2];
    /// The lever arms (body-fixed points that couple a body's rotation into the equations) on
    /// sides `a` and `b`, for the scale estimate and the inertia-scale check.
    fn lever_arms(&self) -> [Option<[f64; 2]>; 2];
    /// A length the joint imposes (the distance joint's), for the length scale.
    fn length(&self) -> Option<f64> {
        None
    }
    /// A description of the joint when it acts on its bodies' rotation (point masses have
    /// none), e.g. `"weld joint"`.
    fn rotation_use(&self) -> Option<&'static str> {
        None
    }
    /// Checks the parameters (finite points, positive lengths, ...) and normalises them.
    fn validate(&mut self, element: &str) -> Result<(), ModelError>;
    /// How the joint is drawn.
    fn sketch(&self) -> Sketch;
    /// The model-file form, bodies named by `name_of`.
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec;
}

/// The kinds of joint, with their parameters. Local points are in the body frame (relative to
/// the centre of mass); on ground they are global points.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum JointKind {
    /// Pin: two points coincide (2 equations).
    Revolute(Revolute),
    /// Slider: a point slides on a line, relative angle fixed (2 equations).
    Prismatic(Prismatic),
    /// Rigid connection: points coincide and relative angle fixed (3 equations).
    Weld(Weld),
    /// Massless rod between two points (1 equation).
    Distance(Distance),
    /// One absolute coordinate of a body point, or the body angle, fixed (1 equation).
    Absolute(Absolute),
    /// Rheonomic driver of a relative angle (1 equation).
    AngleDriver(AngleDriver),
    /// Rheonomic driver of a point's slide along a body's axis (1 equation).
    SlideDriver(SlideDriver),
    /// Rheonomic driver of the distance between two points (1 equation).
    DistanceDriver(DistanceDriver),
}

/// `each_joint!(kind, j => expr)`: `expr` with `j` bound to the joint struct of whatever kind
/// `kind` (a `&JointKind` or `&mut JointKind`) holds.
macro_rules! joint_from {
    ($($variant:ident),*) => {
        $(impl From<$variant> for JointKind {
            fn from(j: $variant) -> Self {
                JointKind::$variant(j)
            }
        })*
    };
}
joint_from!(
    Revolute,
    Prismatic,
    Weld,
    Distance,
    Absolute,
    AngleDriver,
    SlideDriver,
    DistanceDriver
);

macro_rules! each_joint {
    ($kind:expr, $j:ident => $body:expr) => {
        match $kind {
            JointKind::Revolute($j) => $body,
            JointKind::Prismatic($j) => $body,
            JointKind::Weld($j) => $body,
            JointKind::Distance($j) => $body,
            JointKind::Absolute($j) => $body,
            JointKind::AngleDriver($j) => $body,
            JointKind::SlideDriver($j) => $body,
            JointKind::DistanceDriver($j) => $body,
        }
    };
}

/// A named joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Unique name (used in error messages and equation names).
    pub name: String,
    /// Kind and parameters.
    pub kind: JointKind,
}

/// One side of a revolute joint's equations `point_a(pa) - point_b(pb)`: what closed-form
/// revolute rows iterate over (see [`Joint::revolute_sides`]).
#[derive(Clone, Copy, Debug)]
pub struct RevoluteSide {
    /// The body (`None`: ground).
    pub body: Option<usize>,
    /// Its local slot: 0 for side a, 3 for side b.
    pub slot: usize,
    /// The body-fixed point.
    pub p: [f64; 2],
    /// The sign of the side in the equations: `+1` for a, `-1` for b.
    pub sign: f64,
}

impl Joint {
    /// Revolute joint between `a` at `pa` and `b` at `pb`.
    pub fn revolute(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
    ) -> Self {
        let kind = Revolute {
            a: a.into(),
            pa,
            b: b.into(),
            pb,
        };
        Self::new(name, JointKind::Revolute(kind))
    }
    /// Prismatic joint: `pb` on `b` slides along `axis` through `pa` on `a`; relative angle fixed.
    pub fn prismatic(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        axis: [f64; 2],
        angle: f64,
    ) -> Self {
        let kind = Prismatic {
            a: a.into(),
            pa,
            b: b.into(),
            pb,
            axis,
            angle,
        };
        Self::new(name, JointKind::Prismatic(kind))
    }
    /// Weld joint.
    pub fn weld(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        angle: f64,
    ) -> Self {
        let kind = Weld {
            a: a.into(),
            pa,
            b: b.into(),
            pb,
            angle,
        };
        Self::new(name, JointKind::Weld(kind))
    }
    /// Distance constraint.
    pub fn distance(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        length: f64,
    ) -> Self {
        let kind = Distance {
            a: a.into(),
            pa,
            b: b.into(),
            pb,
            length,
        };
        Self::new(name, JointKind::Distance(kind))
    }
    /// Absolute-coordinate constraint.
    pub fn absolute(
        name: impl Into<String>,
        body: impl Into<BodyRef>,
        point: [f64; 2],
        coordinate: Coordinate,
        value: f64,
    ) -> Self {
        let kind = Absolute {
            body: body.into(),
            point,
            coordinate,
            value,
        };
        Self::new(name, JointKind::Absolute(kind))
    }
    /// Relative-angle driver `theta_b - theta_a = f(t)`.
    pub fn angle_driver(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        b: impl Into<BodyRef>,
        f: TimeFunction,
    ) -> Self {
        let kind = AngleDriver {
            a: a.into(),
            b: b.into(),
            f,
        };
        Self::new(name, JointKind::AngleDriver(kind))
    }
    /// A joint of any kind, from its kind's struct with named fields (the positional
    /// constructors above are shorthands):
    ///
    /// ```
    /// use mbd_model::joints::Prismatic;
    /// use mbd_model::{Body, BodyRef, Joint, SystemBuilder};
    /// let mut b = SystemBuilder::new();
    /// let slider = b.add_body(Body::new("slider").position(0.3, 0.0, 0.0));
    /// b.add_joint(Joint::new(
    ///     "guide",
    ///     Prismatic {
    ///         a: BodyRef::Ground,
    ///         pa: [0.0, 0.0],
    ///         b: slider.into(),
    ///         pb: [0.0, 0.0],
    ///         axis: [1.0, 0.0],
    ///         angle: 0.0,
    ///     },
    /// ));
    /// assert_eq!(b.build()?.dof(), 1);
    /// # Ok::<(), mbd_model::ModelError>(())
    /// ```
    pub fn new(name: impl Into<String>, kind: impl Into<JointKind>) -> Self {
        Joint {
            name: name.into(),
            kind: kind.into(),
        }
    }

    /// The two attachments `(a, b)` (for [`JointKind::Absolute`], `b` is ground).
    pub fn bodies(&self) -> (BodyRef, BodyRef) {
        each_joint!(&self.kind, j => j.bodies())
    }

    /// Number of scalar equations.
    #[inline]
    pub fn n_equations(&self) -> usize {
        self.equation_labels().len()
    }

    /// Short labels of the equations, e.g. `["x", "y"]`.
    #[inline]
    pub fn equation_labels(&self) -> &'static [&'static str] {
        each_joint!(&self.kind, j => j.labels())
    }

    /// The kind as a lower-case word (the model file's `type`).
    pub fn kind_name(&self) -> &'static str {
        fn kind<J: JointType>(_: &J) -> &'static str {
            J::KIND
        }
        each_joint!(&self.kind, j => kind(j))
    }

    /// Whether the joint depends explicitly on time.
    pub fn is_rheonomic(&self) -> bool {
        self.driver().is_some_and(|f| !f.is_constant())
    }

    /// How the joint is drawn: its sides, points and axis.
    pub fn sketch(&self) -> Sketch {
        each_joint!(&self.kind, j => j.sketch())
    }

    /// Whether the joint acts on one body only.
    pub(crate) fn is_single_body(&self) -> bool {
        fn single<J: JointType>(_: &J) -> bool {
            J::SINGLE_BODY
        }
        each_joint!(&self.kind, j => single(j))
    }

    #[inline]
    fn driver(&self) -> Option<&TimeFunction> {
        each_joint!(&self.kind, j => j.driver())
    }

    /// `(f(t), f'(t), f''(t))` of equation `k`: the part subtracted from `g_k(q)`.
    #[inline]
    pub(crate) fn time_part(&self, k: usize, t: f64) -> [f64; 3] {
        match self.driver() {
            Some(f) if k == 0 => f.eval(t),
            _ => [0.0; 3],
        }
    }

    /// The time-free part `g(q_a, q_b)` of the equations (the first [`Joint::n_equations`]
    /// entries of `out`), written once for every scalar type: the generic hook through which
    /// every derivative pass evaluates the joint, in this crate and above it (with the bodies'
    /// frames from [`crate::jet::Frame`] and the attachments from [`System::joint_elements`]).
    ///
    /// [`System::joint_elements`]: crate::System::joint_elements
    #[inline]
    pub fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        each_joint!(&self.kind, j => j.eval(qa, qb, out))
    }

    /// See [`JointType::anchors`].
    pub(crate) fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        each_joint!(&mut self.kind, j => j.anchors())
    }

    /// See [`JointType::lever_arms`].
    pub(crate) fn lever_arms(&self) -> [Option<[f64; 2]>; 2] {
        each_joint!(&self.kind, j => j.lever_arms())
    }

    /// See [`JointType::length`].
    pub(crate) fn length(&self) -> Option<f64> {
        each_joint!(&self.kind, j => j.length())
    }

    /// See [`JointType::rotation_use`].
    pub(crate) fn rotation_use(&self) -> Option<&'static str> {
        each_joint!(&self.kind, j => j.rotation_use())
    }

    /// Checks the joint's parameters; errors name the joint.
    pub(crate) fn validate(&mut self) -> Result<(), ModelError> {
        let name = &self.name;
        each_joint!(&mut self.kind, j => j.validate(name))
    }

    /// The model-file form.
    pub(crate) fn to_spec(&self, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec {
        each_joint!(&self.kind, j => j.to_spec(self.name.clone(), name_of))
    }

    /// The two sides of a revolute joint attached at `at`, `None` for any other kind: what
    /// the closed-form revolute rows of the derivative passes iterate over (a body point
    /// `r + R(theta) p` has the derivatives `R^(k)(theta) p` in `theta`, a quarter turn each).
    pub fn revolute_sides(&self, at: Attach) -> Option<[RevoluteSide; 2]> {
        match &self.kind {
            JointKind::Revolute(r) => Some([
                RevoluteSide {
                    body: at.a,
                    slot: 0,
                    p: r.pa,
                    sign: 1.0,
                },
                RevoluteSide {
                    body: at.b,
                    slot: 3,
                    p: r.pb,
                    sign: -1.0,
                },
            ]),
            _ => None,
        }
    }
}

impl JointSpec {
    /// The joint this entry describes, bodies found by `find` (which names the joint in its
    /// errors).
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        match self {
            JointSpec::Revolute(s) => s.to_joint(find),
            JointSpec::Prismatic(s) => s.to_joint(find),
            JointSpec::Weld(s) => s.to_joint(find),
            JointSpec::Distance(s) => s.to_joint(find),
            JointSpec::Absolute(s) => s.to_joint(find),
            JointSpec::AngleDriver(s) => s.to_joint(find),
            JointSpec::SlideDriver(s) => s.to_joint(find),
            JointSpec::DistanceDriver(s) => s.to_joint(find),
        }
    }
}

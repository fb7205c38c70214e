//! The slide driver: the distance of a point of one body along an axis of another, prescribed
//! as a function of time (a translational actuator; with a prismatic joint on the same
//! points it drives the slider).

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{direction, dot, point, sub2, Frame, Scalar};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Rheonomic driver: `(P_b - P_a) . u_a = f(t)` (1 equation), with `u_a` a unit axis fixed in
/// body `a` (ground: a global direction): the slide of `P_b` along the axis from `P_a`.
#[derive(Clone, Debug, PartialEq)]
pub struct SlideDriver {
    /// The body that carries the axis.
    pub a: BodyRef,
    /// The point the slide is measured from, on `a`.
    pub pa: [f64; 2],
    /// The driven body.
    pub b: BodyRef,
    /// The driven point, on `b`.
    pub pb: [f64; 2],
    /// Direction of the axis in `a`'s frame (any non-zero length; normalised at build).
    pub axis: [f64; 2],
    /// The prescribed slide, m, as a function of time.
    pub f: TimeFunction,
}

impl JointType for SlideDriver {
    const KIND: &'static str = "slide_driver";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["slide"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        let d = sub2(point(qb, self.pb), point(qa, self.pa));
        out[0] = dot(d, direction(qa, self.axis));
    }
    fn driver(&self) -> Option<&TimeFunction> {
        Some(&self.f)
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [
            Some(Anchor::new(self.a, "point_a", &mut self.pa)),
            Some(Anchor::new(self.b, "point_b", &mut self.pb)),
        ]
    }
    fn lever_arms(&self) -> [Option<[f64; 2]>; 2] {
        [Some(self.pa), Some(self.pb)]
    }
    fn rotation_use(&self) -> Option<&'static str> {
        Some("slide driver")
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)?;
        check::unit_axis(element, "axis", &mut self.axis)?;
        check::time_function(element, "f", &self.f)
    }
    fn sketch(&self) -> Sketch {
        Sketch::sliding(self.a, self.pa, self.b, self.pb, self.axis)
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec {
        JointSpec::SlideDriver(SlideDriverSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
            axis: self.axis,
            f: self.f.clone(),
        })
    }
}

/// A slide driver in a model file (see [`SlideDriver`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SlideDriverSpec {
    /// Unique joint name.
    pub name: String,
    /// The body that carries the axis (`ground` for a global direction).
    pub body_a: String,
    /// The point the slide is measured from, on `body_a` (body frame), m.
    #[serde(default)]
    pub point_a: [f64; 2],
    /// The driven body.
    pub body_b: String,
    /// The driven point on `body_b`, m.
    #[serde(default)]
    pub point_b: [f64; 2],
    /// Direction of the axis in `body_a`'s frame (any non-zero length).
    pub axis: [f64; 2],
    /// The prescribed slide `(P_b - P_a) . axis`, m, as a function of time.
    pub f: TimeFunction,
}

impl SlideDriverSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = SlideDriver {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
            axis: self.axis,
            f: self.f.clone(),
        };
        Ok(Joint::new(self.name.clone(), JointKind::SlideDriver(kind)))
    }
}

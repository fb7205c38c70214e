//! The revolute joint (pin): point `pa` on body `a` coincides with point `pb` on body `b`.

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{point, sub2, Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Pin: point `pa` on `a` coincides with point `pb` on `b` (2 equations, `x` and `y` of
/// `P_a - P_b`).
#[derive(Clone, Debug, PartialEq)]
pub struct Revolute {
    /// First body.
    pub a: BodyRef,
    /// Point on `a`.
    pub pa: [f64; 2],
    /// Second body.
    pub b: BodyRef,
    /// Point on `b`.
    pub pb: [f64; 2],
}

impl JointType for Revolute {
    const KIND: &'static str = "revolute";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["x", "y"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        let d = sub2(point(qa, self.pa), point(qb, self.pb));
        out[0] = d[0];
        out[1] = d[1];
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
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)
    }
    fn sketch(&self) -> Sketch {
        Sketch {
            a: self.a,
            point_a: Some(self.pa),
            b: self.b,
            point_b: Some(self.pb),
            axis: None,
        }
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec {
        JointSpec::Revolute(RevoluteSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
        })
    }
}

/// A revolute joint in a model file (see [`Revolute`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RevoluteSpec {
    /// Unique joint name.
    pub name: String,
    /// First body (`ground` for the ground).
    pub body_a: String,
    /// Point on `body_a` (body frame), m.
    #[serde(default)]
    pub point_a: [f64; 2],
    /// Second body.
    pub body_b: String,
    /// Point on `body_b`, m.
    #[serde(default)]
    pub point_b: [f64; 2],
}

impl RevoluteSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = Revolute {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
        };
        Ok(Joint::new(self.name.clone(), JointKind::Revolute(kind)))
    }
}

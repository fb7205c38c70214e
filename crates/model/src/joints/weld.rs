//! The weld joint: two points coincide and the relative angle is fixed.

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{point, sub2, Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Rigid connection: points `pa` on `a` and `pb` on `b` coincide and the relative angle
/// `theta_b - theta_a` is `angle` (3 equations).
#[derive(Clone, Debug, PartialEq)]
pub struct Weld {
    /// First body.
    pub a: BodyRef,
    /// Point on `a`.
    pub pa: [f64; 2],
    /// Second body.
    pub b: BodyRef,
    /// Point on `b`.
    pub pb: [f64; 2],
    /// Relative angle `theta_b - theta_a`.
    pub angle: f64,
}

impl JointType for Weld {
    const KIND: &'static str = "weld";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["x", "y", "angle"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        let d = sub2(point(qa, self.pa), point(qb, self.pb));
        out[0] = d[0];
        out[1] = d[1];
        out[2] = qb[2] - qa[2] - self.angle;
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
        Some("weld joint")
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)?;
        check::finite(element, "angle", self.angle)
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
        JointSpec::Weld(WeldSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
            angle: self.angle,
        })
    }
}

/// A weld joint in a model file (see [`Weld`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WeldSpec {
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
    /// Relative angle `theta_b - theta_a`, rad.
    #[serde(default)]
    pub angle: f64,
}

impl WeldSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = Weld {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
            angle: self.angle,
        };
        Ok(Joint::new(self.name.clone(), JointKind::Weld(kind)))
    }
}

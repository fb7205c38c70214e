//! The distance joint: a massless rod between two body points.

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{dot, point, sub2, Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Massless rod: `|P_b - P_a| = length`, written as `(|d|^2 - L^2) / (2 L)` (1 equation; smooth
/// where the points coincide, with the gradient of `|d| - L` on the constraint).
#[derive(Clone, Debug, PartialEq)]
pub struct Distance {
    /// First body.
    pub a: BodyRef,
    /// Point on `a`.
    pub pa: [f64; 2],
    /// Second body.
    pub b: BodyRef,
    /// Point on `b`.
    pub pb: [f64; 2],
    /// Distance (> 0).
    pub length: f64,
}

impl JointType for Distance {
    const KIND: &'static str = "distance";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["length"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        let d = sub2(point(qb, self.pb), point(qa, self.pa));
        out[0] = (dot(d, d) - self.length * self.length) * (0.5 / self.length);
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
    fn length(&self) -> Option<f64> {
        Some(self.length)
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)?;
        check::positive(element, "length", self.length)
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
        JointSpec::Distance(DistanceSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
            length: self.length,
        })
    }
}

/// A distance joint in a model file (see [`Distance`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DistanceSpec {
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
    /// Distance between the points, m (> 0).
    pub length: f64,
}

impl DistanceSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = Distance {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
            length: self.length,
        };
        Ok(Joint::new(self.name.clone(), JointKind::Distance(kind)))
    }
}

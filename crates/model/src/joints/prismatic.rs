//! The prismatic joint (slider): a point of one body slides on a line fixed in the other, and
//! the relative angle stays fixed.

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{direction, dot, point, sub2, Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Slider: point `pb` on `b` stays on the line through `pa` along `axis` (fixed in `a`), and the
/// relative angle `theta_b - theta_a` stays `angle` (2 equations: the normal offset
/// `n . (P_b - P_a)` with `n` the axis turned a quarter, and the angle).
#[derive(Clone, Debug, PartialEq)]
pub struct Prismatic {
    /// First body (carries the axis).
    pub a: BodyRef,
    /// Point on `a` on the sliding line.
    pub pa: [f64; 2],
    /// Second body.
    pub b: BodyRef,
    /// Point on `b` that slides on the line.
    pub pb: [f64; 2],
    /// Direction of the line in `a`'s frame (any non-zero length; normalised at build).
    pub axis: [f64; 2],
    /// Relative angle kept fixed.
    pub angle: f64,
}

impl JointType for Prismatic {
    const KIND: &'static str = "prismatic";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["normal", "angle"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        // normal to the axis in a's frame: R * axis
        let n = direction(qa, [-self.axis[1], self.axis[0]]);
        let d = sub2(point(qb, self.pb), point(qa, self.pa));
        out[0] = dot(n, d);
        out[1] = qb[2] - qa[2] - self.angle;
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
        Some("prismatic joint")
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)?;
        check::finite(element, "angle", self.angle)?;
        check::unit_axis(element, "axis", &mut self.axis)
    }
    fn sketch(&self) -> Sketch {
        Sketch::sliding(self.a, self.pa, self.b, self.pb, self.axis)
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec {
        JointSpec::Prismatic(PrismaticSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
            axis: self.axis,
            angle: self.angle,
        })
    }
}

/// A prismatic joint in a model file (see [`Prismatic`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PrismaticSpec {
    /// Unique joint name.
    pub name: String,
    /// The body that carries the axis (`ground` for the ground).
    pub body_a: String,
    /// A point of the sliding line on `body_a` (body frame), m.
    #[serde(default)]
    pub point_a: [f64; 2],
    /// The sliding body.
    pub body_b: String,
    /// The point of `body_b` that slides on the line, m.
    #[serde(default)]
    pub point_b: [f64; 2],
    /// Direction of the line in `body_a`'s frame (any non-zero length).
    pub axis: [f64; 2],
    /// Relative angle `theta_b - theta_a` kept fixed, rad.
    #[serde(default)]
    pub angle: f64,
}

impl PrismaticSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = Prismatic {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
            axis: self.axis,
            angle: self.angle,
        };
        Ok(Joint::new(self.name.clone(), JointKind::Prismatic(kind)))
    }
}

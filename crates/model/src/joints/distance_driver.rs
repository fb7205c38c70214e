//! The distance driver: the distance between two body points prescribed as a function of time
//! (a telescopic actuator, a cable winch).

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{dot, point, sub2, Frame, Scalar};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Rheonomic driver: `|P_b - P_a| = f(t)` (1 equation, written `|P_b - P_a| - f(t)`: time
/// enters additively). The prescribed length must stay positive: where the points meet the
/// direction between them, and so the equation's gradient, is undefined.
#[derive(Clone, Debug, PartialEq)]
pub struct DistanceDriver {
    /// First body.
    pub a: BodyRef,
    /// Point on `a`.
    pub pa: [f64; 2],
    /// Second body.
    pub b: BodyRef,
    /// Point on `b`.
    pub pb: [f64; 2],
    /// The prescribed distance, m, as a function of time (positive).
    pub f: TimeFunction,
}

impl JointType for DistanceDriver {
    const KIND: &'static str = "distance_driver";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["length"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        let d = sub2(point(qb, self.pb), point(qa, self.pa));
        out[0] = dot(d, d).sqrt();
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
    fn length(&self) -> Option<f64> {
        let l = self.f.eval(0.0)[0];
        (l.is_finite() && l > 0.0).then_some(l)
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)?;
        check::time_function(element, "f", &self.f)?;
        check::positive(element, "f(0)", self.f.eval(0.0)[0])
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
        JointSpec::DistanceDriver(DistanceDriverSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
            f: self.f.clone(),
        })
    }
}

/// A distance driver in a model file (see [`DistanceDriver`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DistanceDriverSpec {
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
    /// The prescribed distance between the points, m (positive), as a function of time.
    pub f: TimeFunction,
}

impl DistanceDriverSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = DistanceDriver {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
            f: self.f.clone(),
        };
        Ok(Joint::new(
            self.name.clone(),
            JointKind::DistanceDriver(kind),
        ))
    }
}

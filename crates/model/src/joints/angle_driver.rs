//! The angle driver: a relative angle prescribed as a function of time.

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{Frame, Scalar};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Rheonomic driver: `theta_b - theta_a = f(t)` (1 equation). With `a` = ground it drives an
/// absolute angle.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleDriver {
    /// Reference body.
    pub a: BodyRef,
    /// Driven body.
    pub b: BodyRef,
    /// The prescribed relative angle.
    pub f: TimeFunction,
}

impl JointType for AngleDriver {
    const KIND: &'static str = "angle_driver";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn labels(&self) -> &'static [&'static str] {
        &["angle"]
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        out[0] = qb[2] - qa[2];
    }
    fn driver(&self) -> Option<&TimeFunction> {
        Some(&self.f)
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [None, None]
    }
    fn lever_arms(&self) -> [Option<[f64; 2]>; 2] {
        [None, None]
    }
    fn rotation_use(&self) -> Option<&'static str> {
        Some("angle driver")
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::time_function(element, "f", &self.f)
    }
    fn sketch(&self) -> Sketch {
        Sketch {
            a: self.a,
            point_a: None,
            b: self.b,
            point_b: None,
            axis: None,
        }
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec {
        JointSpec::AngleDriver(AngleDriverSpec {
            name,
            body_a: name_of(self.a),
            body_b: name_of(self.b),
            f: self.f.clone(),
        })
    }
}

/// An angle driver in a model file (see [`AngleDriver`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AngleDriverSpec {
    /// Unique joint name.
    pub name: String,
    /// Reference body (`ground` for an absolute angle).
    pub body_a: String,
    /// Driven body.
    pub body_b: String,
    /// The prescribed relative angle `theta_b - theta_a`, rad, as a function of time.
    pub f: TimeFunction,
}

impl AngleDriverSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = AngleDriver {
            a: find(&element, &self.body_a)?,
            b: find(&element, &self.body_b)?,
            f: self.f.clone(),
        };
        Ok(Joint::new(self.name.clone(), JointKind::AngleDriver(kind)))
    }
}

//! The absolute-coordinate joint: one global coordinate of a body point, or the body's angle,
//! held at a value.

use super::{Joint, JointKind, JointType};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::JointSpec;
use crate::jet::{point, Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Which coordinate an [`Absolute`] joint fixes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Coordinate {
    /// Global x of the point.
    X,
    /// Global y of the point.
    Y,
    /// The body's rotation angle.
    Angle,
}

/// One absolute coordinate of a body point (or the body angle) fixed (1 equation).
#[derive(Clone, Debug, PartialEq)]
pub struct Absolute {
    /// The body.
    pub body: BodyRef,
    /// Point on the body (ignored for [`Coordinate::Angle`]).
    pub point: [f64; 2],
    /// Which coordinate.
    pub coordinate: Coordinate,
    /// Its value.
    pub value: f64,
}

impl JointType for Absolute {
    const KIND: &'static str = "absolute";
    const SINGLE_BODY: bool = true;
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.body, BodyRef::Ground)
    }
    fn labels(&self) -> &'static [&'static str] {
        match self.coordinate {
            Coordinate::X => &["x"],
            Coordinate::Y => &["y"],
            Coordinate::Angle => &["angle"],
        }
    }
    #[inline(always)]
    fn eval<T: Scalar>(&self, qa: &Frame<T>, _qb: &Frame<T>, out: &mut [T; 3]) {
        out[0] = match self.coordinate {
            Coordinate::X => point(qa, self.point)[0] - self.value,
            Coordinate::Y => point(qa, self.point)[1] - self.value,
            Coordinate::Angle => qa[2] - self.value,
        };
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [Some(Anchor::new(self.body, "point", &mut self.point)), None]
    }
    fn lever_arms(&self) -> [Option<[f64; 2]>; 2] {
        match self.coordinate {
            Coordinate::Angle => [None, None],
            _ => [Some(self.point), None],
        }
    }
    fn rotation_use(&self) -> Option<&'static str> {
        (self.coordinate == Coordinate::Angle).then_some("absolute angle joint")
    }
    fn validate(&mut self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point", self.point)?;
        check::finite(element, "value", self.value)
    }
    fn sketch(&self) -> Sketch {
        Sketch {
            a: self.body,
            point_a: Some(self.point),
            b: BodyRef::Ground,
            point_b: None,
            axis: None,
        }
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> JointSpec {
        JointSpec::Absolute(AbsoluteSpec {
            name,
            body: name_of(self.body),
            point: self.point,
            coordinate: self.coordinate,
            value: self.value,
        })
    }
}

/// An absolute-coordinate joint in a model file (see [`Absolute`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AbsoluteSpec {
    /// Unique joint name.
    pub name: String,
    /// The body.
    pub body: String,
    /// The point on the body (body frame), m; ignored for `angle`.
    #[serde(default)]
    pub point: [f64; 2],
    /// `x`, `y` or `angle`.
    pub coordinate: Coordinate,
    /// The value held, m or rad.
    pub value: f64,
}

impl AbsoluteSpec {
    pub(crate) fn to_joint(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Joint, ModelError> {
        let element = format!("joint '{}'", self.name);
        let kind = Absolute {
            body: find(&element, &self.body)?,
            point: self.point,
            coordinate: self.coordinate,
            value: self.value,
        };
        Ok(Joint::new(self.name.clone(), JointKind::Absolute(kind)))
    }
}

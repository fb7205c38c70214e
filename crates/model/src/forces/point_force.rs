//! A force in global axes applied at a body point.

use super::{Force, ForceKind, ForceType, LocalState};
use crate::body::BodyRef;
use crate::check;
use crate::element::Anchor;
use crate::error::ModelError;
use crate::file::ForceSpec;
use crate::jet::{point, Frame, Scalar};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Force in global axes applied at a body point: `(fx(t), fy(t))`. A constant force is
/// conservative (potential `-F . r_P`); a time-dependent one enters the generalized force.
#[derive(Clone, Debug, PartialEq)]
pub struct PointForce {
    /// The body.
    pub body: BodyRef,
    /// Point of application (body frame).
    pub point: [f64; 2],
    /// Global x component.
    pub fx: TimeFunction,
    /// Global y component.
    pub fy: TimeFunction,
}

impl PointForce {
    fn is_constant(&self) -> bool {
        self.fx.is_constant() && self.fy.is_constant()
    }
}

impl ForceType for PointForce {
    const KIND: &'static str = "force";
    const SINGLE_BODY: bool = true;
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.body, BodyRef::Ground)
    }
    #[inline(always)]
    fn potential<T: Scalar>(&self, qa: &Frame<T>, _qb: &Frame<T>) -> T {
        if self.is_constant() {
            let r = point(qa, self.point);
            -(r[0] * self.fx.eval(0.0)[0] + r[1] * self.fy.eval(0.0)[0])
        } else {
            T::cst(0.0)
        }
    }
    fn is_nonconservative(&self) -> bool {
        !self.is_constant()
    }
    fn nonconservative(&self, s: &LocalState, t: f64, out: &mut [f64; 6]) {
        if self.is_constant() {
            return;
        }
        let f = [self.fx.eval(t)[0], self.fy.eval(t)[0]];
        let p = self.point;
        let (sn, cs) = s.qa[2].sin_cos();
        // d r_P / d theta = B s = (-sin sx - cos sy, cos sx - sin sy)
        let dx = -sn * p[0] - cs * p[1];
        let dy = cs * p[0] - sn * p[1];
        out[0] += f[0];
        out[1] += f[1];
        out[2] += f[0] * dx + f[1] * dy;
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [Some(Anchor::new(self.body, "point", &mut self.point)), None]
    }
    fn validate(&self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point", self.point)?;
        check::time_function(element, "fx", &self.fx)?;
        check::time_function(element, "fy", &self.fy)
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec {
        ForceSpec::Force(PointForceSpec {
            name,
            body: name_of(self.body),
            point: self.point,
            fx: self.fx.clone(),
            fy: self.fy.clone(),
        })
    }
}

/// An applied force in a model file (see [`PointForce`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointForceSpec {
    /// Unique element name.
    pub name: String,
    /// The loaded body.
    pub body: String,
    /// Point of application (body frame), m.
    #[serde(default)]
    pub point: [f64; 2],
    /// Global x component, N, as a function of time.
    pub fx: TimeFunction,
    /// Global y component, N, as a function of time.
    pub fy: TimeFunction,
}

impl PointForceSpec {
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Force, ModelError> {
        let element = format!("force '{}'", self.name);
        let kind = PointForce {
            body: find(&element, &self.body)?,
            point: self.point,
            fx: self.fx.clone(),
            fy: self.fy.clone(),
        };
        Ok(Force::new(self.name.clone(), ForceKind::Force(kind)))
    }
}

//! The rotational spring-damper on a relative angle.

use super::{Force, ForceKind, ForceType, LocalState};
use crate::body::BodyRef;
use crate::check;
use crate::element::Anchor;
use crate::error::ModelError;
use crate::file::ForceSpec;
use crate::jet::{Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Rotational spring-damper on the relative angle: `V = k/2 (theta_b - theta_a - angle0)^2`,
/// damping torque `c (omega_b - omega_a)`.
#[derive(Clone, Debug, PartialEq)]
pub struct RotarySpringDamper {
    /// First body.
    pub a: BodyRef,
    /// Second body.
    pub b: BodyRef,
    /// Stiffness (>= 0).
    pub stiffness: f64,
    /// Damping (>= 0).
    pub damping: f64,
    /// Rest relative angle.
    pub rest_angle: f64,
}

impl ForceType for RotarySpringDamper {
    const KIND: &'static str = "rotary_spring_damper";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    #[inline(always)]
    fn potential<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>) -> T {
        let e = qb[2] - qa[2] - self.rest_angle;
        e * e * (0.5 * self.stiffness)
    }
    fn is_nonconservative(&self) -> bool {
        self.damping != 0.0
    }
    fn dissipative(&self) -> bool {
        true
    }
    fn nonconservative(&self, s: &LocalState, _t: f64, out: &mut [f64; 6]) {
        let tau = self.damping * (s.vb[2] - s.va[2]);
        out[2] += tau;
        out[5] -= tau;
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [None, None]
    }
    fn rotation_use(&self) -> Option<&'static str> {
        Some("rotary spring-damper")
    }
    fn validate(&self, element: &str) -> Result<(), ModelError> {
        check::nonneg(element, "stiffness", self.stiffness)?;
        check::nonneg(element, "damping", self.damping)?;
        check::finite(element, "rest_angle", self.rest_angle)
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec {
        ForceSpec::RotarySpringDamper(RotarySpringDamperSpec {
            name,
            body_a: name_of(self.a),
            body_b: name_of(self.b),
            stiffness: self.stiffness,
            damping: self.damping,
            rest_angle: self.rest_angle,
        })
    }
}

/// A rotary spring-damper in a model file (see [`RotarySpringDamper`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RotarySpringDamperSpec {
    /// Unique element name.
    pub name: String,
    /// First body (`ground` for the ground).
    pub body_a: String,
    /// Second body.
    pub body_b: String,
    /// Stiffness, N m/rad (>= 0).
    pub stiffness: f64,
    /// Damping, N m s/rad (>= 0).
    #[serde(default)]
    pub damping: f64,
    /// Rest relative angle `theta_b - theta_a`, rad.
    #[serde(default)]
    pub rest_angle: f64,
}

impl RotarySpringDamperSpec {
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Force, ModelError> {
        let element = format!("force '{}'", self.name);
        let kind = RotarySpringDamper {
            a: find(&element, &self.body_a)?,
            b: find(&element, &self.body_b)?,
            stiffness: self.stiffness,
            damping: self.damping,
            rest_angle: self.rest_angle,
        };
        Ok(Force::new(
            self.name.clone(),
            ForceKind::RotarySpringDamper(kind),
        ))
    }
}

//! A torque applied to a body.

use super::{Force, ForceKind, ForceType, LocalState};
use crate::body::BodyRef;
use crate::check;
use crate::element::Anchor;
use crate::error::ModelError;
use crate::file::ForceSpec;
use crate::jet::{Frame, Scalar};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Torque `tau(t)` on a body. A constant torque is conservative (potential `-tau theta`).
#[derive(Clone, Debug, PartialEq)]
pub struct Torque {
    /// The body.
    pub body: BodyRef,
    /// The torque.
    pub torque: TimeFunction,
}

impl ForceType for Torque {
    const KIND: &'static str = "torque";
    const SINGLE_BODY: bool = true;
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.body, BodyRef::Ground)
    }
    #[inline(always)]
    fn potential<T: Scalar>(&self, qa: &Frame<T>, _qb: &Frame<T>) -> T {
        if self.torque.is_constant() {
            -(qa[2] * self.torque.eval(0.0)[0])
        } else {
            T::cst(0.0)
        }
    }
    fn is_nonconservative(&self) -> bool {
        !self.torque.is_constant()
    }
    fn nonconservative(&self, _s: &LocalState, t: f64, out: &mut [f64; 6]) {
        if !self.torque.is_constant() {
            out[2] += self.torque.eval(t)[0];
        }
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [None, None]
    }
    fn rotation_use(&self) -> Option<&'static str> {
        Some("torque")
    }
    fn validate(&self, element: &str) -> Result<(), ModelError> {
        check::time_function(element, "torque", &self.torque)
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec {
        ForceSpec::Torque(TorqueSpec {
            name,
            body: name_of(self.body),
            torque: self.torque.clone(),
        })
    }
}

/// An applied torque in a model file (see [`Torque`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TorqueSpec {
    /// Unique element name.
    pub name: String,
    /// The loaded body.
    pub body: String,
    /// The torque, N m, as a function of time.
    pub torque: TimeFunction,
}

impl TorqueSpec {
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Force, ModelError> {
        let element = format!("force '{}'", self.name);
        let kind = Torque {
            body: find(&element, &self.body)?,
            torque: self.torque.clone(),
        };
        Ok(Force::new(self.name.clone(), ForceKind::Torque(kind)))
    }
}

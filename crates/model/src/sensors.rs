//! Sensors: quantities a model names for its output, beside the state (`mbd run`'s columns,
//! `mbd_solve::SensorSolver`). Part of the model (as in Exudyn and MuJoCo) so that a model file
//! says what to measure.

use crate::body::BodyRef;
use crate::check::invalid;
use crate::error::ModelError;
use crate::system::JointHandle;
use serde::{Deserialize, Serialize};

/// A measured quantity (see each kind for its output columns).
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// Unique sensor name: the prefix of its columns (`tip.x`, ...).
    pub name: String,
    /// What it measures.
    pub kind: SensorKind,
}

/// What a [`Sensor`] measures.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SensorKind {
    /// A body-fixed point (body frame, relative to the centre of mass; for a body with a frame
    /// offset, in that frame like every local point): its position, velocity and acceleration in
    /// global axes, columns `NAME.x`, `.y`, `.vx`, `.vy`, `.ax`, `.ay`.
    Point {
        /// The body (ground gives a fixed point).
        body: BodyRef,
        /// The point.
        point: [f64; 2],
    },
    /// A joint's relative coordinates: the angle of its second body relative to its first and
    /// its rate, columns `NAME.angle`, `.rate`; for a prismatic joint also the slide along its
    /// axis between its two points and its rate, `NAME.s`, `.ds`.
    Joint {
        /// The joint.
        joint: JointHandle,
    },
}

impl Sensor {
    /// A point sensor (see [`SensorKind::Point`]).
    pub fn point(name: impl Into<String>, body: impl Into<BodyRef>, point: [f64; 2]) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::Point {
                body: body.into(),
                point,
            },
        }
    }

    /// A joint sensor (see [`SensorKind::Joint`]).
    pub fn joint(name: impl Into<String>, joint: JointHandle) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::Joint { joint },
        }
    }

    pub(crate) fn validate(&self) -> Result<(), ModelError> {
        if let SensorKind::Point { point, .. } = &self.kind {
            if !(point[0].is_finite() && point[1].is_finite()) {
                return Err(invalid(
                    format!("sensor '{}'", self.name),
                    format!("point {point:?} must be finite"),
                ));
            }
        }
        Ok(())
    }
}

/// A sensor in a model file (bodies and joints by name), tagged by `type`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SensorSpec {
    /// A body-fixed point: position, velocity and acceleration (columns `NAME.x`, `.y`, `.vx`,
    /// `.vy`, `.ax`, `.ay`).
    Point {
        /// Unique sensor name.
        name: String,
        /// The body.
        body: String,
        /// The point on it (body frame), m.
        #[serde(default)]
        point: [f64; 2],
    },
    /// A joint's relative angle and rate (`NAME.angle`, `.rate`; a prismatic joint adds its
    /// slide `NAME.s`, `.ds`).
    Joint {
        /// Unique sensor name.
        name: String,
        /// The joint.
        joint: String,
    },
}

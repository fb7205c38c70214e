//! Model files: the same model as the builder, in JSON or TOML (serde). Bodies are referred to by
//! name; `"ground"` is the fixed frame.
//!
//! ```toml
//! gravity = [0.0, -9.81]
//!
//! [[bodies]]
//! name = "rod"
//! mass = 1.0
//! inertia = 0.083333333333
//! position = [0.0, -0.5, -1.5707963267948966]
//!
//! [[joints]]
//! type = "revolute"
//! name = "pivot"
//! body_a = "ground"
//! point_a = [0.0, 0.0]
//! body_b = "rod"
//! point_b = [-0.5, 0.0]
//! ```

use crate::body::{Body, BodyHandle, BodyRef};
use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::force::{Force, ForceKind};
use crate::joint::{Coordinate, Joint, JointKind};
use crate::system::System;
use crate::timefn::TimeFunction;
use serde::{Deserialize, Serialize};

/// A whole model as stored in a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Gravity vector (default zero).
    #[serde(default)]
    pub gravity: [f64; 2],
    /// The bodies.
    pub bodies: Vec<Body>,
    /// The joints.
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    /// The force elements.
    #[serde(default)]
    pub forces: Vec<ForceSpec>,
}

/// A joint in a model file (bodies by name).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
#[allow(missing_docs)]
pub enum JointSpec {
    /// See [`JointKind::Revolute`].
    Revolute {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
    },
    /// See [`JointKind::Prismatic`].
    Prismatic {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        axis: [f64; 2],
        #[serde(default)]
        angle: f64,
    },
    /// See [`JointKind::Weld`].
    Weld {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        #[serde(default)]
        angle: f64,
    },
    /// See [`JointKind::Distance`].
    Distance {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        length: f64,
    },
    /// See [`JointKind::Absolute`].
    Absolute {
        name: String,
        body: String,
        #[serde(default)]
        point: [f64; 2],
        coordinate: Coordinate,
        value: f64,
    },
    /// See [`JointKind::AngleDriver`].
    AngleDriver {
        name: String,
        body_a: String,
        body_b: String,
        f: TimeFunction,
    },
}

/// A force element in a model file (bodies by name).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
#[allow(missing_docs)]
pub enum ForceSpec {
    /// See [`ForceKind::SpringDamper`].
    SpringDamper {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        rest_length: f64,
    },
    /// See [`ForceKind::RotarySpringDamper`].
    RotarySpringDamper {
        name: String,
        body_a: String,
        body_b: String,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        #[serde(default)]
        rest_angle: f64,
    },
    /// See [`ForceKind::Force`].
    Force {
        name: String,
        body: String,
        #[serde(default)]
        point: [f64; 2],
        fx: TimeFunction,
        fy: TimeFunction,
    },
    /// See [`ForceKind::Torque`].
    Torque {
        name: String,
        body: String,
        torque: TimeFunction,
    },
}

impl ModelFile {
    /// Parses JSON.
    pub fn from_json(s: &str) -> Result<Self, ModelError> {
        serde_json::from_str(s).map_err(|e| ModelError::Parse {
            format: "json",
            message: e.to_string(),
        })
    }
    /// Parses TOML.
    pub fn from_toml(s: &str) -> Result<Self, ModelError> {
        toml::from_str(s).map_err(|e| ModelError::Parse {
            format: "toml",
            message: e.to_string(),
        })
    }
    /// Serialises to pretty JSON.
    pub fn to_json(&self) -> Result<String, ModelError> {
        serde_json::to_string_pretty(self).map_err(|e| ModelError::Parse {
            format: "json",
            message: e.to_string(),
        })
    }
    /// Serialises to TOML.
    pub fn to_toml(&self) -> Result<String, ModelError> {
        toml::to_string(self).map_err(|e| ModelError::Parse {
            format: "toml",
            message: e.to_string(),
        })
    }

    /// Resolves body names into a builder (errors name the element and the unknown body).
    pub fn to_builder(&self) -> Result<SystemBuilder, ModelError> {
        let mut b = SystemBuilder::new();
        b.set_gravity(self.gravity);
        for body in &self.bodies {
            b.add_body(body.clone());
        }
        let find = |element: &str, name: &str| -> Result<BodyRef, ModelError> {
            if name.eq_ignore_ascii_case("ground") {
                return Ok(BodyRef::Ground);
            }
            self.bodies
                .iter()
                .position(|x| x.name == name)
                .map(|i| BodyRef::Body(BodyHandle(i)))
                .ok_or_else(|| ModelError::UnknownBody {
                    element: element.to_string(),
                    body: name.to_string(),
                })
        };
        for j in &self.joints {
            let joint = match j {
                JointSpec::Revolute {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                } => Joint::revolute(
                    name.clone(),
                    find(&format!("joint '{name}'"), body_a)?,
                    *point_a,
                    find(&format!("joint '{name}'"), body_b)?,
                    *point_b,
                ),
                JointSpec::Prismatic {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    axis,
                    angle,
                } => Joint::prismatic(
                    name.clone(),
                    find(&format!("joint '{name}'"), body_a)?,
                    *point_a,
                    find(&format!("joint '{name}'"), body_b)?,
                    *point_b,
                    *axis,
                    *angle,
                ),
                JointSpec::Weld {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    angle,
                } => Joint::weld(
                    name.clone(),
                    find(&format!("joint '{name}'"), body_a)?,
                    *point_a,
                    find(&format!("joint '{name}'"), body_b)?,
                    *point_b,
                    *angle,
                ),
                JointSpec::Distance {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    length,
                } => Joint::distance(
                    name.clone(),
                    find(&format!("joint '{name}'"), body_a)?,
                    *point_a,
                    find(&format!("joint '{name}'"), body_b)?,
                    *point_b,
                    *length,
                ),
                JointSpec::Absolute {
                    name,
                    body,
                    point,
                    coordinate,
                    value,
                } => Joint::absolute(
                    name.clone(),
                    find(&format!("joint '{name}'"), body)?,
                    *point,
                    *coordinate,
                    *value,
                ),
                JointSpec::AngleDriver {
                    name,
                    body_a,
                    body_b,
                    f,
                } => Joint::angle_driver(
                    name.clone(),
                    find(&format!("joint '{name}'"), body_a)?,
                    find(&format!("joint '{name}'"), body_b)?,
                    f.clone(),
                ),
            };
            b.add_joint(joint);
        }
        for f in &self.forces {
            let force = match f {
                ForceSpec::SpringDamper {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    stiffness,
                    damping,
                    rest_length,
                } => Force::spring_damper(
                    name.clone(),
                    find(&format!("force '{name}'"), body_a)?,
                    *point_a,
                    find(&format!("force '{name}'"), body_b)?,
                    *point_b,
                    *stiffness,
                    *damping,
                    *rest_length,
                ),
                ForceSpec::RotarySpringDamper {
                    name,
                    body_a,
                    body_b,
                    stiffness,
                    damping,
                    rest_angle,
                } => Force::rotary_spring_damper(
                    name.clone(),
                    find(&format!("force '{name}'"), body_a)?,
                    find(&format!("force '{name}'"), body_b)?,
                    *stiffness,
                    *damping,
                    *rest_angle,
                ),
                ForceSpec::Force {
                    name,
                    body,
                    point,
                    fx,
                    fy,
                } => Force::force(
                    name.clone(),
                    find(&format!("force '{name}'"), body)?,
                    *point,
                    fx.clone(),
                    fy.clone(),
                ),
                ForceSpec::Torque { name, body, torque } => Force::torque(
                    name.clone(),
                    find(&format!("force '{name}'"), body)?,
                    torque.clone(),
                ),
            };
            b.add_force(force);
        }
        Ok(b)
    }

    /// Resolves and validates into a [`System`].
    pub fn build(&self) -> Result<System, ModelError> {
        self.to_builder()?.build()
    }
}

impl System {
    /// Loads a model from a JSON string.
    pub fn from_json(s: &str) -> Result<System, ModelError> {
        ModelFile::from_json(s)?.build()
    }
    /// Loads a model from a TOML string.
    pub fn from_toml(s: &str) -> Result<System, ModelError> {
        ModelFile::from_toml(s)?.build()
    }
    /// Loads a model file, JSON or TOML by its extension (`.json`, `.toml`).
    pub fn from_path(path: impl AsRef<std::path::Path>) -> Result<System, ModelError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| ModelError::Parse {
            format: "io",
            message: format!("{}: {e}", path.display()),
        })?;
        match path.extension().and_then(|e| e.to_str()) {
            Some("json") => Self::from_json(&text),
            Some("toml") => Self::from_toml(&text),
            _ => Err(ModelError::Parse {
                format: "io",
                message: format!("{}: unknown extension (use .json or .toml)", path.display()),
            }),
        }
    }

    /// The model as a file description (bodies by name).
    pub fn to_model_file(&self) -> ModelFile {
        let name = |r: BodyRef| -> String {
            match r {
                BodyRef::Ground => "ground".to_string(),
                BodyRef::Body(h) => self.bodies[h.0].name.clone(),
            }
        };
        let joints = self
            .joints
            .iter()
            .map(|j| {
                let n = j.name.clone();
                match &j.kind {
                    JointKind::Revolute { a, pa, b, pb } => JointSpec::Revolute {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                    },
                    JointKind::Prismatic {
                        a,
                        pa,
                        b,
                        pb,
                        axis,
                        angle,
                    } => JointSpec::Prismatic {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        axis: *axis,
                        angle: *angle,
                    },
                    JointKind::Weld {
                        a,
                        pa,
                        b,
                        pb,
                        angle,
                    } => JointSpec::Weld {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        angle: *angle,
                    },
                    JointKind::Distance {
                        a,
                        pa,
                        b,
                        pb,
                        length,
                    } => JointSpec::Distance {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        length: *length,
                    },
                    JointKind::Absolute {
                        body,
                        point,
                        coordinate,
                        value,
                    } => JointSpec::Absolute {
                        name: n,
                        body: name(*body),
                        point: *point,
                        coordinate: *coordinate,
                        value: *value,
                    },
                    JointKind::AngleDriver { a, b, f } => JointSpec::AngleDriver {
                        name: n,
                        body_a: name(*a),
                        body_b: name(*b),
                        f: f.clone(),
                    },
                }
            })
            .collect();
        let forces = self
            .forces
            .iter()
            .map(|f| {
                let n = f.name.clone();
                match &f.kind {
                    ForceKind::SpringDamper {
                        a,
                        pa,
                        b,
                        pb,
                        stiffness,
                        damping,
                        rest_length,
                    } => ForceSpec::SpringDamper {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        stiffness: *stiffness,
                        damping: *damping,
                        rest_length: *rest_length,
                    },
                    ForceKind::RotarySpringDamper {
                        a,
                        b,
                        stiffness,
                        damping,
                        rest_angle,
                    } => ForceSpec::RotarySpringDamper {
                        name: n,
                        body_a: name(*a),
                        body_b: name(*b),
                        stiffness: *stiffness,
                        damping: *damping,
                        rest_angle: *rest_angle,
                    },
                    ForceKind::Force {
                        body,
                        point,
                        fx,
                        fy,
                    } => ForceSpec::Force {
                        name: n,
                        body: name(*body),
                        point: *point,
                        fx: fx.clone(),
                        fy: fy.clone(),
                    },
                    ForceKind::Torque { body, torque } => ForceSpec::Torque {
                        name: n,
                        body: name(*body),
                        torque: torque.clone(),
                    },
                }
            })
            .collect();
        ModelFile {
            gravity: self.gravity,
            bodies: self.bodies.clone(),
            joints,
            forces,
        }
    }
}

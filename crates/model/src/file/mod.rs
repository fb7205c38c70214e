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

mod resolve;
mod spatial;
mod spatial_forces;
mod spec;

pub use spatial::{
    EulerSpec, OrientationSpec, SpatialBodyKind, SpatialBodySpec, SpatialJointSpec,
    SpatialJointType,
};
pub use spatial_forces::{
    SpatialForceSpec, SpatialPointForceSpec, SpatialSpringDamperSpec, SpatialTorqueSpec,
};
pub use spec::{BodyKind, BodySpec, ForceSpec, InitialInput, JointSpec};

use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::init::RedundantConstraints;
use crate::system::System;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A whole model as stored in a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Gravity vector `[gx, gy]`, m/s^2 (default zero).
    #[serde(default)]
    pub gravity: [f64; 2],
    /// The (planar) bodies.
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    /// The joints.
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    /// The force elements.
    #[serde(default)]
    pub forces: Vec<ForceSpec>,
    /// The sensors: quantities written beside the state by `mbd run` (points on bodies, joint
    /// coordinates).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<crate::sensors::SensorSpec>,
    /// Initial joint coordinates: revolute angles and prismatic slides (and rates) from which
    /// the initial state is assembled and which it keeps.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub assembly: Vec<crate::JointInitialSpec>,
    /// What to do with constraint equations that are combinations of others at the initial
    /// configuration: `"allow"` (default: the model runs, `mbd check` names them) or
    /// `"reject"` (an error).
    #[serde(default, skip_serializing_if = "is_allow")]
    pub redundant_constraints: RedundantConstraints,
    /// Gravity of the spatial bodies `[gx, gy, gz]`, m/s^2 (default zero).
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub spatial_gravity: [f64; 3],
    /// Spatial (3D) rigid bodies (docs/spatial.md).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spatial_bodies: Vec<SpatialBodySpec>,
    /// Joints between spatial bodies.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spatial_joints: Vec<SpatialJointSpec>,
    /// Force elements on spatial bodies: spring-dampers, forces and torques.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spatial_forces: Vec<SpatialForceSpec>,
}

fn is_zero3(g: &[f64; 3]) -> bool {
    *g == [0.0; 3]
}

fn is_allow(r: &RedundantConstraints) -> bool {
    *r == RedundantConstraints::Allow
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

    /// Resolves body names into a builder (errors name the element and the unknown body):
    /// converts body-frame points and poses to the centre of mass, and turns each point mass
    /// into a body with a nominal inertia `m l^2` plus an `absolute` angle joint
    /// `<name>:point_mass` holding its angle at 0 (see `docs/model-files.md`).
    pub fn to_builder(&self) -> Result<SystemBuilder, ModelError> {
        self.to_builder_impl(&crate::forces::ForceLaws::new())
    }

    /// [`ModelFile::to_builder`] for files whose `custom` force elements name laws registered
    /// in `laws`.
    pub fn to_builder_with(
        &self,
        laws: &crate::forces::ForceLaws,
    ) -> Result<SystemBuilder, ModelError> {
        self.to_builder_impl(laws)
    }

    /// The JSON Schema (draft 2020-12) of model files, generated from these types; checked in
    /// as `schema/model.schema.json`.
    pub fn json_schema() -> String {
        let schema = schemars::schema_for!(ModelFile);
        let mut s = serde_json::to_string_pretty(&schema).unwrap_or_default();
        s.push('\n');
        s
    }

    /// Resolves and validates into a [`System`].
    pub fn build(&self) -> Result<System, ModelError> {
        self.to_builder()?.build()
    }

    /// Resolves and validates into a [`System`], building `custom` force elements from the
    /// laws registered in `laws`.
    pub fn build_with(&self, laws: &crate::forces::ForceLaws) -> Result<System, ModelError> {
        self.to_builder_with(laws)?.build()
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
    /// Loads a model file, JSON or TOML by its extension (`.json`, `.toml`); table files
    /// named in it are read relative to its directory.
    pub fn from_path(path: impl AsRef<std::path::Path>) -> Result<System, ModelError> {
        let path = path.as_ref();
        let text = read_text(path, MAX_MODEL_FILE_BYTES).map_err(|e| ModelError::Parse {
            format: "io",
            message: format!("{}: {e}", path.display()),
        })?;
        ModelFile::from_text_at(&text, path)?.build()
    }
}

impl ModelFile {
    /// Parses the text of the model file at `path`, JSON or TOML by the path's extension;
    /// the CSV files of tabulated time functions (`file = "..."`) are read relative to the
    /// path's directory. ([`ModelFile::from_json`] and [`ModelFile::from_toml`] read them
    /// relative to the working directory.)
    pub fn from_text_at(text: &str, path: &std::path::Path) -> Result<ModelFile, ModelError> {
        let dir = path.parent();
        crate::timefn::with_base_dir(dir, || match path.extension().and_then(|e| e.to_str()) {
            Some("json") => ModelFile::from_json(text),
            Some("toml") => ModelFile::from_toml(text),
            _ => Err(ModelError::Parse {
                format: "io",
                message: format!("{}: unknown extension (use .json or .toml)", path.display()),
            }),
        })
    }
}

/// The largest model file read ([`System::from_path`], `mbd check`, `mbd run`): far above any
/// real model (a 10,000-link chain's TOML is about 3 MB), and a device such as `/dev/zero` is
/// refused instead of read forever.
pub const MAX_MODEL_FILE_BYTES: u64 = 64 << 20;

/// Reads a text file of at most `limit` bytes; a longer one (or an endless device) is an
/// [`std::io::ErrorKind::InvalidData`] error saying so, after reading `limit + 1` bytes.
///
/// ```
/// let dir = std::env::temp_dir().join("mbd-read-text-doc");
/// std::fs::create_dir_all(&dir)?;
/// let p = dir.join("m.toml");
/// std::fs::write(&p, "gravity = [0.0, -9.81]")?;
/// assert_eq!(mbd_model::read_text(&p, 100)?, "gravity = [0.0, -9.81]");
/// let e = mbd_model::read_text(&p, 10).unwrap_err();
/// assert!(e.to_string().contains("more than 10 bytes"));
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn read_text(path: &std::path::Path, limit: u64) -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("the file has more than {limit} bytes (is it the right file?)"),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text: {e}"),
        )
    })
}

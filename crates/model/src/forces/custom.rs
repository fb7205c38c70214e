//! Force laws written by library users in their own crates: the [`ForceLaw`] trait, the
//! element that carries one ([`CustomForce`]), and the [`ForceLaws`] registry through which a
//! model file names them (`type = "custom"`, `law = "..."`).

use super::{Force, ForceKind, ForceType, LocalState};
use crate::body::BodyRef;
use crate::element::Anchor;
use crate::error::ModelError;
use crate::file::ForceSpec;
use crate::jet::{Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

/// What a force law sees: the coordinates `(x, y, theta)` of its two bodies' centre-of-mass
/// frames, their velocities, and the time. A ground side reads zeros.
#[derive(Clone, Copy, Debug)]
pub struct ForceInput<'a> {
    /// Coordinates of body a.
    pub qa: &'a [f64; 3],
    /// Coordinates of body b.
    pub qb: &'a [f64; 3],
    /// Velocities of body a.
    pub va: &'a [f64; 3],
    /// Velocities of body b.
    pub vb: &'a [f64; 3],
    /// Time.
    pub t: f64,
}

/// A force law implemented outside this crate: generalised forces from the coordinates,
/// velocities and time of two bodies.
///
/// The law enters the equations of motion as a non-conservative generalised force (it has no
/// potential here even if it is a spring), so models with one are not conservative: the
/// modified-Lagrangian schemes refuse them, `e(H)` is not reported, and the energy balance
/// counts its power as external work or, for a law that says it is [dissipative], as
/// dissipation.
///
/// [dissipative]: ForceLaw::dissipative
///
/// ```
/// use mbd_model::forces::{ForceInput, ForceLaw};
/// use mbd_model::{Body, BodyRef, Force, SystemBuilder};
/// use std::sync::Arc;
///
/// /// Quadratic air drag on a body's centre of mass: F = -c |v| v.
/// #[derive(Debug)]
/// struct Drag { c: f64 }
/// impl ForceLaw for Drag {
///     fn law(&self) -> &str { "drag" }
///     fn force(&self, x: &ForceInput, out: &mut [f64; 6]) {
///         let speed = x.va[0].hypot(x.va[1]);
///         out[0] -= self.c * speed * x.va[0];
///         out[1] -= self.c * speed * x.va[1];
///     }
///     fn dissipative(&self) -> bool { true }
/// }
///
/// let mut b = SystemBuilder::new();
/// let ball = b.add_body(Body::new("ball").mass(1.0).inertia(0.01).velocity(3.0, 4.0, 0.0));
/// b.add_force(Force::custom("air", ball, BodyRef::Ground, Arc::new(Drag { c: 0.5 })));
/// let sys = b.build()?;
/// let (q, v) = (vec![0.0, 0.0, 0.0], vec![3.0, 4.0, 0.0]);
/// let mut f = vec![0.0; 3];
/// sys.nonconservative_forces(&q, &v, 0.0, &mut f);
/// assert_eq!(f, [-7.5, -10.0, 0.0]);
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub trait ForceLaw: fmt::Debug + Send + Sync {
    /// The law's name (the model file's `law`, messages).
    fn law(&self) -> &str;

    /// Adds the generalised force into `out`: force `(fx, fy)` in global axes at the centre
    /// of mass and moment on body a, then the same for body b. Entries of a ground side are
    /// ignored.
    fn force(&self, x: &ForceInput, out: &mut [f64; 6]);

    /// The Jacobians of [`force`](ForceLaw::force): `dq[i][j] = d out[i] / d (qa, qb)[j]` and
    /// `dv[i][j] = d out[i] / d (va, vb)[j]`, both overwritten. Return `false` (the default)
    /// when the law has none: the implicit solvers then take central differences of `force`.
    fn jacobian(&self, x: &ForceInput, dq: &mut [[f64; 6]; 6], dv: &mut [[f64; 6]; 6]) -> bool {
        let _ = (x, dq, dv);
        false
    }

    /// Whether the law only takes energy out (a damper, friction): its power is counted as
    /// dissipation in the energy balance, else as external work (the default).
    fn dissipative(&self) -> bool {
        false
    }

    /// Checks the law's parameters; the message is reported after the element's name.
    fn validate(&self) -> Result<(), String> {
        Ok(())
    }

    /// The parameters written into a model file (`parameters = {...}`) and given back to the
    /// law's factory in [`ForceLaws`] when the file is loaded; `null` (the default) writes
    /// none.
    fn parameters(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
}

/// A force element whose law is a [`ForceLaw`].
#[derive(Clone, Debug)]
pub struct CustomForce {
    /// First body.
    pub a: BodyRef,
    /// Second body (`BodyRef::Ground` for a law acting on one body).
    pub b: BodyRef,
    /// The law.
    pub law: Arc<dyn ForceLaw>,
}

impl PartialEq for CustomForce {
    /// Equal when both sides are the same bodies and the law is the same object.
    fn eq(&self, other: &Self) -> bool {
        self.a == other.a && self.b == other.b && Arc::ptr_eq(&self.law, &other.law)
    }
}

impl CustomForce {
    fn input<'a>(s: &'a LocalState, t: f64) -> ForceInput<'a> {
        ForceInput {
            qa: s.qa,
            qb: s.qb,
            va: s.va,
            vb: s.vb,
            t,
        }
    }

    /// The law's own Jacobians, if it has them (see [`ForceLaw::jacobian`]).
    pub(crate) fn analytic_jacobian(
        &self,
        s: &LocalState,
        t: f64,
        dq: &mut [[f64; 6]; 6],
        dv: &mut [[f64; 6]; 6],
    ) -> bool {
        self.law.jacobian(&Self::input(s, t), dq, dv)
    }
}

impl ForceType for CustomForce {
    const KIND: &'static str = "custom";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    fn potential<T: Scalar>(&self, _qa: &Frame<T>, _qb: &Frame<T>) -> T {
        T::cst(0.0)
    }
    fn is_nonconservative(&self) -> bool {
        true
    }
    fn dissipative(&self) -> bool {
        self.law.dissipative()
    }
    fn nonconservative(&self, s: &LocalState, t: f64, out: &mut [f64; 6]) {
        self.law.force(&Self::input(s, t), out);
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [None, None]
    }
    fn validate(&self, element: &str) -> Result<(), ModelError> {
        self.law
            .validate()
            .map_err(|message| ModelError::InvalidElement {
                element: format!("force '{element}' (law '{}')", self.law.law()),
                message,
            })
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec {
        ForceSpec::Custom(CustomForceSpec {
            name,
            law: self.law.law().to_string(),
            body_a: name_of(self.a),
            body_b: name_of(self.b),
            parameters: self.law.parameters(),
        })
    }
}

/// Builds a law from the parameters of a model file's entry; the message of an error is
/// reported after the element's name.
pub type ForceLawFactory =
    Arc<dyn Fn(&serde_json::Value) -> Result<Arc<dyn ForceLaw>, String> + Send + Sync>;

/// The force laws a model file may name, by law name: register each of your laws once, then
/// load files with [`ModelFile::build_with`](crate::ModelFile::build_with).
#[derive(Clone, Default)]
pub struct ForceLaws {
    factories: BTreeMap<String, ForceLawFactory>,
}

impl fmt::Debug for ForceLaws {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.factories.keys()).finish()
    }
}

impl ForceLaws {
    /// No laws.
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers `law` (the name files use); a second registration of one name is an error.
    pub fn register(
        &mut self,
        law: &str,
        factory: impl Fn(&serde_json::Value) -> Result<Arc<dyn ForceLaw>, String>
            + Send
            + Sync
            + 'static,
    ) -> Result<&mut Self, ModelError> {
        if self.factories.contains_key(law) {
            return Err(ModelError::DuplicateName {
                kind: "force law",
                name: law.to_string(),
            });
        }
        self.factories.insert(law.to_string(), Arc::new(factory));
        Ok(self)
    }

    /// The registered law names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.factories.keys().map(String::as_str)
    }

    /// The law of a file entry, built by its factory.
    fn build(&self, spec: &CustomForceSpec) -> Result<Arc<dyn ForceLaw>, ModelError> {
        let element = format!("force '{}'", spec.name);
        let factory = self.factories.get(&spec.law).ok_or_else(|| {
            let known: Vec<&str> = self.names().collect();
            ModelError::InvalidElement {
                element: element.clone(),
                message: if known.is_empty() {
                    format!(
                        "force law '{}' is not registered: custom laws live in Rust code; load \
                         the file with ModelFile::build_with and a ForceLaws that registers it",
                        spec.law
                    )
                } else {
                    format!(
                        "force law '{}' is not registered (registered: {})",
                        spec.law,
                        known.join(", ")
                    )
                },
            }
        })?;
        factory(&spec.parameters).map_err(|message| ModelError::InvalidElement {
            element: format!("{element} (law '{}')", spec.law),
            message,
        })
    }
}

/// A force element with a user's law in a model file (see [`ForceLaw`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CustomForceSpec {
    /// Unique element name.
    pub name: String,
    /// The law's registered name.
    pub law: String,
    /// First body.
    pub body_a: String,
    /// Second body (default `ground`).
    #[serde(default = "ground")]
    pub body_b: String,
    /// The law's parameters, handed to its factory as they are.
    #[serde(default, skip_serializing_if = "serde_json::Value::is_null")]
    pub parameters: serde_json::Value,
}

fn ground() -> String {
    "ground".to_string()
}

impl CustomForceSpec {
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
        laws: &ForceLaws,
    ) -> Result<Force, ModelError> {
        let element = format!("force '{}'", self.name);
        let kind = CustomForce {
            a: find(&element, &self.body_a)?,
            b: find(&element, &self.body_b)?,
            law: laws.build(self)?,
        };
        Ok(Force::new(self.name.clone(), ForceKind::Custom(kind)))
    }
}

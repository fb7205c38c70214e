//! Rigid bodies and handles.

use serde::{Deserialize, Serialize};

/// Handle of a body inside a [`crate::System`], given by [`crate::SystemBuilder::add_body`],
/// [`crate::System::body_handle`] or [`crate::System::body_handles`]. Opaque: it cannot be
/// made from a number, so a handle always comes from a model (one of another model with more
/// bodies is an error of `build`, naming the element).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BodyHandle(pub(crate) usize);

impl BodyHandle {
    /// The body's position in [`crate::System::bodies`] (insertion order); its coordinates
    /// are `q[3 * index..3 * index + 3]`.
    pub fn index(self) -> usize {
        self.0
    }
}

/// What a joint or force attaches to: the fixed ground frame or a body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum BodyRef {
    /// The inertial frame. Local points on ground are global points.
    Ground,
    /// A moving body.
    Body(BodyHandle),
}

impl From<BodyHandle> for BodyRef {
    fn from(h: BodyHandle) -> Self {
        BodyRef::Body(h)
    }
}

impl BodyRef {
    /// The body index, or `None` for ground.
    pub fn index(self) -> Option<usize> {
        match self {
            BodyRef::Ground => None,
            BodyRef::Body(h) => Some(h.0),
        }
    }
}

/// A planar rigid body: mass, centroidal moment of inertia, and an initial state (a guess that
/// `mbd_solve::consistent_state` projects onto the constraints).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Unique name.
    pub name: String,
    /// Mass (> 0).
    pub mass: f64,
    /// Moment of inertia about the centre of mass (> 0).
    pub inertia: f64,
    /// Initial `(x, y, theta)` of the centre of mass and body frame.
    #[serde(default)]
    pub position: [f64; 3],
    /// Initial `(xdot, ydot, thetadot)`.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Which of the initial coordinates and velocities are inputs: the consistent-state solve
    /// keeps them and solves for the others (default: none, every one may move).
    #[serde(default)]
    pub inputs: Inputs,
}

/// One of a body's three coordinates `(x, y, theta)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coord {
    /// The centre of mass's `x`.
    X,
    /// The centre of mass's `y`.
    Y,
    /// The rotation angle.
    Theta,
}

impl Coord {
    /// The offset of this coordinate in a body's block `(x, y, theta)`.
    pub fn offset(self) -> usize {
        match self {
            Coord::X => 0,
            Coord::Y => 1,
            Coord::Theta => 2,
        }
    }
    /// The name used in coordinate names and model files: `x`, `y`, `theta`.
    pub fn name(self) -> &'static str {
        ["x", "y", "theta"][self.offset()]
    }
}

/// Which of a body's initial coordinates (`position`) and velocities (`velocity`) are inputs,
/// in the order `(x, y, theta)`. Initial states are projected onto the constraints
/// (`mbd_solve::consistent_state`) with the smallest mass-weighted change; an input is not
/// changed at all, and the other coordinates take up the whole correction (an error names an
/// equation the inputs leave no free coordinate for).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inputs {
    /// Kept coordinates.
    #[serde(default)]
    pub position: [bool; 3],
    /// Kept velocities.
    #[serde(default)]
    pub velocity: [bool; 3],
}

impl Body {
    /// A body with the given name, unit mass and inertia, at the origin, at rest.
    pub fn new(name: impl Into<String>) -> Self {
        Body {
            name: name.into(),
            mass: 1.0,
            inertia: 1.0,
            position: [0.0; 3],
            velocity: [0.0; 3],
            inputs: Inputs::default(),
        }
    }
    /// Sets the mass.
    pub fn mass(mut self, m: f64) -> Self {
        self.mass = m;
        self
    }
    /// Sets the centroidal moment of inertia.
    pub fn inertia(mut self, j: f64) -> Self {
        self.inertia = j;
        self
    }
    /// A uniform slender rod of mass `m` and length `l` (inertia `m l^2 / 12`).
    pub fn rod(mut self, m: f64, l: f64) -> Self {
        self.mass = m;
        self.inertia = m * l * l / 12.0;
        self
    }
    /// Sets the initial position `(x, y, theta)`.
    pub fn position(mut self, x: f64, y: f64, theta: f64) -> Self {
        self.position = [x, y, theta];
        self
    }
    /// Sets the initial velocity `(xdot, ydot, thetadot)`.
    pub fn velocity(mut self, vx: f64, vy: f64, omega: f64) -> Self {
        self.velocity = [vx, vy, omega];
        self
    }
    /// Marks the initial value of coordinate `c` as an input (see [`Inputs`]).
    pub fn input_position(mut self, c: Coord) -> Self {
        self.inputs.position[c.offset()] = true;
        self
    }
    /// Marks the initial velocity of coordinate `c` as an input (see [`Inputs`]): e.g. a
    /// crank's `6 rad/s`, with the other bodies' velocities solved from the constraints.
    ///
    /// ```
    /// use mbd_model::{models::SliderCrankParams, Coord};
    /// let mut p = SliderCrankParams::default();
    /// p.speed = 6.0;
    /// let sys = mbd_model::models::slider_crank_with(&p)?;
    /// let crank = sys.body_handle("crank").unwrap();
    /// // the model's crank velocity is not an input unless marked
    /// assert!(!sys.bodies()[crank.index()].inputs.velocity[2]);
    /// let marked = sys.bodies()[crank.index()].clone().input_velocity(Coord::Theta);
    /// assert_eq!(marked.inputs.velocity, [false, false, true]);
    /// # Ok::<(), mbd_model::ModelError>(())
    /// ```
    pub fn input_velocity(mut self, c: Coord) -> Self {
        self.inputs.velocity[c.offset()] = true;
        self
    }
}

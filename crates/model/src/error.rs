//! The one error type of `mbd-model`.

use thiserror::Error;

/// Everything that can go wrong when building, loading or evaluating a model.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// An element refers to a body that does not exist.
    #[error("{element} refers to unknown body '{body}'")]
    UnknownBody {
        /// The joint or force that refers to it.
        element: String,
        /// The name (or handle) that could not be resolved.
        body: String,
    },
    /// A body's rotational inertia is negligible against its mass times the square of a lever
    /// arm: the constraint matrix would be singular in double precision.
    #[error(
        "body '{body}': inertia {inertia:e} is negligible against mass x lever arm^2 = \
         {mass:e} x {lever:e}^2 (joint '{joint}'), a ratio of {ratio:.1e} (limit 1e12): the \
         mass matrix's scale would make the constraint matrix singular in double precision; \
         give the body its real moment of inertia (a slender rod of mass m and length l has \
         m l^2 / 12)"
    )]
    NegligibleInertia {
        /// The body.
        body: String,
        /// Its inertia.
        inertia: f64,
        /// Its mass.
        mass: f64,
        /// The joint whose point is far from the centre of mass.
        joint: String,
        /// The distance of that point from the centre of mass.
        lever: f64,
        /// `mass * lever^2 / inertia`.
        ratio: f64,
    },
    /// The heaviest and the lightest body differ in mass beyond what double precision can
    /// hold in one constraint matrix ([`crate::MAX_MASS_RATIO`]).
    #[error(
        "body '{light}': mass {light_mass:e} is negligible against the mass {heavy_mass:e} of \
         body '{heavy}', a ratio of {ratio:.1e} (limit 1e12): the constraint matrix \
         Phi_q M^-1 Phi_q^T would be singular in double precision; give the bodies their real \
         masses (a part too light to matter can be left out, or welded to its neighbour)"
    )]
    MassRatio {
        /// The lightest body.
        light: String,
        /// Its mass.
        light_mass: f64,
        /// The heaviest body.
        heavy: String,
        /// Its mass.
        heavy_mass: f64,
        /// `heavy_mass / light_mass`.
        ratio: f64,
    },
    /// Two bodies, joints or forces share a name.
    #[error("duplicate {kind} name '{name}'")]
    DuplicateName {
        /// "body", "joint" or "force".
        kind: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A parameter is out of range or not finite.
    #[error("{element}: parameter '{parameter}' = {} is invalid: {reason}", num(*value))]
    InvalidParameter {
        /// The body, joint or force at fault.
        element: String,
        /// The parameter name.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A joint connects a body to itself (or ground to ground).
    #[error("joint '{joint}' attaches body '{body}' to itself")]
    SameBody {
        /// The joint.
        joint: String,
        /// The body named twice.
        body: String,
    },
    /// The constraint Jacobian is rank deficient.
    #[error("redundant constraints: equation {equation} is a combination of others; joints involved: {joints:?}")]
    Redundant {
        /// The first dependent constraint equation (by name).
        equation: String,
        /// The joints whose equations are linearly dependent.
        joints: Vec<String>,
    },
    /// A vector or matrix argument has the wrong size.
    #[error("{what}: expected length {expected}, got {got}")]
    Dimension {
        /// The argument.
        what: &'static str,
        /// Required size.
        expected: usize,
        /// Given size.
        got: usize,
    },
    /// The model has no moving body.
    #[error("the model has no bodies")]
    Empty,
    /// An element of a model file is inconsistent with the body it attaches to (e.g. a joint
    /// point off a point mass's centre) or misses a field its kind needs.
    #[error("{element}: {message}")]
    InvalidElement {
        /// The body, joint or force at fault, e.g. `joint 'pivot'`.
        element: String,
        /// What is wrong, naming the field and the body.
        message: String,
    },
    /// A spatial joint needs axes on a spatial point mass, which has none.
    #[error(
        "spatial joint '{joint}' ({kind}) needs axes on point mass '{point_mass}', which has \
         none: a point mass takes spherical, distance and distance_driver joints on either \
         side, and a slide_driver as its second body"
    )]
    PointMassJoint {
        /// The joint.
        joint: String,
        /// The joint's kind (its model-file `type`).
        kind: &'static str,
        /// The point mass.
        point_mass: String,
    },
    /// A joint marker, spring point or load point on a spatial point mass is off its
    /// position.
    #[error(
        "{element}: its point {point:?} on point mass '{point_mass}' must be zero (a point \
         mass has one point, its position)"
    )]
    PointMassOffset {
        /// The joint, force or sensor, e.g. `spatial joint 'rod'`.
        element: String,
        /// The point mass.
        point_mass: String,
        /// The point given (from the point mass's position).
        point: [f64; 3],
    },
    /// A load a spatial point mass cannot take: a torque or a load in body axes (it has no
    /// rotation and no axes).
    #[error("{element}: point mass '{point_mass}' takes no {what} (it has no rotation or axes)")]
    PointMassLoad {
        /// The force element or sensor.
        element: String,
        /// The point mass.
        point_mass: String,
        /// What it cannot take: `torque`, `body axes`, `angular velocity`.
        what: &'static str,
    },
    /// A model file could not be read or parsed.
    #[error("model file ({format}): {message}")]
    Parse {
        /// "json" or "toml" (or "io").
        format: &'static str,
        /// The parser's message.
        message: String,
    },
    /// A tabulated time function built in code is invalid.
    #[error(transparent)]
    Table(#[from] crate::timefn::TableError),
}

/// `x` as a reader wants it in a message: plain decimal between 1e-4 and 1e16 (and 0), else in
/// scientific notation (never 300 digits for `1e300`). The one number format of the messages of
/// every crate (`mbd_model::format_number`).
///
/// ```
/// use mbd_model::format_number;
/// assert_eq!(format_number(0.001), "0.001");
/// assert_eq!(format_number(1e300), "1e300");
/// assert_eq!(format_number(-1e-7), "-1e-7");
/// ```
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

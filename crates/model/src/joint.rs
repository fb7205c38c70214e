//! Joints: holonomic constraints between two bodies (or a body and ground).
//!
//! Every joint equation has the form `Phi_k(q, t) = g_k(q_a, q_b) - f_k(t)`: time enters only
//! additively, through the driver's function. So `Phi_q` does not depend on `t`, `Phi_qt = 0`,
//! `Phi_t = -f'(t)` and `Phi_tt = -f''(t)`.

use crate::body::BodyRef;
use crate::jet::{direction, dot, point, sub2, Frame, Scalar};
use crate::system::Attach;
use crate::timefn::TimeFunction;
use serde::{Deserialize, Serialize};

/// Which coordinate an [`JointKind::Absolute`] constraint fixes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Coordinate {
    /// Global x of the point.
    X,
    /// Global y of the point.
    Y,
    /// The body's rotation angle.
    Angle,
}

/// The kinds of joint, with their parameters. Local points are in the body frame (relative to
/// the centre of mass); on ground they are global points.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum JointKind {
    /// Pin: point `pa` on `a` coincides with point `pb` on `b` (2 equations).
    Revolute {
        /// First body.
        a: BodyRef,
        /// Point on `a`.
        pa: [f64; 2],
        /// Second body.
        b: BodyRef,
        /// Point on `b`.
        pb: [f64; 2],
    },
    /// Slider: point `pb` on `b` stays on the line through `pa` along `axis` (fixed in `a`), and the
    /// relative angle `theta_b - theta_a` stays `angle` (2 equations).
    Prismatic {
        /// First body (carries the axis).
        a: BodyRef,
        /// Point on `a` on the sliding line.
        pa: [f64; 2],
        /// Second body.
        b: BodyRef,
        /// Point on `b` that slides on the line.
        pb: [f64; 2],
        /// Direction of the line in `a`'s frame (any non-zero length; normalised at build).
        axis: [f64; 2],
        /// Relative angle kept fixed.
        angle: f64,
    },
    /// Rigid connection: points coincide and relative angle fixed (3 equations).
    Weld {
        /// First body.
        a: BodyRef,
        /// Point on `a`.
        pa: [f64; 2],
        /// Second body.
        b: BodyRef,
        /// Point on `b`.
        pb: [f64; 2],
        /// Relative angle `theta_b - theta_a`.
        angle: f64,
    },
    /// Massless rod: `|P_b - P_a| = length`, written as `(|d|^2 - L^2) / (2 L)` (1 equation).
    Distance {
        /// First body.
        a: BodyRef,
        /// Point on `a`.
        pa: [f64; 2],
        /// Second body.
        b: BodyRef,
        /// Point on `b`.
        pb: [f64; 2],
        /// Distance (> 0).
        length: f64,
    },
    /// One absolute coordinate of a body point (or the body angle) fixed (1 equation).
    Absolute {
        /// The body.
        body: BodyRef,
        /// Point on the body (ignored for [`Coordinate::Angle`]).
        point: [f64; 2],
        /// Which coordinate.
        coordinate: Coordinate,
        /// Its value.
        value: f64,
    },
    /// Rheonomic driver: `theta_b - theta_a = f(t)` (1 equation). With `a` = ground it drives an
    /// absolute angle.
    AngleDriver {
        /// Reference body.
        a: BodyRef,
        /// Driven body.
        b: BodyRef,
        /// The prescribed relative angle.
        f: TimeFunction,
    },
}

/// A named joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Unique name (used in error messages and equation names).
    pub name: String,
    /// Kind and parameters.
    pub kind: JointKind,
}

/// One side of a revolute joint's equations `point_a(pa) - point_b(pb)`: the body (`None`:
/// ground), its local slot (0 for body a, 3 for body b), the body-fixed point and the sign.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RevoluteSide {
    pub(crate) body: Option<usize>,
    pub(crate) slot: usize,
    pub(crate) p: [f64; 2],
    pub(crate) sign: f64,
}

impl Joint {
    /// The two sides of a revolute joint attached at `at`, `None` for any other kind: what
    /// the closed-form revolute rows of the derivative passes iterate over (a body point
    /// `r + R(theta) p` has the derivatives `R^(k)(theta) p` in `theta`, a quarter turn each).
    pub(crate) fn revolute_sides(&self, at: Attach) -> Option<[RevoluteSide; 2]> {
        match &self.kind {
            JointKind::Revolute { pa, pb, .. } => Some([
                RevoluteSide {
                    body: at.a,
                    slot: 0,
                    p: *pa,
                    sign: 1.0,
                },
                RevoluteSide {
                    body: at.b,
                    slot: 3,
                    p: *pb,
                    sign: -1.0,
                },
            ]),
            _ => None,
        }
    }
}

impl Joint {
    /// Revolute joint between `a` at `pa` and `b` at `pb`.
    pub fn revolute(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
    ) -> Self {
        Joint {
            name: name.into(),
            kind: JointKind::Revolute {
                a: a.into(),
                pa,
                b: b.into(),
                pb,
            },
        }
    }
    /// Prismatic joint: `pb` on `b` slides along `axis` through `pa` on `a`; relative angle fixed.
    pub fn prismatic(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        axis: [f64; 2],
        angle: f64,
    ) -> Self {
        Joint {
            name: name.into(),
            kind: JointKind::Prismatic {
                a: a.into(),
                pa,
                b: b.into(),
                pb,
                axis,
                angle,
            },
        }
    }
    /// Weld joint.
    pub fn weld(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        angle: f64,
    ) -> Self {
        Joint {
            name: name.into(),
            kind: JointKind::Weld {
                a: a.into(),
                pa,
                b: b.into(),
                pb,
                angle,
            },
        }
    }
    /// Distance constraint.
    pub fn distance(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        length: f64,
    ) -> Self {
        Joint {
            name: name.into(),
            kind: JointKind::Distance {
                a: a.into(),
                pa,
                b: b.into(),
                pb,
                length,
            },
        }
    }
    /// Absolute-coordinate constraint.
    pub fn absolute(
        name: impl Into<String>,
        body: impl Into<BodyRef>,
        point: [f64; 2],
        coordinate: Coordinate,
        value: f64,
    ) -> Self {
        Joint {
            name: name.into(),
            kind: JointKind::Absolute {
                body: body.into(),
                point,
                coordinate,
                value,
            },
        }
    }
    /// Relative-angle driver `theta_b - theta_a = f(t)`.
    pub fn angle_driver(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        b: impl Into<BodyRef>,
        f: TimeFunction,
    ) -> Self {
        Joint {
            name: name.into(),
            kind: JointKind::AngleDriver {
                a: a.into(),
                b: b.into(),
                f,
            },
        }
    }

    /// The two attachments `(a, b)` (for [`JointKind::Absolute`], `b` is ground).
    pub fn bodies(&self) -> (BodyRef, BodyRef) {
        match &self.kind {
            JointKind::Revolute { a, b, .. }
            | JointKind::Prismatic { a, b, .. }
            | JointKind::Weld { a, b, .. }
            | JointKind::Distance { a, b, .. }
            | JointKind::AngleDriver { a, b, .. } => (*a, *b),
            JointKind::Absolute { body, .. } => (*body, BodyRef::Ground),
        }
    }

    /// Number of scalar equations.
    pub fn n_equations(&self) -> usize {
        match &self.kind {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } => 2,
            JointKind::Weld { .. } => 3,
            JointKind::Distance { .. }
            | JointKind::Absolute { .. }
            | JointKind::AngleDriver { .. } => 1,
        }
    }

    /// Short labels of the equations, e.g. `["x", "y"]`.
    pub fn equation_labels(&self) -> &'static [&'static str] {
        match &self.kind {
            JointKind::Revolute { .. } => &["x", "y"],
            JointKind::Prismatic { .. } => &["normal", "angle"],
            JointKind::Weld { .. } => &["x", "y", "angle"],
            JointKind::Distance { .. } => &["length"],
            JointKind::Absolute { coordinate, .. } => match coordinate {
                Coordinate::X => &["x"],
                Coordinate::Y => &["y"],
                Coordinate::Angle => &["angle"],
            },
            JointKind::AngleDriver { .. } => &["angle"],
        }
    }

    /// The kind as a lower-case word.
    pub fn kind_name(&self) -> &'static str {
        match &self.kind {
            JointKind::Revolute { .. } => "revolute",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Weld { .. } => "weld",
            JointKind::Distance { .. } => "distance",
            JointKind::Absolute { .. } => "absolute",
            JointKind::AngleDriver { .. } => "angle_driver",
        }
    }

    /// Whether the joint depends explicitly on time.
    pub fn is_rheonomic(&self) -> bool {
        matches!(&self.kind, JointKind::AngleDriver { f, .. } if !f.is_constant())
    }

    /// `(f(t), f'(t), f''(t))` of equation `k`: the part subtracted from `g_k(q)`.
    pub(crate) fn time_part(&self, k: usize, t: f64) -> [f64; 3] {
        match &self.kind {
            JointKind::AngleDriver { f, .. } if k == 0 => f.eval(t),
            _ => [0.0; 3],
        }
    }

    /// The time-free part `g(q_a, q_b)` of the equations, written once for every scalar type.
    #[inline]
    pub(crate) fn eval<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>, out: &mut [T; 3]) {
        match &self.kind {
            JointKind::Revolute { pa, pb, .. } => {
                let d = sub2(point(qa, *pa), point(qb, *pb));
                out[0] = d[0];
                out[1] = d[1];
            }
            JointKind::Prismatic {
                pa,
                pb,
                axis,
                angle,
                ..
            } => {
                // normal to the axis in a's frame: R * axis
                let n = direction(qa, [-axis[1], axis[0]]);
                let d = sub2(point(qb, *pb), point(qa, *pa));
                out[0] = dot(n, d);
                out[1] = qb[2] - qa[2] - *angle;
            }
            JointKind::Weld { pa, pb, angle, .. } => {
                let d = sub2(point(qa, *pa), point(qb, *pb));
                out[0] = d[0];
                out[1] = d[1];
                out[2] = qb[2] - qa[2] - *angle;
            }
            JointKind::Distance { pa, pb, length, .. } => {
                let d = sub2(point(qb, *pb), point(qa, *pa));
                out[0] = (dot(d, d) - length * length) * (0.5 / length);
            }
            JointKind::Absolute {
                point: p,
                coordinate,
                value,
                ..
            } => {
                out[0] = match coordinate {
                    Coordinate::X => point(qa, *p)[0] - *value,
                    Coordinate::Y => point(qa, *p)[1] - *value,
                    Coordinate::Angle => qa[2] - *value,
                };
            }
            JointKind::AngleDriver { .. } => {
                out[0] = qb[2] - qa[2];
            }
        }
    }
}

//! Force elements. Gravity is a system-wide vector (see [`crate::SystemBuilder::gravity`]).
//!
//! Springs and constant loads are conservative and contribute to the potential `V(q)`; dampers
//! and time-dependent loads are non-conservative and enter only the generalized force.

use crate::body::BodyRef;
use crate::jet::{dot, point, sub2, Frame, Scalar};
use crate::timefn::TimeFunction;

/// The kinds of force element.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ForceKind {
    /// Linear point-to-point spring-damper: `V = k/2 (l - l0)^2`, damping force `c ldot` along
    /// the line.
    SpringDamper {
        /// First body.
        a: BodyRef,
        /// Point on `a`.
        pa: [f64; 2],
        /// Second body.
        b: BodyRef,
        /// Point on `b`.
        pb: [f64; 2],
        /// Stiffness (>= 0).
        stiffness: f64,
        /// Damping (>= 0).
        damping: f64,
        /// Rest length (>= 0).
        rest_length: f64,
    },
    /// Rotational spring-damper on the relative angle: `V = k/2 (theta_b - theta_a - angle0)^2`.
    RotarySpringDamper {
        /// First body.
        a: BodyRef,
        /// Second body.
        b: BodyRef,
        /// Stiffness (>= 0).
        stiffness: f64,
        /// Damping (>= 0).
        damping: f64,
        /// Rest relative angle.
        rest_angle: f64,
    },
    /// Force in global axes applied at a body point: `(fx(t), fy(t))`.
    Force {
        /// The body.
        body: BodyRef,
        /// Point of application (body frame).
        point: [f64; 2],
        /// Global x component.
        fx: TimeFunction,
        /// Global y component.
        fy: TimeFunction,
    },
    /// Torque `tau(t)` on a body.
    Torque {
        /// The body.
        body: BodyRef,
        /// The torque.
        torque: TimeFunction,
    },
}

/// A named force element.
#[derive(Clone, Debug, PartialEq)]
pub struct Force {
    /// Unique name.
    pub name: String,
    /// Kind and parameters.
    pub kind: ForceKind,
}

impl Force {
    /// Point-to-point spring-damper.
    #[allow(clippy::too_many_arguments)]
    pub fn spring_damper(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        pa: [f64; 2],
        b: impl Into<BodyRef>,
        pb: [f64; 2],
        stiffness: f64,
        damping: f64,
        rest_length: f64,
    ) -> Self {
        Force {
            name: name.into(),
            kind: ForceKind::SpringDamper {
                a: a.into(),
                pa,
                b: b.into(),
                pb,
                stiffness,
                damping,
                rest_length,
            },
        }
    }
    /// Rotational spring-damper on `theta_b - theta_a`.
    pub fn rotary_spring_damper(
        name: impl Into<String>,
        a: impl Into<BodyRef>,
        b: impl Into<BodyRef>,
        stiffness: f64,
        damping: f64,
        rest_angle: f64,
    ) -> Self {
        Force {
            name: name.into(),
            kind: ForceKind::RotarySpringDamper {
                a: a.into(),
                b: b.into(),
                stiffness,
                damping,
                rest_angle,
            },
        }
    }
    /// Applied force (global axes) at a body point.
    #[allow(clippy::self_named_constructors)] // `Force::force` next to `Force::torque`
    pub fn force(
        name: impl Into<String>,
        body: impl Into<BodyRef>,
        point: [f64; 2],
        fx: TimeFunction,
        fy: TimeFunction,
    ) -> Self {
        Force {
            name: name.into(),
            kind: ForceKind::Force {
                body: body.into(),
                point,
                fx,
                fy,
            },
        }
    }
    /// Applied torque.
    pub fn torque(name: impl Into<String>, body: impl Into<BodyRef>, torque: TimeFunction) -> Self {
        Force {
            name: name.into(),
            kind: ForceKind::Torque {
                body: body.into(),
                torque,
            },
        }
    }

    /// The two attachments (`b` is ground for single-body loads).
    pub fn bodies(&self) -> (BodyRef, BodyRef) {
        match &self.kind {
            ForceKind::SpringDamper { a, b, .. } | ForceKind::RotarySpringDamper { a, b, .. } => {
                (*a, *b)
            }
            ForceKind::Force { body, .. } | ForceKind::Torque { body, .. } => {
                (*body, BodyRef::Ground)
            }
        }
    }

    /// Whether the element has a non-conservative part (damping or a time-dependent load).
    pub fn is_nonconservative(&self) -> bool {
        match &self.kind {
            ForceKind::SpringDamper { damping, .. }
            | ForceKind::RotarySpringDamper { damping, .. } => *damping != 0.0,
            ForceKind::Force { fx, fy, .. } => !(fx.is_constant() && fy.is_constant()),
            ForceKind::Torque { torque, .. } => !torque.is_constant(),
        }
    }

    /// Potential energy of the conservative part, generic over the scalar type.
    #[inline]
    pub(crate) fn potential<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>) -> T {
        match &self.kind {
            ForceKind::SpringDamper {
                pa,
                pb,
                stiffness,
                rest_length,
                ..
            } => {
                let d = sub2(point(qb, *pb), point(qa, *pa));
                if *rest_length == 0.0 {
                    // k/2 |d|^2: the same energy, but smooth (no square root) where the
                    // attachment points coincide
                    return dot(d, d) * (0.5 * stiffness);
                }
                let e = dot(d, d).sqrt() - *rest_length;
                e * e * (0.5 * stiffness)
            }
            ForceKind::RotarySpringDamper {
                stiffness,
                rest_angle,
                ..
            } => {
                let e = qb[2] - qa[2] - *rest_angle;
                e * e * (0.5 * stiffness)
            }
            ForceKind::Force {
                point: p, fx, fy, ..
            } => {
                if fx.is_constant() && fy.is_constant() {
                    let r = point(qa, *p);
                    -(r[0] * fx.eval(0.0)[0] + r[1] * fy.eval(0.0)[0])
                } else {
                    T::cst(0.0)
                }
            }
            ForceKind::Torque { torque, .. } => {
                if torque.is_constant() {
                    -(qa[2] * torque.eval(0.0)[0])
                } else {
                    T::cst(0.0)
                }
            }
        }
    }

    /// Local generalized force of the non-conservative part, given local coordinates and
    /// velocities; added into `out` (6 entries: body a then body b).
    pub(crate) fn nonconservative(
        &self,
        qa: &[f64; 3],
        qb: &[f64; 3],
        va: &[f64; 3],
        vb: &[f64; 3],
        t: f64,
        out: &mut [f64; 6],
    ) {
        use crate::jet::DirJet;
        match &self.kind {
            ForceKind::SpringDamper {
                pa, pb, damping, ..
            } => {
                if *damping == 0.0 {
                    return;
                }
                let ja = Frame::new(std::array::from_fn(|i| DirJet::var(i, qa[i], va[i])));
                let jb = Frame::new(std::array::from_fn(|i| DirJet::var(i + 3, qb[i], vb[i])));
                let d = sub2(point(&jb, *pb), point(&ja, *pa));
                if dot(d, d).v == 0.0 {
                    // coincident points: the line of action is undefined and the bounded
                    // force has no limit; take zero instead of 0/0
                    return;
                }
                let l = dot(d, d).sqrt();
                // l.d1 = ldot; the force is -c ldot grad(l)
                let s = -damping * l.d1;
                for k in 0..6 {
                    out[k] += s * l.g[k];
                }
            }
            ForceKind::RotarySpringDamper { damping, .. } => {
                let tau = damping * (vb[2] - va[2]);
                out[2] += tau;
                out[5] -= tau;
            }
            ForceKind::Force {
                point: p, fx, fy, ..
            } => {
                if fx.is_constant() && fy.is_constant() {
                    return;
                }
                let f = [fx.eval(t)[0], fy.eval(t)[0]];
                let (sn, cs) = qa[2].sin_cos();
                // d r_P / d theta = B s = (-sin sx - cos sy, cos sx - sin sy)
                let dx = -sn * p[0] - cs * p[1];
                let dy = cs * p[0] - sn * p[1];
                out[0] += f[0];
                out[1] += f[1];
                out[2] += f[0] * dx + f[1] * dy;
            }
            ForceKind::Torque { torque, .. } => {
                if !torque.is_constant() {
                    out[2] += torque.eval(t)[0];
                }
            }
        }
    }
}

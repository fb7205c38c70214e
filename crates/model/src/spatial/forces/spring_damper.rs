//! A linear spring-damper between a point of each of two spatial bodies.

use super::SW;
use crate::check;
use crate::error::ModelError;
use crate::spatial::joints::{dot3, sub3, SpatialFrame};
use mbd_jet::{DirJetN, Scalar};

/// A spring-damper between `point_a` on the first body and `point_b` on the second (body
/// frames; ground: global), with tension `stiffness (l - rest_length) + damping l'` along the
/// line between them (`l` their distance).
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialSpringDamper {
    /// The point on the first body (m).
    pub point_a: [f64; 3],
    /// The point on the second body (m).
    pub point_b: [f64; 3],
    /// Stiffness (N/m), non-negative.
    pub stiffness: f64,
    /// Damping (N s/m), non-negative.
    pub damping: f64,
    /// Rest length (m), non-negative.
    pub rest_length: f64,
}

impl SpatialSpringDamper {
    /// `k/2 (l - L)^2`; with `L = 0` the same energy as `k/2 |d|^2`, smooth where the points
    /// meet.
    pub(crate) fn potential<T: Scalar>(&self, fa: &SpatialFrame<T>, fb: &SpatialFrame<T>) -> T {
        let d = sub3(fb.point(self.point_b), fa.point(self.point_a));
        if self.rest_length == 0.0 {
            return dot3(d, d) * (0.5 * self.stiffness);
        }
        let e = dot3(d, d).sqrt() - self.rest_length;
        e * e * (0.5 * self.stiffness)
    }

    /// Adds the damping force `-c l' grad l` (the jets carry the velocities as their
    /// direction, so `l.d1 = l'`).
    pub(crate) fn damping_force(
        &self,
        fa: &SpatialFrame<DirJetN<SW>>,
        fb: &SpatialFrame<DirJetN<SW>>,
        out: &mut [f64; SW],
    ) {
        if self.damping == 0.0 {
            return;
        }
        let d = sub3(fb.point(self.point_b), fa.point(self.point_a));
        let d2 = dot3(d, d);
        if d2.v == 0.0 {
            // coincident points: no line of action; the bounded force has no limit there
            return;
        }
        let l = d2.sqrt();
        let f = -self.damping * l.d1;
        for (o, g) in out.iter_mut().zip(&l.g) {
            *o += f * g;
        }
    }

    /// Checks the parameters; errors name `element` and the field.
    pub(crate) fn validate(&self, element: &str) -> Result<(), ModelError> {
        for &x in self.point_a.iter() {
            check::finite(element, "point_a", x)?;
        }
        for &x in self.point_b.iter() {
            check::finite(element, "point_b", x)?;
        }
        check::nonneg(element, "stiffness", self.stiffness)?;
        check::nonneg(element, "damping", self.damping)?;
        check::nonneg(element, "rest_length", self.rest_length)
    }
}

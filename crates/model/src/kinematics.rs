//! Positions and velocities of body-fixed points.

use crate::body::BodyHandle;
use crate::system::*;
use nalgebra::Vector2;

impl System {
    /// Global position of the point `local` (body frame) of `body`.
    pub fn point_position(&self, body: BodyHandle, local: [f64; 2], q: &[f64]) -> Vector2<f64> {
        let i = body.0;
        let (s, c) = q[3 * i + 2].sin_cos();
        Vector2::new(
            q[3 * i] + c * local[0] - s * local[1],
            q[3 * i + 1] + s * local[0] + c * local[1],
        )
    }

    /// Global velocity of the point `local` of `body`.
    pub fn point_velocity(
        &self,
        body: BodyHandle,
        local: [f64; 2],
        q: &[f64],
        v: &[f64],
    ) -> Vector2<f64> {
        let i = body.0;
        let (s, c) = q[3 * i + 2].sin_cos();
        let w = v[3 * i + 2];
        Vector2::new(
            v[3 * i] + w * (-s * local[0] - c * local[1]),
            v[3 * i + 1] + w * (c * local[0] - s * local[1]),
        )
    }
}

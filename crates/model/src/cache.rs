//! The one angle cache: `sin` and `cos` of every body's angle at a configuration, evaluated
//! once and shared by the element passes there, or brought to a nearby configuration by
//! rotation.

use crate::jet::{Frame, Scalar};
use crate::system::System;

/// The sine and cosine of every body's angle at one configuration `q`, evaluated once
/// ([`BodyAngles::update`]) and shared by all the element passes at that `q` (the `_at`
/// variants of the derivative passes of mbd-symplectic, and its `constraint_poly_series`):
/// they give bit for bit the results of the plain passes without one `sin_cos` per element
/// and body. Allocated once ([`BodyAngles::new`]); updating allocates nothing unless the
/// number of bodies changed.
///
/// The same table serves repeated evaluations at nearby configurations (Newton iterations):
/// [`BodyAngles::update_near`] rotates the stored values by each angle's increment `delta`
/// (`|delta| <=` [`BodyAngles::MAX_INCREMENT`], with `cos delta` and `sin delta` from their
/// Taylor series, exact to rounding there) instead of calling `sin_cos`, and evaluates exactly after
/// [`BodyAngles::MAX_ROTATIONS`] rotations, for a larger increment, or after
/// [`BodyAngles::invalidate`]. Rotated values differ from exact ones by a few units in the last
/// place; [`System::phi_and_phi_dot_cached`] uses them.
#[derive(Clone, Debug, Default)]
pub struct BodyAngles {
    /// Per body: `[theta, sin theta, cos theta]`.
    sc: Vec<[f64; 3]>,
    /// Per body: rotations since the last exact evaluation (used by `update_near` only).
    rotations: Vec<u32>,
    /// Whether the table holds values `update_near` may rotate from.
    valid: bool,
}

impl BodyAngles {
    /// The table for the bodies of `sys` at the configuration `q` (length `sys.n_coords()`).
    pub fn new(sys: &System, q: &[f64]) -> Self {
        let mut a = BodyAngles::default();
        a.update(sys, q);
        a
    }

    /// Evaluates `sin` and `cos` of every body angle of `sys` at `q` (length
    /// `sys.n_coords()`), in place.
    pub fn update(&mut self, sys: &System, q: &[f64]) {
        let nb = sys.bodies.len();
        // the planar bodies come first (spatial coordinates, if any, follow)
        debug_assert!(q.len() >= 3 * nb);
        self.resize(nb);
        for (i, e) in self.sc.iter_mut().enumerate() {
            let th = q[3 * i + 2];
            let (s, c) = th.sin_cos();
            *e = [th, s, c];
        }
        // (the rotation counts are left as they are: after an exact evaluation they can only
        // make `update_near` evaluate exactly sooner)
        self.valid = true;
    }

    /// An empty table sized for the bodies of `sys` (allocated here, so later updates allocate
    /// nothing); the first [`BodyAngles::update_near`] evaluates exactly.
    pub fn sized(sys: &System) -> Self {
        let nb = sys.bodies.len();
        BodyAngles {
            sc: vec![[0.0; 3]; nb],
            rotations: vec![0; nb],
            valid: false,
        }
    }

    /// Rotations allowed between two exact evaluations of one body's `sin_cos` in
    /// [`BodyAngles::update_near`].
    pub const MAX_ROTATIONS: u32 = 8;

    /// Largest angle increment rotated rather than evaluated exactly by
    /// [`BodyAngles::update_near`]: its series for `sin` and `cos` are exact to rounding up to
    /// here.
    pub const MAX_INCREMENT: f64 = 1e-3;

    /// Brings the table to the configuration `q` from the one it holds: each angle that moved
    /// by at most [`BodyAngles::MAX_INCREMENT`] has its `sin`/`cos` rotated by the increment
    /// (at most [`BodyAngles::MAX_ROTATIONS`] times in a row), the others are evaluated
    /// exactly. For `|d| <= 1e-3` the truncated series `cos d = 1 - d^2/2 + d^4/24`,
    /// `sin d = d - d^3/6 + d^5/120` are exact to rounding (the next terms are below 1.4e-21).
    pub fn update_near(&mut self, sys: &System, q: &[f64]) {
        let nb = sys.bodies.len();
        // the planar bodies come first (spatial coordinates, if any, follow)
        debug_assert!(q.len() >= 3 * nb);
        if self.sc.len() != nb {
            self.resize(nb);
            self.valid = false;
        }
        let valid = self.valid;
        // (the coordinates by body: no index checks in the loop)
        let bodies = q[..3 * nb].chunks_exact(3);
        for ((e, r), qi) in self.sc.iter_mut().zip(&mut self.rotations).zip(bodies) {
            let theta = qi[2];
            let d = theta - e[0];
            if valid && d.abs() <= Self::MAX_INCREMENT && *r < Self::MAX_ROTATIONS {
                if d != 0.0 {
                    let d2 = d * d;
                    let cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0));
                    let sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)));
                    let (s, c) = (e[1], e[2]);
                    *e = [theta, s * cd + c * sd, c * cd - s * sd];
                    *r += 1;
                }
            } else {
                let (s, c) = theta.sin_cos();
                *e = [theta, s, c];
                *r = 0;
            }
        }
        self.valid = true;
    }

    /// Forgets the stored values: the next [`BodyAngles::update_near`] evaluates `sin_cos`
    /// exactly.
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    fn resize(&mut self, nb: usize) {
        if self.sc.len() != nb {
            self.sc.resize(nb, [0.0; 3]);
            self.rotations.resize(nb, 0);
        }
    }

    /// Whether the table holds the angles of `q` (the `_at` passes check it in debug builds):
    /// those of its planar bodies, whose coordinates come first (spatial ones may follow).
    pub fn matches(&self, q: &[f64]) -> bool {
        q.len() >= 3 * self.sc.len()
            && self
                .sc
                .iter()
                .enumerate()
                .all(|(i, e)| e[0].to_bits() == q[3 * i + 2].to_bits())
    }

    /// `R(theta_i) p`: the body-fixed vector `p` of body `i` in global axes, with `sin`/`cos`
    /// of its angle from the table or, without one, evaluated (the closed-form revolute rows of
    /// the derivative passes start from it; `R'(theta) p` is its quarter turn `(-y, x)`).
    #[inline(always)]
    pub fn rotate(angles: Option<&Self>, q: &[f64], i: usize, p: [f64; 2]) -> [f64; 2] {
        let (sn, cs) = match angles {
            Some(a) => (a.sc[i][1], a.sc[i][2]),
            None => q[3 * i + 2].sin_cos(),
        };
        [cs * p[0] - sn * p[1], sn * p[0] + cs * p[1]]
    }

    /// `[theta, sin theta, cos theta]` of body `i`.
    #[inline(always)]
    pub fn sin_cos_of(&self, i: usize) -> [f64; 3] {
        self.sc[i]
    }

    /// The frame of body `i` with the jet coordinates `vars` (whose angle has the value of
    /// body `i`'s angle in the table), or with `sin_cos` evaluated when there is no table.
    #[inline(always)]
    pub fn frame<T: Scalar>(angles: Option<&Self>, i: usize, vars: [T; 3]) -> Frame<T> {
        match angles {
            Some(a) => {
                let [_, s, c] = a.sc[i];
                Frame::with_sin_cos(vars, s, c)
            }
            None => Frame::new(vars),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::BodyAngles;
    use crate::models;

    /// Rotated values stay within a few units in the last place of `sin_cos` for increments
    /// up to `MAX_INCREMENT` over `MAX_ROTATIONS` rotations in a row, and a larger increment or
    /// the rotation cap falls back to the exact values, bit for bit.
    #[test]
    fn rotations_track_sin_cos_to_rounding_and_fall_back_exactly() {
        let sys = models::manipulator().expect("model");
        let mut q: Vec<f64> = sys.initial_guess().0.iter().copied().collect();
        let mut table = BodyAngles::new(&sys, &q);
        let mut worst = 0.0f64;
        for k in 0..BodyAngles::MAX_ROTATIONS {
            // increments of both signs up to the limit
            q[2] += 0.9 * BodyAngles::MAX_INCREMENT;
            q[5] -= 0.5 * BodyAngles::MAX_INCREMENT * f64::from(k % 3);
            table.update_near(&sys, &q);
            for (i, th) in [(0, q[2]), (1, q[5])] {
                let [a, s, c] = table.sin_cos_of(i);
                assert_eq!(a.to_bits(), th.to_bits());
                let (se, ce) = th.sin_cos();
                worst = worst.max((s - se).abs()).max((c - ce).abs());
            }
        }
        assert!(
            worst <= 4.0 * f64::EPSILON,
            "rotated sin/cos off by {worst:e}"
        );
        // past the rotation cap, and for a larger increment: exact
        for step in [1e-4, 1.5 * BodyAngles::MAX_INCREMENT] {
            q[2] += step;
            table.update_near(&sys, &q);
            let (se, ce) = q[2].sin_cos();
            let [_, s, c] = table.sin_cos_of(0);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (se.to_bits(), ce.to_bits()),
                "{step}"
            );
        }
    }
}

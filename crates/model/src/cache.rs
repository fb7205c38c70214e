//! The angle cache of repeated constraint evaluations at nearby configurations.

use crate::system::*;

/// `sin` and `cos` of every body's angle from the last evaluation, for repeated evaluations
/// at nearby configurations (Newton iterations): [`System::phi_and_phi_dot_cached`] rotates
/// the cached values by the angle increment `delta` (`|delta| <= 1e-3`, with `cos delta` and
/// `sin delta` from their Taylor series, exact to rounding there) instead of calling `sin_cos`,
/// and recomputes them exactly after [`AngleCache::MAX_ROTATIONS`] rotations, for a larger
/// increment, or after [`AngleCache::invalidate`]. The rotated values differ from exact ones by
/// a few units in the last place.
#[derive(Clone, Debug)]
pub struct AngleCache {
    /// Per body: the angle, its sine and cosine, and the rotations since the exact evaluation.
    pub(crate) entries: Vec<AngleEntry>,
    pub(crate) valid: bool,
}

#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AngleEntry {
    pub(crate) theta: f64,
    pub(crate) s: f64,
    pub(crate) c: f64,
    pub(crate) rotations: u32,
}

impl AngleCache {
    /// Rotations allowed between two exact evaluations of one body's `sin_cos`.
    pub const MAX_ROTATIONS: u32 = 8;

    /// A cache for the bodies of `sys` (empty: the first evaluation is exact).
    pub fn new(sys: &System) -> Self {
        AngleCache {
            entries: vec![AngleEntry::default(); sys.bodies.len()],
            valid: false,
        }
    }

    /// Forgets the cached values: the next evaluation computes `sin_cos` exactly.
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// `(sin, cos)` of body `i`'s angle `theta`, updating the cache. For `|d| <= 1e-3` the
    /// truncated series `cos d = 1 - d^2/2 + d^4/24`, `sin d = d - d^3/6 + d^5/120` are exact to
    /// rounding (the next terms are below 1.4e-21).
    #[inline]
    pub(crate) fn sin_cos(&mut self, i: usize, theta: f64) -> (f64, f64) {
        let valid = self.valid;
        let e = &mut self.entries[i];
        let d = theta - e.theta;
        if valid && d.abs() <= 1e-3 && e.rotations < Self::MAX_ROTATIONS {
            if d != 0.0 {
                let d2 = d * d;
                let cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0));
                let sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)));
                let (s, c) = (e.s, e.c);
                e.s = s * cd + c * sd;
                e.c = c * cd - s * sd;
                e.theta = theta;
                e.rotations += 1;
            }
        } else {
            (e.s, e.c) = theta.sin_cos();
            e.theta = theta;
            e.rotations = 0;
        }
        (e.s, e.c)
    }
}

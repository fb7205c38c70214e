//! The search box `[lo, hi]^d`.

use crate::FireflyError;

/// A validated axis-aligned search box `[lo_k, hi_k]`, `k = 0..d`.
///
/// Invariants (checked by every constructor): `d >= 1`, every bound finite,
/// `lo_k <= hi_k`. A zero-width dimension (`lo_k == hi_k`) is allowed: that
/// coordinate is fixed for the whole run.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Bounds {
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl Bounds {
    /// Builds a box from lower and upper bound vectors.
    ///
    /// # Errors
    /// [`FireflyError::EmptyBounds`], [`FireflyError::BoundsLengthMismatch`],
    /// [`FireflyError::NonFiniteBound`] or [`FireflyError::InvertedBound`].
    pub fn new(lo: Vec<f64>, hi: Vec<f64>) -> Result<Self, FireflyError> {
        if lo.len() != hi.len() {
            return Err(FireflyError::BoundsLengthMismatch {
                lo: lo.len(),
                hi: hi.len(),
            });
        }
        if lo.is_empty() {
            return Err(FireflyError::EmptyBounds);
        }
        for (dim, (&l, &h)) in lo.iter().zip(&hi).enumerate() {
            if !l.is_finite() || !h.is_finite() {
                return Err(FireflyError::NonFiniteBound { dim, lo: l, hi: h });
            }
            if l > h {
                return Err(FireflyError::InvertedBound { dim, lo: l, hi: h });
            }
        }
        Ok(Self { lo, hi })
    }

    /// The hypercube `[lo, hi]^dim`.
    ///
    /// # Errors
    /// As [`Bounds::new`].
    pub fn cube(dim: usize, lo: f64, hi: f64) -> Result<Self, FireflyError> {
        Self::new(vec![lo; dim], vec![hi; dim])
    }

    /// The box `[c_k - h_k, c_k + h_k]` centred on `center` (for instance a
    /// predictor point) with half widths `half_width`.
    ///
    /// # Errors
    /// [`FireflyError::BoundsLengthMismatch`] if the slices differ in length,
    /// [`FireflyError::InvalidHalfWidth`] for a negative or non-finite half
    /// width, otherwise as [`Bounds::new`].
    pub fn centered(center: &[f64], half_width: &[f64]) -> Result<Self, FireflyError> {
        if center.len() != half_width.len() {
            return Err(FireflyError::BoundsLengthMismatch {
                lo: center.len(),
                hi: half_width.len(),
            });
        }
        for (dim, &h) in half_width.iter().enumerate() {
            if !h.is_finite() || h < 0.0 {
                return Err(FireflyError::InvalidHalfWidth { dim, half_width: h });
            }
        }
        let lo = center.iter().zip(half_width).map(|(c, h)| c - h).collect();
        let hi = center.iter().zip(half_width).map(|(c, h)| c + h).collect();
        Self::new(lo, hi)
    }

    /// Number of dimensions `d` (always at least 1).
    pub fn dim(&self) -> usize {
        self.lo.len()
    }

    /// Lower bounds.
    pub fn lo(&self) -> &[f64] {
        &self.lo
    }

    /// Upper bounds.
    pub fn hi(&self) -> &[f64] {
        &self.hi
    }

    /// Width `hi_k - lo_k` of dimension `k`, or `None` if `k >= d`.
    pub fn width(&self, k: usize) -> Option<f64> {
        Some(self.hi.get(k)? - self.lo.get(k)?)
    }

    /// Whether `x` has dimension `d` and lies inside the box (bounds included).
    /// NaN coordinates are never inside.
    pub fn contains(&self, x: &[f64]) -> bool {
        x.len() == self.dim()
            && x.iter()
                .zip(self.lo.iter().zip(&self.hi))
                .all(|(v, (l, h))| *l <= *v && *v <= *h)
    }
}

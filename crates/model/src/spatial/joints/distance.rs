//! The distance joint: a massless rod of fixed length between the markers' points.

use super::{dot3, sub3, MarkerAt};
use mbd_jet::Scalar;

/// `1/2 (|P_b - P_a|^2 - L^2)` (1 equation; the half makes its gradient the rod's direction
/// times its length).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, length: f64, out: &mut [T; 6]) {
    let r = sub3(b.p, a.p);
    out[0] = (dot3(r, r) - length * length) * 0.5;
}

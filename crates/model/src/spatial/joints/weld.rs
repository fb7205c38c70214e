//! The weld (fixed) joint: the markers coincide, points and axes.

use super::{dot3, spherical, MarkerAt};
use mbd_jet::Scalar;

/// `P_a - P_b` (3), `X_a . Y_b`, `X_a . Z_b`, `Y_a . Z_b` (6 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    spherical::eval(a, b, out);
    out[3] = dot3(a.x, b.y);
    out[4] = dot3(a.x, b.z);
    out[5] = dot3(a.y, b.z);
}

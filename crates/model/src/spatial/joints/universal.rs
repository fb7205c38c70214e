//! The universal (Cardan) joint: the points coincide and `a`'s `x` axis stays perpendicular to
//! `b`'s `y` axis (the cross's two arms).

use super::{dot3, spherical, MarkerAt};
use mbd_jet::Scalar;

/// `P_a - P_b` (3), `X_a . Y_b` (4 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    spherical::eval(a, b, out);
    out[3] = dot3(a.x, b.y);
}

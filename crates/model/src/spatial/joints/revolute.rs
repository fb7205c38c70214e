//! The revolute joint (hinge): the points coincide and `b`'s `z` axis stays along `a`'s.

use super::{dot3, spherical, MarkerAt};
use mbd_jet::Scalar;

/// `P_a - P_b` (3), `Z_b . X_a`, `Z_b . Y_a` (5 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    spherical::eval(a, b, out);
    out[3] = dot3(b.z, a.x);
    out[4] = dot3(b.z, a.y);
}

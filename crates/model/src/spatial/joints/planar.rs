//! The planar joint: `b`'s marker slides in `a`'s `x`-`y` plane and turns about its normal.

use super::{dot3, sub3, MarkerAt};
use mbd_jet::Scalar;

/// `Z_b . X_a`, `Z_b . Y_a`, `(P_b - P_a) . Z_a` (3 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    out[0] = dot3(b.z, a.x);
    out[1] = dot3(b.z, a.y);
    out[2] = dot3(sub3(b.p, a.p), a.z);
}

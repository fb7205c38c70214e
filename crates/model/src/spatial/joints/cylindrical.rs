//! The cylindrical joint: `b`'s `z` axis stays along `a`'s, and `b`'s point on the line
//! through `a`'s point along it.

use super::{dot3, sub3, MarkerAt};
use mbd_jet::Scalar;

/// `Z_b . X_a`, `Z_b . Y_a`, `(P_b - P_a) . X_a`, `(P_b - P_a) . Y_a` (4 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    let r = sub3(b.p, a.p);
    out[0] = dot3(b.z, a.x);
    out[1] = dot3(b.z, a.y);
    out[2] = dot3(r, a.x);
    out[3] = dot3(r, a.y);
}

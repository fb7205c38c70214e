//! The prismatic joint (slider): the cylindrical joint with the rotation about the axis locked.

use super::{cylindrical, dot3, MarkerAt};
use mbd_jet::Scalar;

/// The cylindrical joint's four, `X_a . Y_b` (5 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    cylindrical::eval(a, b, out);
    out[4] = dot3(a.x, b.y);
}

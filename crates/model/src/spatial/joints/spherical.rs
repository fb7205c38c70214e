//! The spherical (ball) joint: the markers' points coincide.

use super::{sub3, MarkerAt};
use mbd_jet::Scalar;

/// `P_a - P_b` (3 equations).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    out[..3].copy_from_slice(&sub3(a.p, b.p));
}

//! The slide driver: the second marker's point moves along the first marker's `z` axis by a
//! prescribed amount.

use super::{dot3, sub3, MarkerAt};
use mbd_jet::Scalar;

/// `(P_b - P_a) . Z_a` (1 equation; the system subtracts the motion `s(t)`).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    out[0] = dot3(sub3(b.p, a.p), a.z);
}

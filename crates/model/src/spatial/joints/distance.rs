//! The distance joint: a massless rod of fixed length between the markers' points.

use super::{dot3, sub3, MarkerAt};
use mbd_jet::Scalar;

/// `(|P_b - P_a|^2 - L^2) / (2 L)` (1 equation, a length like the other joints' position
/// equations, so that its residual and round-off scale with the model's unit of length; on the
/// constraint its gradient is the rod's unit direction). `length` is positive (checked when
/// the joint is made).
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, length: f64, out: &mut [T; 6]) {
    let r = sub3(b.p, a.p);
    out[0] = (dot3(r, r) - length * length) * (0.5 / length);
}

/// `1/2 (|P_b - P_a|^2)`: the distance driver's equation without its motion (the system
/// subtracts `L(t)^2 / 2`).
pub(super) fn eval_driver<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    let r = sub3(b.p, a.p);
    out[0] = dot3(r, r) * 0.5;
}

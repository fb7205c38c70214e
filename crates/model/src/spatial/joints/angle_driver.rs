//! The angle driver: the second marker's `x` axis turns about the first marker's `z` axis by a
//! prescribed angle `theta(t)`, measured from the first marker's `x` axis towards its `y` axis.

use super::{dot3, MarkerAt};
use mbd_jet::Scalar;

/// The two components of the driver's equation: `X_b . Y_a` into `out[0]` and `X_b . X_a` into
/// `out[1]`. The system forms the equation `cos theta X_b . Y_a - sin theta X_b . X_a`: with the
/// `z` axes aligned (a revolute or cylindrical joint beside it) and `X_b = cos phi X_a + sin phi
/// Y_a`, that is `sin(phi - theta)`, zero at `phi = theta` with slope 1 in `phi`. Both
/// components are bilinear in the coordinates, so the equation is quadratic in `q` for every
/// `t`; its Jacobian depends on time through `cos theta`, `sin theta`.
pub(super) fn eval<T: Scalar>(a: &MarkerAt<T>, b: &MarkerAt<T>, out: &mut [T; 6]) {
    out[0] = dot3(b.x, a.y);
    out[1] = dot3(b.x, a.x);
}

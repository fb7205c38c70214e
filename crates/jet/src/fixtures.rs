//! Test fixtures (feature `fixtures`, for the tests of this crate and of the crates above it):
//! a [`PolyJet`](crate::PolyJet) basis the derivative tests share.

use crate::{Basis, MAX_DIRS};

/// A [`PolyJet`](crate::PolyJet) basis in two directions (`t`, `e`): `{1, t, e, t^2, e t, t^3,
/// e t^2, t^4}`, the shape of the symplectic preadjustment's first pass.
#[derive(Clone, Copy, Debug)]
pub struct TwoDirections;
impl Basis<8> for TwoDirections {
    const ND: usize = 2;
    const EXP: [[u8; MAX_DIRS]; 8] = [
        [0, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [2, 0, 0, 0, 0, 0],
        [1, 1, 0, 0, 0, 0],
        [3, 0, 0, 0, 0, 0],
        [2, 1, 0, 0, 0, 0],
        [4, 0, 0, 0, 0, 0],
    ];
}

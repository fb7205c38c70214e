//! Element-local constraint rows assembled into a dense matrix.

use crate::jet::NV;
use crate::system::System;
use nalgebra::DMatrix;

impl System {
    /// The dense `m x n` matrix of element-local constraint rows (six numbers per row in the
    /// columns of its joint's two bodies, as [`System::phi_q_local`] writes them; e.g. `Phi_q`
    /// from its `grads`) into `out` (overwritten).
    pub fn local_rows_dense(&self, rows: &[[f64; NV]], out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        for ji in 0..self.joints.len() {
            let o = self.row_offset[ji];
            for k in 0..self.joints[ji].n_equations() {
                self.scatter_row(ji, o + k, &rows[o + k], out);
            }
        }
    }
}

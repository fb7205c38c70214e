//! The symbolic side of [`DenseLu`]: the nonzero lists of `L` and `U` ([`Pattern`]) and the
//! symbolic factorisation of the tracked pattern with the static diagonal pivots.

use super::DenseLu;

/// Nonzero lists of `L` (by columns) and `U` (by rows) of one factorisation.
#[derive(Clone, Debug, Default)]
pub(super) struct Pattern {
    /// Rows of the multipliers of column `k`: `l_idx[l_start[k]..l_start[k + 1]]`.
    pub(super) l_idx: Vec<usize>,
    pub(super) l_start: Vec<usize>,
    /// Columns right of the diagonal in the `k`-th pivot row: `u_idx[u_start[k]..u_start[k + 1]]`.
    pub(super) u_idx: Vec<usize>,
    pub(super) u_start: Vec<usize>,
}

impl Pattern {
    pub(super) fn new(n: usize) -> Self {
        Pattern {
            l_idx: vec![0; n * n],
            l_start: vec![0; n + 1],
            u_idx: vec![0; n * n],
            u_start: vec![0; n + 1],
        }
    }
}

impl DenseLu {
    /// Symbolic factorisation of `mask` with the diagonal pivots of the ordering.
    pub(super) fn analyse(&mut self) {
        let n = self.n;
        self.n_nz = 0;
        for (k, &m) in self.mask.iter().enumerate() {
            if k % n == 0 {
                self.nz_start[k / n] = self.n_nz;
            }
            if m {
                self.nz[self.n_nz] = k;
                self.nz_col[self.n_nz] = k % n;
                self.n_nz += 1;
            }
        }
        self.nz_start[n] = self.n_nz;
        let mask = &mut self.fill;
        mask.copy_from_slice(&self.mask);
        let p = &mut self.symbolic;
        let (mut nl, mut nu) = (0, 0);
        for k in 0..n {
            p.u_start[k] = nu;
            for j in k + 1..n {
                if mask[k * n + j] {
                    p.u_idx[nu] = j;
                    nu += 1;
                }
            }
            p.l_start[k] = nl;
            for i in k + 1..n {
                if mask[i * n + k] {
                    p.l_idx[nl] = i;
                    nl += 1;
                    for &j in &p.u_idx[p.u_start[k]..nu] {
                        mask[i * n + j] = true;
                    }
                }
            }
        }
        p.l_start[n] = nl;
        p.u_start[n] = nu;
        self.dirty = false;
        self.analyses += 1;
    }
}

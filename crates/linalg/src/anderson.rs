//! Anderson acceleration of a fixed-point iteration (type II, Walker & Ni, SIAM J. Numer.
//! Anal. 49, 2011), for the simplified Newton iterations of the solvers: where the iteration
//! matrix leaves out part of the Jacobian, the iteration `x <- x + d(x)` converges only
//! linearly, and the slow part of its error lives in a few directions that the last few
//! updates reveal.

/// Anderson mixing of the updates of an iteration `x_(k+1) = x_k + d_k`, `d_k = d(x_k)`.
///
/// With the last `p` differences `dX_j = x_(j+1) - x_j` and `dD_j = d_(j+1) - d_j` (columns of
/// `dX`, `dD`), the mixed update is
///
/// `d~_k = d_k - (dX + dD) gamma`, `gamma = argmin |d_k - dD gamma|`,
///
/// the least squares taken over the leading [`Anderson::measured`] entries (the ones whose
/// scale the caller's convergence test uses). For a linear map `d(x) = -(I - E)(x - x*)` whose
/// error operator `E` has `p` eigenvalues away from zero, the mixed iteration converges in
/// about `p + 1` steps where the plain one needs `log(tol) / log(rho(E))`.
///
/// The normal equations of the least squares are solved by Cholesky; a column whose pivot
/// falls below `1e-10` of its diagonal entry (a direction already spanned by the others) is
/// dropped, oldest first. Preallocated: [`Anderson::mix`] allocates nothing.
///
/// ```
/// use mbd_linalg::Anderson;
///
/// // x <- x + d(x) with d = -(I - E)(x - 1): E = diag(0.9, 0.5) contracts slowly
/// let e = [0.9, 0.5];
/// let update = |x: &[f64], d: &mut [f64]| {
///     for i in 0..2 {
///         d[i] = -(1.0 - e[i]) * (x[i] - 1.0);
///     }
/// };
/// let mut aa = Anderson::new(2, 2, 3);
/// let (mut x, mut d) = ([0.0, 0.0], [0.0, 0.0]);
/// for _ in 0..4 {
///     update(&x, &mut d);
///     aa.mix(&x, &mut d);
///     x[0] += d[0];
///     x[1] += d[1];
/// }
/// // the plain iteration would still be 0.9^4 = 0.66 away
/// assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct Anderson {
    dim: usize,
    measured: usize,
    depth: usize,
    /// `dX` and `dD`: `depth` columns of length `dim` each, a ring from `head`.
    dx: Vec<f64>,
    dd: Vec<f64>,
    /// The last recorded iterate and update.
    last_x: Vec<f64>,
    last_d: Vec<f64>,
    has_last: bool,
    /// Columns held, and the slot of the oldest.
    count: usize,
    head: usize,
    /// The normal equations (`depth x depth`, row-major) and their solution.
    gram: Vec<f64>,
    gamma: Vec<f64>,
}

/// Relative pivot below which a column of the least squares is dropped.
const DROP_PIVOT: f64 = 1e-10;

impl Anderson {
    /// Mixing for vectors of length `dim`, the least squares measured over the first
    /// `measured` entries (`measured <= dim`; more is clamped), keeping at most `depth`
    /// difference pairs (at least one).
    pub fn new(dim: usize, measured: usize, depth: usize) -> Self {
        let depth = depth.max(1);
        Anderson {
            dim,
            measured: measured.min(dim),
            depth,
            dx: vec![0.0; depth * dim],
            dd: vec![0.0; depth * dim],
            last_x: vec![0.0; dim],
            last_d: vec![0.0; dim],
            has_last: false,
            count: 0,
            head: 0,
            gram: vec![0.0; depth * depth],
            gamma: vec![0.0; depth],
        }
    }

    /// The number of leading entries the least squares measures.
    pub fn measured(&self) -> usize {
        self.measured
    }

    /// Forgets the history (call it when the map `d` changes, e.g. a new iteration matrix).
    pub fn reset(&mut self) {
        self.has_last = false;
        self.count = 0;
        self.head = 0;
    }

    /// The update `d` recorded by the last [`Anderson::mix`], before mixing (what the plain
    /// iteration would apply).
    pub fn last_update(&self) -> &[f64] {
        &self.last_d
    }

    /// Difference pairs held.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether no difference pair is held.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Starts the history (after a [`Anderson::reset`]) from an iteration run without it:
    /// `x` was reached from the previous iterate by the step `lambda d_prev`, and `d` is the
    /// update at `x`. Holds one difference pair afterwards (none if the lengths differ).
    pub fn start(&mut self, x: &[f64], d_prev: &[f64], lambda: f64, d: &[f64]) {
        let dim = self.dim;
        self.reset();
        if x.len() != dim || d_prev.len() != dim || d.len() != dim {
            return;
        }
        let cx = &mut self.dx[..dim];
        let cd = &mut self.dd[..dim];
        for i in 0..dim {
            cx[i] = lambda * d_prev[i];
            cd[i] = d[i] - d_prev[i];
        }
        self.count = 1;
        self.last_x.copy_from_slice(x);
        self.last_d.copy_from_slice(d);
        self.has_last = true;
    }

    /// Records the iterate `x` and its update `d` (both of length `dim`; other lengths reset
    /// the history and leave `d` alone) and overwrites `d` with the mixed update. Returns the
    /// number of difference pairs the mixed update used (0: `d` unchanged, as on the first
    /// call after a [`Anderson::reset`]).
    pub fn mix(&mut self, x: &[f64], d: &mut [f64]) -> usize {
        let dim = self.dim;
        if x.len() != dim || d.len() != dim {
            self.reset();
            return 0;
        }
        if self.has_last {
            // the new pair goes into the oldest slot once the ring is full
            let slot = (self.head + self.count) % self.depth;
            if self.count == self.depth {
                self.head = (self.head + 1) % self.depth;
            } else {
                self.count += 1;
            }
            let cx = &mut self.dx[slot * dim..(slot + 1) * dim];
            let cd = &mut self.dd[slot * dim..(slot + 1) * dim];
            for i in 0..dim {
                cx[i] = x[i] - self.last_x[i];
                cd[i] = d[i] - self.last_d[i];
            }
        }
        self.last_x.copy_from_slice(x);
        self.last_d.copy_from_slice(d);
        self.has_last = true;
        if self.count == 0 {
            return 0;
        }
        // columns oldest first: k-th column in slot (head + k) % depth; drop the oldest until
        // the normal equations factor
        let mut first = 0;
        while first < self.count {
            if self.solve(first, d) {
                let used = self.count - first;
                for k in 0..used {
                    let slot = (self.head + first + k) % self.depth;
                    let g = self.gamma[k];
                    let cx = &self.dx[slot * dim..(slot + 1) * dim];
                    let cd = &self.dd[slot * dim..(slot + 1) * dim];
                    for i in 0..dim {
                        d[i] -= g * (cx[i] + cd[i]);
                    }
                }
                return used;
            }
            first += 1;
        }
        0
    }

    /// Solves the normal equations of the columns `first..count` against `d` into `gamma`;
    /// `false` if a pivot falls below [`DROP_PIVOT`] of its diagonal entry (or is not finite).
    fn solve(&mut self, first: usize, d: &[f64]) -> bool {
        let (dim, depth, nm) = (self.dim, self.depth, self.measured);
        let p = self.count - first;
        let col = |k: usize| {
            let slot = (self.head + first + k) % depth;
            &self.dd[slot * dim..slot * dim + nm]
        };
        for a in 0..p {
            let ca = col(a);
            for b in 0..=a {
                let cb = col(b);
                self.gram[a * depth + b] = ca.iter().zip(cb).map(|(u, v)| u * v).sum();
            }
            self.gamma[a] = ca.iter().zip(&d[..nm]).map(|(u, v)| u * v).sum();
        }
        // Cholesky in place (lower triangle), then the two triangular solves
        for j in 0..p {
            let diag = self.gram[j * depth + j];
            let mut s = diag;
            for k in 0..j {
                s -= self.gram[j * depth + k] * self.gram[j * depth + k];
            }
            if !(s > DROP_PIVOT * diag) || !s.is_finite() {
                return false;
            }
            let l = s.sqrt();
            self.gram[j * depth + j] = l;
            for i in j + 1..p {
                let mut t = self.gram[i * depth + j];
                for k in 0..j {
                    t -= self.gram[i * depth + k] * self.gram[j * depth + k];
                }
                self.gram[i * depth + j] = t / l;
            }
        }
        for i in 0..p {
            let mut t = self.gamma[i];
            for k in 0..i {
                t -= self.gram[i * depth + k] * self.gamma[k];
            }
            self.gamma[i] = t / self.gram[i * depth + i];
        }
        for i in (0..p).rev() {
            let mut t = self.gamma[i];
            for k in i + 1..p {
                t -= self.gram[k * depth + i] * self.gamma[k];
            }
            self.gamma[i] = t / self.gram[i * depth + i];
        }
        self.gamma[..p].iter().all(|g| g.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::Anderson;

    /// The linear iteration `d = -(I - E)(x - x*)` with `E` of rank `r` (eigenvalues 0.9 to
    /// 0.6 on `r` random-ish orthogonal directions, 0 elsewhere): iterations to `1e-12`.
    fn iterations(depth: usize, apply: bool, r: usize) -> usize {
        let n = 40;
        // E = sum_k rho_k u_k u_k^T with u_k the normalised rows of a fixed matrix (Gram-Schmidt)
        let mut u: Vec<Vec<f64>> = Vec::new();
        for k in 0..r {
            let mut v: Vec<f64> = (0..n)
                .map(|i| ((i * (k + 3) + 7 * k) % 11) as f64 - 5.0 + 0.1 * i as f64)
                .collect();
            for w in &u {
                let p: f64 = v.iter().zip(w).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(w).for_each(|(a, b)| *a -= p * b);
            }
            let nv = v.iter().map(|a| a * a).sum::<f64>().sqrt();
            v.iter_mut().for_each(|a| *a /= nv);
            u.push(v);
        }
        let rho: Vec<f64> = (0..r).map(|k| 0.9 - 0.3 * k as f64 / r as f64).collect();
        let xs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = vec![0.0; n];
        let mut d = vec![0.0; n];
        let mut aa = Anderson::new(n, n, depth);
        for it in 1..=500 {
            // d = -(x - x*) + E (x - x*)
            let e: Vec<f64> = x.iter().zip(&xs).map(|(a, b)| a - b).collect();
            for i in 0..n {
                d[i] = -e[i];
            }
            for (k, w) in u.iter().enumerate() {
                let p: f64 = w.iter().zip(&e).map(|(a, b)| a * b).sum();
                for i in 0..n {
                    d[i] += rho[k] * p * w[i];
                }
            }
            if apply {
                aa.mix(&x, &mut d);
            }
            x.iter_mut().zip(&d).for_each(|(a, b)| *a += b);
            let err = x
                .iter()
                .zip(&xs)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if err < 1e-12 {
                return it;
            }
        }
        usize::MAX
    }

    #[test]
    fn mixing_removes_the_slow_directions() {
        let plain = iterations(3, false, 3);
        let mixed = iterations(3, true, 3);
        // the plain iteration contracts by 0.9 per step: about 260 iterations
        assert!(plain > 200, "plain {plain}");
        // three slow directions, three pairs: a handful of steps
        assert!(mixed <= 6, "mixed {mixed}");
        // with fewer pairs than slow directions, still far faster than the plain iteration
        let shallow = iterations(1, true, 3);
        assert!(shallow < plain / 2, "depth 1: {shallow} against {plain}");
    }

    #[test]
    fn the_first_update_is_untouched_and_mismatched_lengths_reset() {
        let mut aa = Anderson::new(3, 3, 2);
        let x = [1.0, 2.0, 3.0];
        let mut d = [0.5, -0.25, 0.125];
        assert_eq!(aa.mix(&x, &mut d), 0);
        assert_eq!(d, [0.5, -0.25, 0.125]);
        assert!(aa.is_empty());
        let mut d2 = [0.25, -0.125, 0.0625];
        assert_eq!(aa.mix(&[1.5, 1.75, 3.125], &mut d2), 1);
        assert_eq!(aa.len(), 1);
        assert_eq!(aa.last_update(), &[0.25, -0.125, 0.0625]);
        let mut short = [0.0; 2];
        assert_eq!(aa.mix(&[0.0; 2], &mut short), 0);
        assert!(aa.is_empty());
    }

    #[test]
    fn a_repeated_direction_is_dropped_not_divided_by() {
        // two identical difference pairs: the normal equations are singular; the older is
        // dropped and the update stays finite
        let mut aa = Anderson::new(2, 2, 3);
        let mut d = [1.0, 0.0];
        aa.mix(&[0.0, 0.0], &mut d);
        let mut d = [0.5, 0.0];
        aa.mix(&[1.0, 0.0], &mut d);
        let mut d = [0.0, 0.0];
        let used = aa.mix(&[2.0, 0.0], &mut d);
        assert!(used >= 1 && d.iter().all(|v| v.is_finite()), "{used} {d:?}");
    }
}

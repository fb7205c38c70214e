//! The history of the normal coordinates of every map of the last accepted fixed steps (called
//! `eta` here: in the dense chart's canonical basis, or the sparse chart's `eta`; see
//! `Path::canonical_from_zeta`), from which [`TangentRk`](super::TangentRk) extrapolates the
//! Newton starting points of the next step, with the extrapolation order chosen per map from
//! the errors the orders showed on the latest step.

use crate::kernels::with_codim;

/// Most steps of history kept, and the highest extrapolation order.
pub(super) const MAX_ORDER: usize = 6;

/// Orders used while the history fills up (before any order's error has been seen for
/// enough steps): the order equals the number of steps recorded, up to this.
const FILL_ORDER: usize = 3;

/// Backward differences of `eta` over the last accepted steps of one size.
///
/// For every map (stage `i` at `i * 2m`, the end point at `s * 2m` of a step's record of length
/// `len`) the table keeps `nabla^j eta` of the latest step, `j < count`. The extrapolation of
/// order `p` to the next step is Newton's backward formula `sum_(j < p) nabla^j eta` (order 3:
/// `3 e1 - 3 e2 + e3`), and the error it makes on a new value is exactly the new value's
/// `nabla^p`. Recording a step therefore yields the error every available order would have
/// made on it, and each map's next extrapolation takes the order with the smallest one: high
/// orders while the motion is smooth on the scale of the steps (at small steps the errors of
/// the converged `eta`, about the Newton tolerance, dominate the high differences instead, and a
/// low order wins).
#[derive(Clone, Debug)]
pub(super) struct EtaHistory {
    /// `nabla^j eta` of the latest step at `j * len` (`MAX_ORDER` records).
    diff: Vec<f64>,
    /// Length of a step's record, `(s + 1) 2m`, and of one map's `eta`, `2m`.
    len: usize,
    mm: usize,
    /// Steps recorded (at most `depth`), and the most kept: [`MAX_ORDER`] with the order
    /// chosen per map, [`FILL_ORDER`] for the fixed order.
    count: usize,
    depth: usize,
    /// The extrapolation order of each map for the next step.
    order: Vec<usize>,
    /// Scratch (`2m`).
    cur: Vec<f64>,
    /// `TangentChart::rcond` of the charts of the recorded steps, most recent first.
    rcond: [f64; MAX_ORDER],
    /// Size of the recorded steps and the end time of the latest.
    pub(super) h: f64,
    pub(super) t: f64,
}

impl EtaHistory {
    /// An empty history for `maps` maps of `mm` coefficients (allocates once); `adaptive`:
    /// the order is chosen per map up to [`MAX_ORDER`], else it is [`FILL_ORDER`] (the sparse
    /// chart, whose steps this keeps as they were).
    pub(super) fn new(maps: usize, mm: usize, adaptive: bool) -> Self {
        EtaHistory {
            depth: if adaptive { MAX_ORDER } else { FILL_ORDER },
            diff: vec![0.0; MAX_ORDER * maps * mm],
            len: maps * mm,
            mm,
            count: 0,
            order: vec![0; maps],
            cur: vec![0.0; mm],
            rcond: [1.0; MAX_ORDER],
            h: f64::NAN,
            t: f64::NAN,
        }
    }

    /// Forgets every recorded step.
    pub(super) fn clear(&mut self) {
        self.count = 0;
    }

    /// How many of the most recent steps have a chart whose `rcond` lies within a factor
    /// `drift` of `rcond` (a prefix of the history), and whether that prefix covers the latest
    /// `min(len, FILL_ORDER)` steps.
    pub(super) fn usable(&self, rcond: f64, drift: f64) -> (usize, bool) {
        let k = self.rcond[..self.count]
            .iter()
            .take_while(|&&r| r <= drift * rcond && rcond <= drift * r)
            .count();
        (k, k >= self.count.min(FILL_ORDER))
    }

    /// The extrapolation of map `map`'s `eta` to the next step into `out` (`2m`), of the order
    /// chosen for the map but from at most the `npts` most recent steps (`npts >= 1`).
    pub(super) fn predict(&self, map: usize, npts: usize, out: &mut [f64]) {
        let p = self.order[map].min(npts).max(1);
        let (len, off) = (self.len, map * self.mm);
        // the order a literal too: the sums unroll
        match p {
            1 => with_codim!(self.mm, sum_rows(&self.diff, len, off, 1, out)),
            2 => with_codim!(self.mm, sum_rows(&self.diff, len, off, 2, out)),
            3 => with_codim!(self.mm, sum_rows(&self.diff, len, off, 3, out)),
            4 => with_codim!(self.mm, sum_rows(&self.diff, len, off, 4, out)),
            5 => with_codim!(self.mm, sum_rows(&self.diff, len, off, 5, out)),
            6 => with_codim!(self.mm, sum_rows(&self.diff, len, off, 6, out)),
            _ => with_codim!(self.mm, sum_rows(&self.diff, len, off, p, out)),
        }
    }

    /// Records an accepted step's `eta` (`record`, all maps) with its chart's `rcond`, and
    /// chooses each map's order for the next step.
    pub(super) fn commit(&mut self, record: &[f64], rcond: f64) {
        let old = self.count;
        for map in 0..self.order.len() {
            // errs[p]: the largest error of the order-p extrapolation on this step
            let mut errs = [0.0f64; MAX_ORDER + 1];
            let (diff, cur, len, off) = (&mut self.diff, &mut self.cur, self.len, map * self.mm);
            let grow = old < self.depth;
            let new = &record[off..];
            match (self.mm, old) {
                // the common cases with the length and the table's depth literals: the
                // difference vector stays in registers
                (4, MAX_ORDER) => push_fixed::<4>(diff, len, off, new, MAX_ORDER, false, &mut errs),
                (8, MAX_ORDER) => push_fixed::<8>(diff, len, off, new, MAX_ORDER, false, &mut errs),
                (16, MAX_ORDER) => {
                    push_fixed::<16>(diff, len, off, new, MAX_ORDER, false, &mut errs)
                }
                (mm, _) => push_map(diff, len, off, new, old, grow, cur, &mut errs, mm),
            }
            self.order[map] = if old < FILL_ORDER || self.depth == FILL_ORDER {
                (old + 1).min(FILL_ORDER)
            } else {
                // the smallest error (NaN never wins); the lower order on ties
                (2..=old).fold(1, |best, p| if errs[p] < errs[best] { p } else { best })
            };
        }
        self.rcond.copy_within(0..MAX_ORDER - 1, 1);
        self.rcond[0] = rcond;
        self.count = (old + 1).min(self.depth);
    }
}

/// Pushes one map's new `eta` (`new`, `mm`) into its difference table (`nabla^j` at
/// `j * len + off`, `old` of them valid): each `nabla^j` is replaced by the new one,
/// `nabla^(j+1) new = nabla^j new - nabla^j old`, whose max-norm is the error the order-`(j+1)`
/// extrapolation made (into `errs[j + 1]`); with `grow` the table gains `nabla^old new` as
/// its deepest entry. `cur` is scratch of length `mm`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn push_map(
    diff: &mut [f64],
    len: usize,
    off: usize,
    new: &[f64],
    old: usize,
    grow: bool,
    cur: &mut [f64],
    errs: &mut [f64; MAX_ORDER + 1],
    mm: usize,
) {
    let cur = &mut cur[..mm];
    cur.copy_from_slice(&new[..mm]);
    for j in 0..old {
        let row = &mut diff[j * len + off..][..mm];
        let mut e = 0.0f64;
        for i in 0..mm {
            let o = row[i];
            row[i] = cur[i];
            let c = cur[i] - o;
            cur[i] = c;
            let a = c.abs();
            e = if a > e { a } else { e };
        }
        errs[j + 1] = e;
    }
    if grow {
        diff[old * len + off..][..mm].copy_from_slice(cur);
    }
}

/// [`push_map`] for a map of `MM` coefficients.
#[inline(always)]
fn push_fixed<const MM: usize>(
    diff: &mut [f64],
    len: usize,
    off: usize,
    new: &[f64],
    old: usize,
    grow: bool,
    errs: &mut [f64; MAX_ORDER + 1],
) {
    let mut cur: [f64; MM] = new[..MM].try_into().unwrap_or([0.0; MM]);
    for j in 0..old {
        let Ok(row) = <&mut [f64; MM]>::try_from(&mut diff[j * len + off..j * len + off + MM])
        else {
            continue;
        };
        // the max-norm in two lanes (even and odd entries, `MM` is even), so that the
        // difference, its magnitude and the running maximum run as pairs
        let mut e = [0.0f64; 2];
        for i in (0..MM).step_by(2) {
            for l in 0..2 {
                let o = row[i + l];
                row[i + l] = cur[i + l];
                cur[i + l] -= o;
                let a = cur[i + l].abs();
                e[l] = if a > e[l] { a } else { e[l] };
            }
        }
        errs[j + 1] = if e[1] > e[0] { e[1] } else { e[0] };
    }
    if grow {
        diff[old * len + off..old * len + off + MM].copy_from_slice(&cur);
    }
}

/// `out = sum_(j < p) rows[j * len + off ..][..mm]` (`mm` a literal through `with_codim!`).
#[inline(always)]
fn sum_rows(rows: &[f64], len: usize, off: usize, p: usize, out: &mut [f64], mm: usize) {
    let out = &mut out[..mm];
    let rows = &rows[off..(p - 1) * len + off + mm];
    out.copy_from_slice(&rows[..mm]);
    for j in 1..p {
        let r = &rows[j * len..j * len + mm];
        for i in 0..mm {
            out[i] += r[i];
        }
    }
}

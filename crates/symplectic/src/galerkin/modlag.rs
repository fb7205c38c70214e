//! The modified-Lagrangian terms of a step (`PreadjustMode::ModifiedLagrangian`,
//! `docs/symplectic.md` sections 5a and 5b), and when the `s = 2` gradients may be kept from
//! one Newton residual to the next.

use super::{with_time, Galerkin};
use mbd_model::System;
use mbd_solve::SolveError;

/// The `s = 2` modified-Lagrangian gradients of the last four steps, for the first residual of
/// the next one.
///
/// `E_d = h^5 e4(qbar, v)` enters the first momentum row as `h M^-1 (h/2 dE/dq - dE/dv)`,
/// `E = h^4 e4`. At the predictor (the first residual of a step that continues the last two with
/// the same `h`) the gradients are extrapolated by the cubic through the last four steps'
/// converged ones instead of evaluated: they only shape Newton's first update (an error of
/// `O(h^4)` in a term of `O(h^5)`), and every later residual, from which the accepted iterate is computed,
/// evaluates them afresh. A first residual with extrapolated gradients that already passes the
/// tolerance is evaluated again before Newton decides on it. This saves one of the two or three
/// evaluations of a step. The cubic costs Newton no extra iterations where a linear
/// extrapolation does (`docs/symplectic.md` section 5b, "Extrapolated first residual").
#[derive(Debug)]
pub(super) struct GradientHistory {
    /// The scaled gradients `(dE/dq, dE/dv)` of the last four steps (the oldest first).
    hist: [Vec<f64>; 4],
    hist_len: usize,
    /// Whether the next residual is the first of a step that continues the history (set by
    /// `step`), and whether the last residual took extrapolated gradients.
    pub(super) first: bool,
    pub(super) lagged: bool,
}

impl GradientHistory {
    /// The workspace for `n` coordinates (0: no `s = 2` modified Lagrangian).
    pub(super) fn new(n: usize) -> Self {
        GradientHistory {
            hist: [
                vec![0.0; 2 * n],
                vec![0.0; 2 * n],
                vec![0.0; 2 * n],
                vec![0.0; 2 * n],
            ],
            hist_len: 0,
            first: false,
            lagged: false,
        }
    }

    /// Records a step's converged gradients (`contiguous`: the step continued the last one
    /// with the same `h`; otherwise the history restarts).
    pub(super) fn record(&mut self, contiguous: bool, gq: &[f64], gv: &[f64]) {
        let n = gq.len();
        if self.hist[0].len() != 2 * n {
            return;
        }
        if !contiguous {
            self.hist_len = 0;
        }
        self.hist.rotate_left(1);
        self.hist[3][..n].copy_from_slice(gq);
        self.hist[3][n..].copy_from_slice(gv);
        self.hist_len = (self.hist_len + 1).min(4);
    }

    /// Forgets the history.
    pub(super) fn clear(&mut self) {
        self.hist_len = 0;
        self.first = false;
    }
}

impl Galerkin {
    /// The modified-Lagrangian terms `h^2 de/dq`, `h^2 de/dv` (s = 1) or `h^4 de4/dq`,
    /// `h^4 de4/dv` (s = 2) at the chord midpoint and the step's velocity of `self.x` (nothing
    /// without the mode).
    pub(super) fn modified_terms(
        &mut self,
        sys: &System,
        t: f64,
        h: f64,
    ) -> Result<(), SolveError> {
        let (n, s) = (self.n, self.tab.s);
        let Some(ml) = self.ml.first_mut() else {
            return Ok(());
        };
        if s == 1 {
            // s = 1: E_d = h^3 e(qbar, v) with the chord midpoint qbar = (Q_0 + Q_1) / 2 and
            // the step's constant velocity v = (Q_1 - Q_0) / h = hvj / h (one evaluation per
            // residual; docs/symplectic.md section 5a)
            let h2 = h * h;
            ml.set_time(t + 0.5 * h);
            for i in 0..n {
                self.mlvel[i] = self.hvj[i] / h;
                self.mlmid[i] = 0.5 * (self.qn[i] + self.qn[n + i]);
            }
            ml.modified_gradients(sys, &self.mlmid, &self.mlvel, &mut self.mlq, &mut self.mlv)
                .map_err(|e| with_time(e, t))?;
            for i in 0..n {
                self.mlq[i] *= h2;
                self.mlv[i] *= h2;
            }
            return Ok(());
        }
        // s = 2: E_d = h^5 e4(qbar, v) at the chord of the end control points, its exact
        // gradients by a reverse pass (preadjust/modified_s2/; docs/symplectic.md section 5b); at a
        // continuing step's predictor extrapolated from the last four steps (`GradientHistory`)
        let r = &mut self.mlhist;
        r.lagged = std::mem::take(&mut r.first) && r.hist_len == 4;
        if r.lagged {
            let [g0, g1, g2, g3] = &r.hist;
            for i in 0..n {
                self.mlq[i] = 4.0 * (g3[i] + g1[i]) - 6.0 * g2[i] - g0[i];
                self.mlv[i] = 4.0 * (g3[n + i] + g1[n + i]) - 6.0 * g2[n + i] - g0[n + i];
            }
            return Ok(());
        }
        for i in 0..n {
            self.mlmid[i] = 0.5 * (self.qn[i] + self.qn[s * n + i]);
            self.mlvel[i] = (self.qn[s * n + i] - self.qn[i]) / h;
        }
        ml.set_time(t + 0.5 * h);
        ml.modified_gradients_s2(sys, &self.mlmid, &self.mlvel, &mut self.mlq, &mut self.mlv)
            .map_err(|e| with_time(e, t))?;
        let h4 = h.powi(4);
        for i in 0..n {
            self.mlq[i] *= h4;
            self.mlv[i] *= h4;
        }
        Ok(())
    }
}

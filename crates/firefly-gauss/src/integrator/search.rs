//! The firefly run on one step's objective and the optional Gauss-Newton polish.

use super::*;

impl FireflyGauss {
    pub(super) fn run_firefly(
        &mut self,
        sys: &System,
        target: f64,
        attempt: u32,
        max_generations: u64,
        seed_centre: bool,
    ) -> Result<mbd_firefly::FireflyResult, FaDaeError> {
        let bounds = Bounds::centered(&self.centre, &self.half)?;
        let settings =
            self.opts
                .firefly
                .clone()
                .seed(step_seed(self.opts.seed, self.step_index, attempt));
        let mut ff = Firefly::new(bounds)
            .settings(settings)
            .termination(self.opts.stage_termination(target, max_generations));
        if seed_centre {
            ff = ff.initial_position(self.centre.clone());
        }
        let result = if self.opts.parallel {
            let obj = ParallelObjective {
                prob: &self.prob,
                sys,
                pool: &self.pool,
            };
            ff.minimize_parallel(&obj)?
        } else {
            let mut obj = SerialObjective {
                prob: &self.prob,
                sys,
                ws: &mut self.ws,
            };
            ff.minimize(&mut obj)?
        };
        Ok(result)
    }

    /// Gauss-Newton on the residual vector from `self.best` (forward-difference Jacobian).
    /// Keeps the best point; returns (iterations, evaluations, objective).
    pub(super) fn polish(&mut self, sys: &System, f_start: f64) -> (usize, usize, f64) {
        let nd = self.best.len();
        let dof = nd / 2;
        let mut evals = 0;
        let prob = &self.prob;
        let ws = &mut self.ws;
        if !prob.residual_vector(sys, ws, &self.best, &mut self.gn_r) {
            return (0, 1, f_start);
        }
        evals += 1;
        let mut f = self.gn_r.iter().map(|r| r * r).sum::<f64>();
        let mut iters = 0;
        for _ in 0..self.opts.polish_max_iter {
            if f == 0.0 {
                break;
            }
            // Jacobian by forward differences, column by column
            let mut ok = true;
            for j in 0..nd {
                let eta = if j < dof {
                    1e-7 * (1.0 + self.best[j].abs())
                } else {
                    1e-6 * (1.0 + self.best[j].abs())
                };
                self.gn_xt.copy_from_slice(&self.best);
                self.gn_xt[j] += eta;
                let eta = self.gn_xt[j] - self.best[j];
                evals += 1;
                if !prob.residual_vector(sys, ws, &self.gn_xt, &mut self.gn_rt) {
                    ok = false;
                    break;
                }
                let a = self.gn_lu.rows_mut();
                for i in 0..nd {
                    a[i * nd + j] = (self.gn_rt[i] - self.gn_r[i]) / eta;
                }
            }
            if !ok || self.gn_lu.factor_lu().is_err() {
                break;
            }
            for i in 0..nd {
                self.gn_dx[i] = -self.gn_r[i];
            }
            self.gn_lu.solve_in_place(&mut self.gn_dx);
            for i in 0..nd {
                self.gn_xt[i] = self.best[i] + self.gn_dx[i];
            }
            evals += 1;
            if !prob.residual_vector(sys, ws, &self.gn_xt, &mut self.gn_rt) {
                break;
            }
            let ft = self.gn_rt.iter().map(|r| r * r).sum::<f64>();
            if ft.is_nan() || ft >= f {
                break;
            }
            iters += 1;
            f = ft;
            self.best.copy_from_slice(&self.gn_xt);
            std::mem::swap(&mut self.gn_r, &mut self.gn_rt);
            let small = (0..nd)
                .all(|i| self.gn_dx[i].abs() <= 4.0 * f64::EPSILON * (1.0 + self.best[i].abs()));
            if small {
                break;
            }
        }
        (iters, evals, f)
    }
}

//! Butcher tableaus as data, and an allocation-free explicit Runge-Kutta stepper for
//! `y' = f(t, y)` on slices, with embedded error estimates and a step-size controller.

use crate::error::SolveError;

/// An explicit Runge-Kutta method as data.
#[derive(Clone, Debug, PartialEq)]
pub struct ButcherTableau {
    /// Name, e.g. "RK4".
    pub name: &'static str,
    /// Stage count.
    pub stages: usize,
    /// Coefficients `a_ij`, row-major `stages x stages`, strictly lower triangular.
    pub a: Vec<f64>,
    /// Weights `b_i`.
    pub b: Vec<f64>,
    /// Nodes `c_i`.
    pub c: Vec<f64>,
    /// Weights of the embedded method (error estimate `h sum (b_i - bhat_i) k_i`), if any.
    pub b_hat: Option<Vec<f64>>,
    /// Classical order of `b`.
    pub order: u32,
    /// Order of the embedded method (0 if none).
    pub embedded_order: u32,
}

impl ButcherTableau {
    fn from_rows(
        name: &'static str,
        rows: &[&[f64]],
        b: &[f64],
        c: &[f64],
        b_hat: Option<&[f64]>,
        order: u32,
        embedded_order: u32,
    ) -> Self {
        let s = b.len();
        let mut a = vec![0.0; s * s];
        for (i, row) in rows.iter().enumerate() {
            for (j, &x) in row.iter().enumerate() {
                a[i * s + j] = x;
            }
        }
        ButcherTableau {
            name,
            stages: s,
            a,
            b: b.to_vec(),
            c: c.to_vec(),
            b_hat: b_hat.map(|x| x.to_vec()),
            order,
            embedded_order,
        }
    }

    /// The order `q` of the embedded error estimate the step-size controller uses, or `None`
    /// for a tableau without one (no `b_hat`, or an embedded order of 0).
    pub fn error_estimate_order(&self) -> Option<u32> {
        match (&self.b_hat, self.embedded_order) {
            (Some(_), q) if q > 0 => Some(q),
            _ => None,
        }
    }

    /// `a_ij`.
    #[inline]
    pub fn a(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.stages + j]
    }

    /// Forward Euler (order 1).
    pub fn euler() -> Self {
        Self::from_rows("Euler", &[&[]], &[1.0], &[0.0], None, 1, 0)
    }
    /// Explicit midpoint (order 2).
    pub fn midpoint() -> Self {
        Self::from_rows(
            "Midpoint",
            &[&[], &[0.5]],
            &[0.0, 1.0],
            &[0.0, 0.5],
            None,
            2,
            0,
        )
    }
    /// Heun's method with Euler embedded (order 2(1)).
    pub fn heun_euler() -> Self {
        Self::from_rows(
            "Heun-Euler 2(1)",
            &[&[], &[1.0]],
            &[0.5, 0.5],
            &[0.0, 1.0],
            Some(&[1.0, 0.0]),
            2,
            1,
        )
    }
    /// Kutta's third-order method.
    pub fn rk3() -> Self {
        Self::from_rows(
            "RK3",
            &[&[], &[0.5], &[-1.0, 2.0]],
            &[1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
            &[0.0, 0.5, 1.0],
            None,
            3,
            0,
        )
    }
    /// The classic fourth-order Runge-Kutta method.
    pub fn rk4() -> Self {
        Self::from_rows(
            "RK4",
            &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]],
            &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
            &[0.0, 0.5, 0.5, 1.0],
            None,
            4,
            0,
        )
    }
    /// Kutta's 3/8 rule (order 4).
    pub fn rk38() -> Self {
        Self::from_rows(
            "RK 3/8",
            &[&[], &[1.0 / 3.0], &[-1.0 / 3.0, 1.0], &[1.0, -1.0, 1.0]],
            &[1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0],
            &[0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0],
            None,
            4,
            0,
        )
    }
    /// Bogacki-Shampine 3(2).
    pub fn bogacki_shampine() -> Self {
        Self::from_rows(
            "Bogacki-Shampine 3(2)",
            &[
                &[],
                &[0.5],
                &[0.0, 0.75],
                &[2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0],
            ],
            &[2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
            &[0.0, 0.5, 0.75, 1.0],
            Some(&[7.0 / 24.0, 0.25, 1.0 / 3.0, 0.125]),
            3,
            2,
        )
    }
    /// Dormand-Prince 5(4) (DOPRI5): order 5 with an embedded order-4 estimate.
    pub fn dopri5() -> Self {
        Self::from_rows(
            "DOPRI5 5(4)",
            &[
                &[],
                &[1.0 / 5.0],
                &[3.0 / 40.0, 9.0 / 40.0],
                &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
                &[
                    19372.0 / 6561.0,
                    -25360.0 / 2187.0,
                    64448.0 / 6561.0,
                    -212.0 / 729.0,
                ],
                &[
                    9017.0 / 3168.0,
                    -355.0 / 33.0,
                    46732.0 / 5247.0,
                    49.0 / 176.0,
                    -5103.0 / 18656.0,
                ],
                &[
                    35.0 / 384.0,
                    0.0,
                    500.0 / 1113.0,
                    125.0 / 192.0,
                    -2187.0 / 6784.0,
                    11.0 / 84.0,
                ],
            ],
            &[
                35.0 / 384.0,
                0.0,
                500.0 / 1113.0,
                125.0 / 192.0,
                -2187.0 / 6784.0,
                11.0 / 84.0,
                0.0,
            ],
            &[0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0],
            Some(&[
                5179.0 / 57600.0,
                0.0,
                7571.0 / 16695.0,
                393.0 / 640.0,
                -92097.0 / 339200.0,
                187.0 / 2100.0,
                1.0 / 40.0,
            ]),
            5,
            4,
        )
    }

    /// Looks a tableau up by name (case-insensitive): euler, midpoint, heun, rk3, rk4, rk38,
    /// bs23, dopri5.
    pub fn by_name(name: &str) -> Result<Self, SolveError> {
        match name.to_ascii_lowercase().as_str() {
            "euler" => Ok(Self::euler()),
            "midpoint" => Ok(Self::midpoint()),
            "heun" | "heun_euler" => Ok(Self::heun_euler()),
            "rk3" => Ok(Self::rk3()),
            "rk4" => Ok(Self::rk4()),
            "rk38" => Ok(Self::rk38()),
            "bs23" | "bogacki_shampine" => Ok(Self::bogacki_shampine()),
            "dopri5" | "dp5" => Ok(Self::dopri5()),
            _ => Err(SolveError::Unsupported(format!("unknown tableau '{name}'"))),
        }
    }

    /// Checks explicitness and the row-sum condition `c_i = sum_j a_ij`.
    pub fn validate(&self) -> Result<(), SolveError> {
        let s = self.stages;
        let bad = |reason: &'static str| SolveError::InvalidParameter {
            parameter: "tableau",
            value: s as f64,
            reason,
        };
        if s == 0 || self.a.len() != s * s || self.b.len() != s || self.c.len() != s {
            return Err(bad("inconsistent sizes"));
        }
        if self.b_hat.as_ref().is_some_and(|b| b.len() != s) {
            return Err(bad("embedded weights have the wrong length"));
        }
        for i in 0..s {
            for j in i..s {
                if self.a(i, j) != 0.0 {
                    return Err(bad("not explicit (a_ij != 0 for j >= i)"));
                }
            }
            let rs: f64 = (0..i).map(|j| self.a(i, j)).sum();
            if (rs - self.c[i]).abs() > 1e-14 {
                return Err(bad("row sums differ from c"));
            }
        }
        Ok(())
    }
}

/// Allocation-free explicit Runge-Kutta stepper for `y' = f(t, y)` with `dim` unknowns.
#[derive(Clone, Debug)]
pub struct ExplicitRk {
    /// The method.
    pub tableau: ButcherTableau,
    k: Vec<Vec<f64>>,
    ytmp: Vec<f64>,
    /// Embedded error estimate of the last step (if the tableau has one).
    pub err: Vec<f64>,
}

impl ExplicitRk {
    /// A stepper for `dim` unknowns.
    pub fn new(tableau: ButcherTableau, dim: usize) -> Result<Self, SolveError> {
        tableau.validate()?;
        let s = tableau.stages;
        Ok(ExplicitRk {
            tableau,
            k: vec![vec![0.0; dim]; s],
            ytmp: vec![0.0; dim],
            err: vec![0.0; dim],
        })
    }

    /// The slope `k_i` of stage `i` of the last step.
    pub(crate) fn slope(&self, i: usize) -> &[f64] {
        &self.k[i]
    }

    /// One step of size `h` from `(t, y)`; `y` is overwritten with `y(t + h)`. `f(t, y, dy)`
    /// writes the derivative and may fail. If the tableau has embedded weights, the error
    /// estimate goes to [`ExplicitRk::err`].
    pub fn step<F>(&mut self, f: &mut F, t: f64, y: &mut [f64], h: f64) -> Result<(), SolveError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SolveError>,
    {
        let tb = &self.tableau;
        let s = tb.stages;
        let n = y.len();
        for i in 0..s {
            self.ytmp[..n].copy_from_slice(y);
            for j in 0..i {
                let a = tb.a(i, j);
                if a != 0.0 {
                    let kj = &self.k[j];
                    for (yt, kv) in self.ytmp.iter_mut().zip(kj) {
                        *yt += h * a * kv;
                    }
                }
            }
            let (ti, ki) = (t + tb.c[i] * h, &mut self.k[i]);
            f(ti, &self.ytmp[..n], &mut ki[..n])?;
        }
        if let Some(bh) = &tb.b_hat {
            for (m, e) in self.err.iter_mut().enumerate().take(n) {
                let mut acc = 0.0;
                for i in 0..s {
                    acc += (tb.b[i] - bh[i]) * self.k[i][m];
                }
                *e = h * acc;
            }
        }
        for i in 0..s {
            let b = tb.b[i];
            if b != 0.0 {
                for (yv, kv) in y.iter_mut().zip(&self.k[i]) {
                    *yv += h * b * kv;
                }
            }
        }
        Ok(())
    }
}

/// Standard step-size controller for embedded pairs:
/// `h_new = h * min(fac_max, max(fac_min, safety * err^(-1/(p+1))))` with
/// `err = rms(e_i / (atol + rtol |y_i|))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepController {
    /// Absolute tolerance.
    pub atol: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Safety factor.
    pub safety: f64,
    /// Smallest shrink factor.
    pub fac_min: f64,
    /// Largest growth factor.
    pub fac_max: f64,
    /// Smallest step allowed before giving up.
    pub h_min: f64,
}

impl StepController {
    /// Checks every field; an error names the field (`controller.<field>`).
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |parameter, value, reason| {
            Err(SolveError::InvalidParameter {
                parameter,
                value,
                reason,
            })
        };
        if !(self.atol.is_finite() && self.atol >= 0.0) {
            return bad(
                "controller.atol",
                self.atol,
                "must be non-negative and finite",
            );
        }
        if !(self.rtol.is_finite() && self.rtol >= 0.0) {
            return bad(
                "controller.rtol",
                self.rtol,
                "must be non-negative and finite",
            );
        }
        if !(self.atol > 0.0 || self.rtol > 0.0) {
            return bad(
                "controller.atol",
                self.atol,
                "atol and rtol cannot both be zero",
            );
        }
        if !(self.safety > 0.0 && self.safety <= 1.0) {
            return bad("controller.safety", self.safety, "must lie in (0, 1]");
        }
        if !(self.fac_min > 0.0 && self.fac_min < 1.0) {
            return bad("controller.fac_min", self.fac_min, "must lie in (0, 1)");
        }
        if !(self.fac_max > 1.0 && self.fac_max.is_finite()) {
            return bad(
                "controller.fac_max",
                self.fac_max,
                "must be finite and above 1",
            );
        }
        if !(self.h_min.is_finite() && self.h_min > 0.0) {
            return bad(
                "controller.h_min",
                self.h_min,
                "must be positive and finite",
            );
        }
        Ok(())
    }
}

impl Default for StepController {
    fn default() -> Self {
        StepController {
            atol: 1e-8,
            rtol: 1e-8,
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 5.0,
            h_min: 1e-12,
        }
    }
}

impl StepController {
    /// Scaled RMS error norm of `err` relative to `y`.
    pub fn error_norm(&self, err: &[f64], y: &[f64]) -> f64 {
        let n = err.len().max(1) as f64;
        (err.iter()
            .zip(y)
            .map(|(e, y)| (e / (self.atol + self.rtol * y.abs())).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    }
    /// The factor to multiply `h` by after a step with error norm `en`, for an embedded pair whose
    /// lower order is `q` (the exponent uses `q + 1`).
    pub fn factor(&self, en: f64, q: u32) -> f64 {
        if en == 0.0 {
            return self.fac_max;
        }
        (self.safety * en.powf(-1.0 / (q as f64 + 1.0))).clamp(self.fac_min, self.fac_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order_on_exp(tb: ButcherTableau) -> f64 {
        // y' = -y + sin t, y(0) = 1 ; exact: y = 1.5 e^-t + (sin t - cos t)/2
        let exact = |t: f64| 1.5 * (-t).exp() + 0.5 * (t.sin() - t.cos());
        let mut errs = vec![];
        for &n in &[20usize, 40] {
            let h = 1.0 / n as f64;
            let mut rk = ExplicitRk::new(tb.clone(), 1).unwrap();
            let mut y = [1.0];
            let mut f = |t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = -y[0] + t.sin();
                Ok(())
            };
            for k in 0..n {
                rk.step(&mut f, k as f64 * h, &mut y, h).unwrap();
            }
            errs.push((y[0] - exact(1.0)).abs());
        }
        (errs[0] / errs[1]).log2()
    }

    #[test]
    fn tableaus_have_their_orders() {
        for tb in [
            ButcherTableau::euler(),
            ButcherTableau::midpoint(),
            ButcherTableau::heun_euler(),
            ButcherTableau::rk3(),
            ButcherTableau::rk4(),
            ButcherTableau::rk38(),
            ButcherTableau::bogacki_shampine(),
            ButcherTableau::dopri5(),
        ] {
            tb.validate().unwrap();
            let p = tb.order as f64;
            let o = order_on_exp(tb.clone());
            assert!(
                (o - p).abs() < 0.2,
                "{}: measured {o}, expected {p}",
                tb.name
            );
        }
    }

    #[test]
    fn embedded_error_estimates_have_lower_order() {
        for tb in [ButcherTableau::dopri5(), ButcherTableau::bogacki_shampine()] {
            let q = tb.embedded_order as f64;
            let mut ests = vec![];
            for &h in &[0.1, 0.05] {
                let mut rk = ExplicitRk::new(tb.clone(), 1).unwrap();
                let mut y = [1.0];
                let mut f = |_t: f64, y: &[f64], dy: &mut [f64]| {
                    dy[0] = y[0].cos();
                    Ok(())
                };
                rk.step(&mut f, 0.0, &mut y, h).unwrap();
                ests.push(rk.err[0].abs());
            }
            let o = (ests[0] / ests[1]).log2();
            assert!(
                (o - (q + 1.0)).abs() < 0.3,
                "{}: local error order {o}",
                tb.name
            );
        }
    }

    #[test]
    fn unknown_name_and_implicit_tableau_are_errors() {
        assert!(ButcherTableau::by_name("nope").is_err());
        let mut t = ButcherTableau::rk4();
        t.a[0] = 1.0;
        assert!(t.validate().is_err());
        assert!(ExplicitRk::new(t, 2).is_err());
    }
}

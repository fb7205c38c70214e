//! The exact motion of a torque-free rigid body (Euler's equations): the body-frame angular
//! velocity by Jacobi elliptic functions, the orientation by two Euler angles relative to the
//! constant angular momentum and one quadrature. A reference for the spatial solvers, including
//! the flips of a body spun near its intermediate axis ("tennis racket", Dzhanibekov).
//!
//! With principal moments `J`, body-frame angular velocity `w` and rotation `R` (columns: the
//! principal axes in global axes), `J_i w_i' = e_ijk (J_j - J_k) w_j w_k` and `R' = R [w]x`.
//! `2T = sum J_i w_i^2` and `L^2 = sum J_i^2 w_i^2` are constant. Sorting the moments,
//! `J_lo <= J_mid <= J_hi`, the body circulates about the axis `c` = `hi` if `L^2 > 2T J_mid`,
//! `c` = `lo` if `L^2 < 2T J_mid`; with `a` the other extreme axis and `b = mid`,
//!
//! ```text
//! w_a = A cn(u | m),   w_b = beta B sn(u | m),   w_c = gamma C dn(u | m),   u = lambda t + u0
//! ```
//!
//! with `A, B, C, lambda, m` from the two integrals and the signs `beta gamma` fixed by the
//! equations. On the separatrix `L^2 = 2T J_mid` (`m = 1`) `sn = tanh`, `cn = dn = sech`: one
//! crossing of `w_b = 0`, no period. `docs/torque-free-body.md` has the derivation.

use super::exact::{reduce, Agm};
use crate::error::ModelError;
use nalgebra::{Matrix3, Vector3};

/// The element name in errors.
const ELEMENT: &str = "torque-free body";
/// Largest deviation of `R0^T R0` from the identity and of `det R0` from 1.
const ROTATION_TOLERANCE: f64 = 1e-10;
/// On the separatrix the precession integrand's varying part is `O(sech^2 u)`: below `1e-34`
/// of its constant part beyond `|u| = 40`, where the integral is taken as complete.
const SEPARATRIX_SPAN: f64 = 40.0;
/// Most Gauss-Legendre panels of the precession quadrature.
const MAX_PANELS: usize = 1 << 12;
/// Most flip times [`TorqueFreeBody::flip_times`] returns.
const MAX_FLIPS: usize = 1 << 20;
/// The positive nodes of 8-point Gauss-Legendre quadrature on `[-1, 1]`.
const GL_NODES: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
/// The weights of [`GL_NODES`].
const GL_WEIGHTS: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// How a [`TorqueFreeBody`] moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TorqueFreeMotion {
    /// `w` is constant: at rest, spinning about a principal axis (the intermediate one
    /// included), or about any axis of a plane of equal moments.
    Steady,
    /// `L^2 > 2 T J_mid`: `w` circulates about the axis of the largest moment (whose component
    /// keeps its sign), and the intermediate component flips sign every half period.
    AboutLargest,
    /// `L^2 < 2 T J_mid`: as [`TorqueFreeMotion::AboutLargest`] about the smallest moment.
    AboutSmallest,
    /// `L^2 = 2 T J_mid` (within rounding) and not steady: the intermediate component crosses
    /// zero once and tends to `+-B` as `t -> +-inf`; no period.
    Separatrix,
}

/// The time dependence of `w`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// `w = w0`; the body turns about `w0` at `|w0|`.
    Steady,
    /// `u = lambda t + u0` with parameter `m` (`m1 = 1 - m`), quarter period `K(m)` of `u`,
    /// period `4 K / lambda` of `w`.
    Elliptic {
        m: f64,
        m1: f64,
        quarter: f64,
        u0: f64,
        period: f64,
    },
    /// `u = lambda t + u0`, `sn = tanh u`, `cn = dn = sech u`.
    Separatrix { u0: f64 },
}

/// The exact torque-free motion of a rigid body from its principal moments, its initial
/// body-frame angular velocity and its initial orientation. See the module documentation.
///
/// Accuracy: the functions are evaluated in double precision after reducing `t` by the period,
/// so beyond rounding the error grows only with the rounding of `t` itself (`|w'| ulp(t)`).
/// The precession quadrature is refined until two successive estimates agree to `8 eps` of
/// the precession angle over a quarter period (elliptic) or over `|u| <= 40` (separatrix). In
/// the tests, `omega` and `rotation` agree with a double-double Taylor integration to `4e-14`
/// over three periods, the separatrix and within `2e-6` of it included
/// (`docs/torque-free-body.md`).
#[derive(Clone, Debug, PartialEq)]
pub struct TorqueFreeBody {
    /// Principal moments as given.
    j: [f64; 3],
    /// Initial body-frame angular velocity.
    omega0: Vector3<f64>,
    /// Initial rotation as given.
    r0: Matrix3<f64>,
    motion: TorqueFreeMotion,
    kind: Kind,
    /// Body axes `[a, b, c]`: the other extreme, the intermediate, the circulation axis.
    axes: [usize; 3],
    /// Signed amplitudes: `w_a = amp[0] cn`, `w_b = amp[1] sn`, `w_c = amp[2] dn`.
    amp: [f64; 3],
    /// `du/dt`.
    lambda: f64,
    /// The moments divided by the largest (the motion depends only on their ratios).
    jn: [f64; 3],
    /// `|jn w|`.
    l_mag: f64,
    /// `Pi`: columns `sigma e_a`, `e_b`, `e_c` (`sigma` makes `det Pi = 1`); body axes of the
    /// z-x-z Euler angles with the pole on `c`.
    pole: Matrix3<f64>,
    sigma: f64,
    /// `R0 Pi (Rx(theta0) Rz(psi0))^T`: third column along `L`.
    frame: Matrix3<f64>,
    /// Panel width (in `u`) of the precession quadrature.
    panel: f64,
    /// `Gamma(K)` (elliptic) or `Gamma(inf)` (separatrix), `Gamma(u) = int_0^u g`.
    gamma_ref: f64,
    /// `Gamma(u0)`.
    gamma0: f64,
}

/// The parity of a permutation of `0, 1, 2`.
fn parity(p: [usize; 3]) -> f64 {
    if (p[1] + 3 - p[0]) % 3 == 1 {
        1.0
    } else {
        -1.0
    }
}

fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// `int_0^len f` by `panels` equal panels of 8-point Gauss-Legendre, compensated sum.
fn gauss(f: &dyn Fn(f64) -> f64, len: f64, panels: usize) -> f64 {
    let h = len / panels as f64;
    let (mut sum, mut carry) = (0.0f64, 0.0f64);
    for p in 0..panels {
        let mid = (p as f64 + 0.5) * h;
        let mut panel = 0.0;
        for (x, w) in GL_NODES.iter().zip(GL_WEIGHTS) {
            panel += w * (f(mid - 0.5 * h * x) + f(mid + 0.5 * h * x));
        }
        super::exact::neumaier_add(&mut sum, &mut carry, panel);
    }
    0.5 * h * (sum + carry)
}

impl TorqueFreeBody {
    /// The motion from principal moments `j = [J1, J2, J3]` (any order; positive, finite, each
    /// at most the sum of the other two within `4 eps`), the initial body-frame angular
    /// velocity `omega0` (finite) and the initial rotation `r0` (columns: the principal axes in
    /// global axes; orthonormal with determinant +1 within `1e-10`, used as given).
    ///
    /// Errors are [`ModelError::InvalidParameter`] of the element `"torque-free body"` naming
    /// `J1`, `J2`, `J3`, `omega0` (a component not finite, or the energy overflows) or `R0`
    /// (value: the largest deviation from orthonormality or of the determinant from 1).
    pub fn new(j: [f64; 3], omega0: Vector3<f64>, r0: Matrix3<f64>) -> Result<Self, ModelError> {
        let bad = |parameter, value, reason| ModelError::InvalidParameter {
            element: ELEMENT.into(),
            parameter,
            value,
            reason,
        };
        const NAMES: [&str; 3] = ["J1", "J2", "J3"];
        for i in 0..3 {
            if !(j[i].is_finite() && j[i] > 0.0) {
                return Err(bad(NAMES[i], j[i], "must be positive and finite"));
            }
        }
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&p, &q| j[p].total_cmp(&j[q]));
        let [lo, mid, hi] = idx;
        if j[hi] > (j[lo] + j[mid]) * (1.0 + 4.0 * f64::EPSILON) {
            return Err(bad(
                NAMES[hi],
                j[hi],
                "exceeds the sum of the other two principal moments (triangle inequality)",
            ));
        }
        for i in 0..3 {
            if !omega0[i].is_finite() {
                return Err(bad("omega0", omega0[i], "must be finite"));
            }
        }
        let energy: f64 = (0..3).map(|i| j[i] * omega0[i] * omega0[i]).sum();
        if !energy.is_finite() {
            return Err(bad("omega0", omega0.amax(), "overflows the kinetic energy"));
        }
        let dev = (r0.transpose() * r0 - Matrix3::identity()).amax();
        let det_dev = (r0.determinant() - 1.0).abs();
        if !(dev <= ROTATION_TOLERANCE && det_dev <= ROTATION_TOLERANCE) {
            let value = if dev.is_nan() { dev } else { dev.max(det_dev) };
            return Err(bad(
                "R0",
                value,
                "must be orthonormal with determinant +1 (within 1e-10)",
            ));
        }
        let jn = j.map(|x| x / j[hi]);
        let mut body = TorqueFreeBody {
            j,
            omega0,
            r0,
            motion: TorqueFreeMotion::Steady,
            kind: Kind::Steady,
            axes: [lo, mid, hi],
            amp: [0.0; 3],
            lambda: 0.0,
            jn,
            l_mag: (0..3)
                .map(|i| (jn[i] * omega0[i]).powi(2))
                .sum::<f64>()
                .sqrt(),
            pole: Matrix3::identity(),
            sigma: 1.0,
            frame: r0,
            panel: 1.0,
            gamma_ref: 0.0,
            gamma0: 0.0,
        };
        // Euler's right-hand side exactly zero: w is constant
        let steady = (0..3).all(|i| {
            let (p, q) = ((i + 1) % 3, (i + 2) % 3);
            (jn[p] - jn[q]) * omega0[p] * omega0[q] == 0.0
        });
        if !steady {
            body.solve(omega0);
        }
        Ok(body)
    }

    /// The elliptic (or separatrix) solution through `omega0`; leaves the body steady if an
    /// amplitude underflows (the motion then differs from steady by less than rounding).
    fn solve(&mut self, omega0: Vector3<f64>) {
        let jn = self.jn;
        let [lo, mid, hi] = self.axes;
        let scale = omega0.amax();
        let w = omega0 / scale;
        let (il, im, ih) = (jn[lo], jn[mid], jn[hi]);
        let (wl, wm, wh) = (w[lo], w[mid], w[hi]);
        // L^2 - 2T J_lo, 2T J_hi - L^2 (sums of non-negative terms) and L^2 - 2T J_mid
        let d_lo = im * (im - il) * wm * wm + ih * (ih - il) * wh * wh;
        let d_hi = il * (ih - il) * wl * wl + im * (ih - im) * wm * wm;
        let (p_hi, p_lo) = (ih * (ih - im) * wh * wh, il * (im - il) * wl * wl);
        let d_mid = p_hi - p_lo;
        let prod = il * im * ih;
        let separatrix = d_mid.abs() <= 4.0 * f64::EPSILON * (p_hi + p_lo);
        // [A^2, B^2, C^2, lambda^2] (scaled), m, m1 and the axes [a, b, c]
        let (sq, m, m1, axes, motion) = if separatrix || d_mid > 0.0 {
            let sq = [
                d_hi / (il * (ih - il)),
                d_hi / (im * (ih - im)),
                d_lo / (ih * (ih - il)),
                (ih - im) * d_lo / prod,
            ];
            let m = (im - il) * d_hi / ((ih - im) * d_lo);
            let m1 = (ih - il) * d_mid / ((ih - im) * d_lo);
            let motion = if separatrix {
                TorqueFreeMotion::Separatrix
            } else {
                TorqueFreeMotion::AboutLargest
            };
            (sq, m, m1, [lo, mid, hi], motion)
        } else {
            let sq = [
                d_lo / (ih * (ih - il)),
                d_lo / (im * (im - il)),
                d_hi / (il * (ih - il)),
                (im - il) * d_hi / prod,
            ];
            let m = (ih - im) * d_lo / ((im - il) * d_hi);
            let m1 = (ih - il) * (-d_mid) / ((im - il) * d_hi);
            (sq, m, m1, [hi, mid, lo], TorqueFreeMotion::AboutSmallest)
        };
        let [amp_a, amp_b, amp_c, lam] = sq.map(f64::sqrt);
        if ![amp_a, amp_b, amp_c, lam]
            .iter()
            .all(|x| x.is_finite() && *x > 0.0)
        {
            return;
        }
        let [a, b, c] = axes;
        let eps = parity(axes);
        // beta gamma = parity(a, b, c) sign(J_c - J_a), from the equations of w_a, w_b, w_c
        let s = if c == hi { eps } else { -eps };
        let gamma = w[c].signum();
        let (kind, alpha) = if motion == TorqueFreeMotion::Separatrix {
            let alpha = w[a].signum();
            let beta = s * alpha * gamma;
            let sech0 = (w[a].abs() / amp_a).max(w[c].abs() / amp_c).min(1.0);
            let u0 = (beta * w[b] / amp_b / sech0).asinh();
            if !u0.is_finite() {
                return;
            }
            (Kind::Separatrix { u0 }, alpha)
        } else {
            let beta = s * gamma;
            let agm = Agm::new(m, m1);
            let quarter = agm.k();
            let u0 = agm.f((beta * w[b] / amp_b).atan2(w[a] / amp_a));
            let period = 4.0 * quarter / (lam * scale);
            (
                Kind::Elliptic {
                    m,
                    m1,
                    quarter,
                    u0,
                    period,
                },
                1.0,
            )
        };
        let beta = s * alpha * gamma;
        self.motion = motion;
        self.kind = kind;
        self.axes = axes;
        self.amp = [alpha * amp_a, beta * amp_b, gamma * amp_c].map(|x| x * scale);
        self.lambda = lam * scale;
        self.sigma = eps;
        let mut pole = Matrix3::zeros();
        pole[(a, 0)] = eps;
        pole[(b, 1)] = 1.0;
        pole[(c, 2)] = 1.0;
        self.pole = pole;
        self.precession_setup();
        self.frame = self.r0 * self.pole * self.euler(self.omega0).transpose();
    }

    /// The varying part `g` of the precession rate `phi' = |L| / J_b + g`, from `sn^2, cn^2`:
    /// `g = |L| J_a (J_b - J_a) A^2 cn^2 / (J_b (J_a^2 A^2 cn^2 + J_b^2 B^2 sn^2))`.
    fn g(&self, sn2: f64, cn2: f64) -> f64 {
        let [a, b, _] = self.axes;
        let (ja, jb) = (self.jn[a], self.jn[b]);
        let (aa, bb) = (self.amp[0] * self.amp[0], self.amp[1] * self.amp[1]);
        let den = jb * (ja * ja * aa * cn2 + jb * jb * bb * sn2);
        self.l_mag * ja * (jb - ja) * aa * cn2 / den
    }

    /// `Gamma(r) = int_0^r g du` for `|r| <= K` (elliptic) or any `r` (separatrix, integral
    /// cut at `|u| = 40`), by panels of width at most `self.panel`.
    fn gamma_partial(&self, r: f64) -> f64 {
        let len = match self.kind {
            Kind::Separatrix { .. } => r.abs().min(SEPARATRIX_SPAN),
            _ => r.abs(),
        };
        if len == 0.0 {
            return 0.0;
        }
        let panels = ((len / self.panel).ceil() as usize).clamp(1, 2 * MAX_PANELS);
        r.signum() * gauss(&|u| self.g_at(u), len, panels)
    }

    /// `g` at the elliptic argument `u` (`|u| <= K` in the elliptic case).
    fn g_at(&self, u: f64) -> f64 {
        match self.kind {
            Kind::Elliptic { m, m1, .. } => {
                let [_, sn, cn, _] = Agm::new(m, m1).jacobi(u, m, m1);
                self.g(sn * sn, cn * cn)
            }
            Kind::Separatrix { .. } => {
                let sech = 1.0 / u.cosh();
                let tanh = u.tanh();
                self.g(tanh * tanh, sech * sech)
            }
            Kind::Steady => 0.0,
        }
    }

    /// The panel width and `Gamma(K)` (or `Gamma(inf)`), halving the panels until two
    /// estimates agree to `8 eps` of the precession angle over the interval; then `Gamma(u0)`.
    fn precession_setup(&mut self) {
        let len = match self.kind {
            Kind::Elliptic { quarter, .. } => quarter,
            Kind::Separatrix { .. } => SEPARATRIX_SPAN,
            Kind::Steady => return,
        };
        let linear = self.l_mag / self.jn[self.axes[1]] * len;
        let f = |u: f64| self.g_at(u);
        let mut panels = 2;
        let mut prev = gauss(&f, len, panels);
        loop {
            let cur = gauss(&f, len, 2 * panels);
            panels *= 2;
            if (cur - prev).abs() <= 8.0 * f64::EPSILON * (cur.abs() + linear.abs())
                || panels >= MAX_PANELS
            {
                prev = cur;
                break;
            }
            prev = cur;
        }
        self.gamma_ref = prev;
        self.panel = len / panels as f64;
        self.gamma0 = match self.kind {
            Kind::Elliptic { quarter, u0, .. } => {
                let (n, r) = reduce(u0, quarter);
                2.0 * n * self.gamma_ref + self.gamma_partial(r)
            }
            Kind::Separatrix { u0 } => self.gamma_partial(u0),
            Kind::Steady => 0.0,
        };
    }

    /// `[sn, cn, dn]` at `u(t)` and, if `with_gamma`, `Gamma(u(t)) - Gamma(u0)`.
    fn at(&self, t: f64, with_gamma: bool) -> ([f64; 3], f64) {
        match self.kind {
            Kind::Steady => ([0.0, 1.0, 1.0], 0.0),
            Kind::Separatrix { u0 } => {
                let u = self.lambda.mul_add(t, u0);
                let sech = 1.0 / u.cosh();
                let gamma = if with_gamma {
                    let full = if u.abs() > SEPARATRIX_SPAN {
                        u.signum() * self.gamma_ref
                    } else {
                        self.gamma_partial(u)
                    };
                    full - self.gamma0
                } else {
                    0.0
                };
                ([u.tanh(), sech, sech], gamma)
            }
            Kind::Elliptic {
                m,
                m1,
                quarter,
                u0,
                period,
            } => {
                // t reduced by the period first, so u stays within a period of u0
                let turns = (t / period).round();
                let tr = (-turns).mul_add(period, t);
                let (n, r) = reduce(self.lambda.mul_add(tr, u0), quarter);
                let [_, sn, cn, dn] = Agm::new(m, m1).jacobi(r, m, m1);
                let sign = if n.rem_euclid(2.0) == 0.0 { 1.0 } else { -1.0 };
                let gamma = if with_gamma {
                    (4.0 * turns + 2.0 * n).mul_add(self.gamma_ref, self.gamma_partial(r))
                        - self.gamma0
                } else {
                    0.0
                };
                ([sign * sn, sign * cn, dn], gamma)
            }
        }
    }

    /// The body-frame angular velocity from `[sn, cn, dn]`.
    fn omega_from(&self, [sn, cn, dn]: [f64; 3]) -> Vector3<f64> {
        let [a, b, c] = self.axes;
        let mut w = Vector3::zeros();
        w[a] = self.amp[0] * cn;
        w[b] = self.amp[1] * sn;
        w[c] = self.amp[2] * dn;
        w
    }

    /// `Rx(theta) Rz(psi)`: `L`'s direction in the Euler axes `Pi^T l_b` is
    /// `(sin theta sin psi, sin theta cos psi, cos theta)`.
    fn euler(&self, w: Vector3<f64>) -> Matrix3<f64> {
        let [a, b, c] = self.axes;
        let (la, lb, lc) = (self.jn[a] * w[a], self.jn[b] * w[b], self.jn[c] * w[c]);
        let theta = la.hypot(lb).atan2(lc);
        let psi = (self.sigma * la).atan2(lb);
        rot_x(theta) * rot_z(psi)
    }

    /// The body-frame angular velocity (rad/s, principal axes in the order given) at any
    /// finite time `t` (s), negative included.
    pub fn omega(&self, t: f64) -> Vector3<f64> {
        match self.kind {
            Kind::Steady => self.omega0,
            _ => self.omega_from(self.at(t, false).0),
        }
    }

    /// The rotation at any finite time `t` (columns: the principal axes in global axes),
    /// `R(0) = R0`. `R = F Rz(phi) Rx(theta) Rz(psi) Pi^T` with `F` constant (third column
    /// along `L`) and `Pi` the permutation putting the circulation axis last: `theta`, `psi`
    /// place `L`'s direction in the body in closed form; the precession about `L`,
    /// `phi(t) = |L| t / J_b + (Gamma(u) - Gamma(u0)) / lambda`, is the one quadrature (see the
    /// type's accuracy note). A steady body turns about `omega0` at `|omega0|`.
    pub fn rotation(&self, t: f64) -> Matrix3<f64> {
        if self.kind == Kind::Steady {
            let rate = self.omega0.norm();
            if rate == 0.0 {
                return self.r0;
            }
            let n = self.omega0 / rate;
            let (s, c) = (rate * t).sin_cos();
            let k = n.cross_matrix();
            return self.r0 * (Matrix3::identity() + k * s + k * k * (1.0 - c));
        }
        let (jac, gamma) = self.at(t, true);
        let phi = (self.l_mag / self.jn[self.axes[1]]).mul_add(t, gamma / self.lambda);
        self.frame * rot_z(phi) * self.euler(self.omega_from(jac)) * self.pole.transpose()
    }

    /// How the body moves.
    pub fn motion(&self) -> TorqueFreeMotion {
        self.motion
    }

    /// The index (0, 1 or 2, in the order given) of the intermediate principal axis, whose
    /// `omega` component [`TorqueFreeBody::flip_times`] follows. With two equal moments it is
    /// the later of the pair that sorts in the middle (sorting is stable).
    pub fn intermediate_axis(&self) -> usize {
        self.axes[1]
    }

    /// The period (s) of `omega(t)`, `4 K(m) / lambda` (`2 pi / lambda` with two equal
    /// moments); `None` if steady or on the separatrix.
    pub fn period(&self) -> Option<f64> {
        match self.kind {
            Kind::Elliptic { period, .. } => Some(period),
            _ => None,
        }
    }

    /// The flips: the times, ascending, between 0 and `t_end` (either sign, both ends
    /// included), at which the intermediate-axis component of `omega` crosses zero and
    /// changes sign, the zeros of `sn(lambda t + u0)`: `t_n = (2 n K - u0) / lambda`, every
    /// half period. The separatrix has one, at `-u0 / lambda`; a steady body none. At most
    /// 2^20 (the first ones from the interval's start); empty if `t_end` is not finite.
    pub fn flip_times(&self, t_end: f64) -> Vec<f64> {
        if !t_end.is_finite() {
            return Vec::new();
        }
        let (t0, t1) = (t_end.min(0.0), t_end.max(0.0));
        match self.kind {
            Kind::Steady => Vec::new(),
            Kind::Separatrix { u0 } => {
                let t = -u0 / self.lambda;
                if (t0..=t1).contains(&t) {
                    vec![t]
                } else {
                    Vec::new()
                }
            }
            Kind::Elliptic { quarter, u0, .. } => {
                let half = 2.0 * quarter;
                let first = (self.lambda.mul_add(t0, u0) / half).ceil();
                let last = (self.lambda.mul_add(t1, u0) / half).floor();
                let mut out = Vec::new();
                for i in 0..MAX_FLIPS {
                    let n = first + i as f64;
                    if n > last {
                        break;
                    }
                    let t = half.mul_add(n, -u0) / self.lambda;
                    if (t0..=t1).contains(&t) {
                        out.push(t);
                    }
                }
                out
            }
        }
    }

    /// The kinetic energy `T = 1/2 sum J_i w_i^2` (J), constant.
    pub fn energy(&self) -> f64 {
        0.5 * (0..3)
            .map(|i| self.j[i] * self.omega0[i] * self.omega0[i])
            .sum::<f64>()
    }

    /// The angular momentum in global axes, `R J w` (constant): `R0 J omega0`.
    pub fn angular_momentum_global(&self) -> Vector3<f64> {
        self.r0 * Vector3::from_fn(|i, _| self.j[i] * self.omega0[i])
    }
}

#[cfg(test)]
#[path = "tumbling_tests.rs"]
mod tests;

"""Prototype of the plain and preadjusted (1,1) / (2,2) constrained Galerkin schemes in Cartesian
coordinates (library discretisation: Lobatto control points, Gauss quadrature of the action,
constraints at every control point), and their pendulum period errors.

  python3 prototype.py [s1|s2|spring|all]

s1:     point on the unit circle and rod pendulum, 10/45/90/120 deg, plain (1,1), (1,1) + the
        derived e (Cartesian invariants); h = 0.1, 0.05, 0.025; relative period error and order.
s2:     the same for (2,2), plain and + h^4 e4 (reduced-coordinate e4 from s2_constrained.py);
        h = 0.2, 0.1, 0.05.
spring: rod pendulum + a nonlinear spring (tip to a fixed point): (1,1) with the derived e_mid
        against the issue's prototype e_trap (which differs by 1/8 v^T Hess V v).
"""
import sys, os, math
import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
G_ACC = 9.81


# ---------------------------------------------------------------- systems
class System:
    def __init__(self, qs, Mdiag, V, Phi, chi_th, theta_of_q, name):
        self.name = name
        self.n = len(qs)
        self.m = len(Phi)
        self.M = np.array(Mdiag, float)
        self.Minv = 1.0 / self.M
        qv = sp.Matrix(qs)
        self.V = sp.lambdify([qs], V, 'numpy')
        self.gV = sp.lambdify([qs], [sp.diff(V, x) for x in qs], 'numpy')
        self.HV = sp.lambdify([qs], sp.hessian(V, qs), 'numpy')
        self.Phi = sp.lambdify([qs], Phi, 'numpy')
        self.G = sp.lambdify([qs], sp.Matrix(Phi).jacobian(qv), 'numpy')
        self.HP = [sp.lambdify([qs], sp.hessian(p, qs), 'numpy') for p in Phi]
        th = sp.Symbol('th')
        self.chi = sp.lambdify([th], chi_th(th), 'numpy')
        self.theta = theta_of_q

    def gradV(self, q):
        return np.array(self.gV(q), float)

    def hessV(self, q):
        return np.array(self.HV(q), float)

    def Gq(self, q):
        return np.array(self.G(q), float).reshape(self.m, self.n)

    def phi(self, q):
        return np.array(self.Phi(q), float)

    def e2(self, q, v, which='mid'):
        """Cartesian preadjustment term e(q, v) of the (1,1) scheme."""
        g = self.gradV(q)
        G = self.Gq(q)
        S = (G * self.Minv) @ G.T
        mu0 = np.linalg.solve(S, G @ (self.Minv * g))
        fT = -g + G.T @ mu0
        Hs = [np.array(H(q), float) for H in self.HP]
        HPmu = sum(mu0[k] * Hs[k] for k in range(self.m))
        gam = np.array([v @ Hk @ v for Hk in Hs])
        fMf = fT @ (self.Minv * fT)
        vHv = v @ self.hessV(q) @ v
        vPv = v @ HPmu @ v
        gSg = gam @ np.linalg.solve(S, gam)
        if which == 'trap':
            return -fMf / 24 + (vHv - vPv) / 12 + gSg / 24
        return -fMf / 24 - (vHv + 2 * vPv) / 24 + gSg / 24


def circle():
    x, y = sp.symbols('x y')
    return System([x, y], [1.0, 1.0], G_ACC * y, [x**2 + y**2 - 1],
                  lambda t: [sp.sin(t), -sp.cos(t)], lambda q: math.atan2(q[0], -q[1]), 'circle')


def rod(spring=None):
    x, y, p = sp.symbols('x y p')
    l, m = 1.0, 1.0
    V = m * G_ACC * y
    if spring is not None:
        k, L0, P = spring
        tx, ty = x + l / 2 * sp.cos(p), y + l / 2 * sp.sin(p)
        V = V + k / 2 * (sp.sqrt((tx - P[0])**2 + (ty - P[1])**2) - L0)**2
    return System([x, y, p], [m, m, m * l**2 / 12], V,
                  [x - l / 2 * sp.cos(p), y - l / 2 * sp.sin(p)],
                  lambda t: [l / 2 * sp.sin(t), -l / 2 * sp.cos(t), t - sp.pi / 2],
                  lambda q: q[2] + math.pi / 2, 'rod' if spring is None else 'rod+spring')


# ---------------------------------------------------------------- the scheme
def lagrange_tables(s):
    tn = np.linspace(0, 1, s + 1)  # Lobatto control points for s = 1, 2 (0, 1/2, 1)
    c, b = np.polynomial.legendre.leggauss(s)
    c, b = (c + 1) / 2, b / 2
    A = np.zeros((s, s + 1))
    D = np.zeros((s, s + 1))
    for nu in range(s + 1):
        others = [tn[k] for k in range(s + 1) if k != nu]
        poly = np.poly1d(others, r=True) / np.prod([tn[nu] - o for o in others])
        A[:, nu] = poly(c)
        D[:, nu] = poly.deriv()(c)
    return b, A, D


class Scheme:
    def __init__(self, sysm, s, pre=None, which='mid'):
        self.S, self.s, self.pre, self.which = sysm, s, pre, which
        self.b, self.A, self.D = lagrange_tables(s)
        if pre == 'e4':
            e4 = sp.sympify(eval(open(os.path.join(HERE, 'e4_pendulum.txt')).read(), sp.__dict__))
            sy = {x.name: x for x in e4.free_symbols}
            th, w, m, r, J, g = [sy.get(k, sp.Symbol(k)) for k in ('theta', 'omega', 'm', 'r', 'J', 'g')]
            pars = {'circle': {m: 1, r: 1, J: 0, g: G_ACC}, 'rod': {m: 1, r: 0.5, J: 1 / 12, g: G_ACC}}[sysm.name]
            self.e4f = sp.lambdify([th, w], e4.subs(pars), 'numpy')

    def Ed(self, Q0, Q1, h):
        """preadjustment part of L_d (depends on the step's end points only)."""
        if self.pre is None:
            return 0.0
        if self.pre == 'e2':
            v = (Q1 - Q0) / h
            return h**3 / 2 * (self.S.e2(Q0, v, self.which) + self.S.e2(Q1, v, self.which))
        t0, t1 = self.S.theta(Q0), self.S.theta(Q1)
        w = (t1 - t0) / h
        return h**5 / 2 * (self.e4f(t0, w) + self.e4f(t1, w))

    def dEd(self, Q0, Q1, h):
        n = self.S.n
        g0, g1 = np.zeros(n), np.zeros(n)
        if self.pre is None:
            return g0, g1
        d = 1e-6  # central differences: error ~1e-12 relative of an O(h^3) term
        for i in range(n):
            e = np.zeros(n)
            e[i] = d
            g0[i] = (self.Ed(Q0 + e, Q1, h) - self.Ed(Q0 - e, Q1, h)) / (2 * d)
            g1[i] = (self.Ed(Q0, Q1 + e, h) - self.Ed(Q0, Q1 - e, h)) / (2 * d)
        return g0, g1

    def DL(self, Q, h, pre=True):
        """D_nu L_d for nu = 0..s (Q: (s+1) x n)."""
        S = self.S
        out = np.zeros_like(Q)
        for j in range(self.s):
            qj = self.A[j] @ Q
            vj = self.D[j] @ Q / h
            mv, gv = S.M * vj, S.gradV(qj)
            for nu in range(self.s + 1):
                out[nu] += self.b[j] * (self.D[j, nu] * mv - h * self.A[j, nu] * gv)
        if pre and self.pre is not None:
            g0, g1 = self.dEd(Q[0], Q[-1], h)
            out[0] += g0
            out[-1] += g1
        return out

    def residual(self, x, q0, p0, h, pre=True):
        S, s, n, m = self.S, self.s, self.S.n, self.S.m
        Q = np.vstack([q0, x[:s * n].reshape(s, n)])
        lam = x[s * n:].reshape(s, m)
        DL = self.DL(Q, h, pre)
        r = []
        for nu in range(s):
            mom = DL[nu] + S.Gq(Q[nu]).T @ lam[nu] + (p0 if nu == 0 else 0)
            r.append(h * S.Minv * mom)
        for nu in range(1, s + 1):
            r.append(S.phi(Q[nu]))
        return np.concatenate(r)

    def step(self, q0, p0, h):
        S, s, n, m = self.S, self.s, self.S.n, self.S.m
        v0 = S.Minv * p0
        x = np.concatenate([np.concatenate([q0 + (k + 1) / s * h * v0 for k in range(s)]), np.zeros(s * m)])
        N = len(x)
        J = np.zeros((N, N))
        r0 = self.residual(x, q0, p0, h, pre=False)
        for i in range(N):
            e = np.zeros(N)
            e[i] = 1e-7
            J[:, i] = (self.residual(x + e, q0, p0, h, pre=False) - r0) / 1e-7
        for it in range(60):
            r = self.residual(x, q0, p0, h)
            dx = np.linalg.solve(J, -r)
            x = x + dx
            if np.max(np.abs(dx[:s * n])) < 1e-15 * (1 + np.max(np.abs(q0))) * 4:
                break
        Q = np.vstack([q0, x[:s * n].reshape(s, n)])
        lam = x[s * n:].reshape(s, m)
        # end momentum by the momentum balance (sum of all D_nu, as the library)
        DL = self.DL(Q, h)
        p1 = p0 + DL.sum(axis=0) + sum(S.Gq(Q[nu]).T @ lam[nu] for nu in range(s))
        G1 = S.Gq(Q[-1])
        Sm = (G1 * S.Minv) @ G1.T
        p1 = p1 - G1.T @ np.linalg.solve(Sm, G1 @ (S.Minv * p1))
        return Q[-1], p1


# ---------------------------------------------------------------- periods
def agm(a, b):
    for _ in range(60):
        a, b = (a + b) / 2, math.sqrt(a * b)
    return a


def exact_period(sysm, th0):
    w0sq = {'circle': G_ACC, 'rod': 1.5 * G_ACC}[sysm.name]
    return 2 * math.pi / math.sqrt(w0sq) / agm(1.0, math.cos(th0 / 2))


def crossings(ts, ys, level=0.0):
    """times of downward crossings of ys through level: root of the degree-7 polynomial through
    the 8 samples around each crossing (a cubic's O(h^4) interpolation error was a ~1e-5
    relative period noise at h = 0.2, above the (2,2) + e4 errors)."""
    out = []
    y = np.asarray(ys) - level
    for k in range(3, len(y) - 4):
        if y[k] > 0 >= y[k + 1]:
            c = np.polyfit(np.arange(-3, 5), y[k - 3:k + 5], 7)
            lo, hi = 0.0, 1.0
            for _ in range(60):
                mid = (lo + hi) / 2
                if np.polyval(c, mid) > 0:
                    lo = mid
                else:
                    hi = mid
            out.append(ts[k] + (lo + hi) / 2 * (ts[k + 1] - ts[k]))
    return np.array(out)


def measured_period(sch, th0, h, periods, Tref, level=0.0):
    S = sch.S
    q = np.array(S.chi(th0), float)
    p = np.zeros(S.n)
    nst = int(math.ceil(periods * Tref / h)) + 8
    ths = [S.theta(q)]
    for _ in range(nst):
        q, p = sch.step(q, p, h)
        ths.append(S.theta(q))
    tc = crossings(np.arange(nst + 1) * h, ths, level)
    i = np.arange(len(tc))
    slope = np.polyfit(i, tc, 1)[0]
    return slope / Tref - 1.0


def table(sysm, s, pre, hs, amps, periods, which='mid'):
    rows = []
    for deg in amps:
        th0 = math.radians(deg)
        Te = exact_period(sysm, th0)
        errs = [measured_period(Scheme(sysm, s, pre, which), th0, h, periods, Te) for h in hs]
        ords = [math.log2(abs(errs[k] / errs[k + 1])) for k in range(len(errs) - 1)]
        rows.append((deg, errs, ords))
        print('  %-7s s=%d %-5s %5.0f deg: ' % (sysm.name, s, pre or 'plain', deg)
              + ' '.join('%+.4e' % e for e in errs) + '  orders ' + ' '.join('%.2f' % o for o in ords), flush=True)
    return rows


def spring_test(hs=(0.1, 0.05, 0.025), periods=10, spring=(30.0, 0.5, (0.6, -0.9)), amps=(45.0, 90.0),
                variants=((None, 'mid'), ('e2', 'mid'), ('e2', 'trap'))):
    S = rod(spring)
    # reference: the reduced ODE (theta from the downward vertical), I = m l^2 / 3
    th = sp.Symbol('th')
    x, y, p = sp.symbols('x y p')
    tx, ty = 0.5 * sp.sin(th) + 0.5 * sp.cos(th - sp.pi / 2), -0.5 * sp.cos(th) + 0.5 * sp.sin(th - sp.pi / 2)
    k, L0, P = spring
    Ured = G_ACC * (-0.5 * sp.cos(th)) + k / 2 * (sp.sqrt((tx - P[0])**2 + (ty - P[1])**2) - L0)**2
    dU = sp.lambdify(th, sp.diff(Ured, th))
    I = 1.0 / 3.0
    for deg in amps:
        th0 = math.radians(deg)
        ev = lambda t, z: z[1]
        ev.terminal, ev.direction = False, 0
        sol = solve_ivp(lambda t, z: [z[1], -dU(z[0]) / I], (0, 20), [th0, 0.0], method='DOP853',
                        rtol=1e-13, atol=1e-13, events=ev, dense_output=True)
        te = sol.t_events[0]
        te = te[te > 1e-9]
        Tref = 2 * te[0]
        tmin = sol.sol(te[0])[0]
        level = 0.5 * (th0 + tmin)
        out = []
        for pre, which in variants:
            try:
                errs = [measured_period(Scheme(S, 1, pre, which), th0, h, periods, Tref, level) for h in hs]
            except Exception as exc:  # e.g. Newton failure / blow-up
                print('  rod+spring s=1 %s/%s %3.0f deg: failed (%s)' % (pre, which, deg, type(exc).__name__), flush=True)
                continue
            ords = [math.log2(abs(errs[k] / errs[k + 1])) for k in range(len(errs) - 1)]
            lab = 'plain' if pre is None else ('e_mid (derived)' if which == 'mid' else 'e_trap (issue prototype)')
            print('  rod+spring s=1 %-25s %3.0f deg (T = %.10f): ' % (lab, deg, Tref)
                  + ' '.join('%+.4e' % e for e in errs) + '  orders ' + ' '.join('%.2f' % o for o in ords), flush=True)


def energy_test(periods=10):
    """max |H(q_k, M^-1 p_k) - H_0| over `periods` periods, rod at 90 deg."""
    S = rod()
    th0 = math.radians(90.0)
    Te = exact_period(S, th0)
    for s, pre, hs in ((1, None, (0.1, 0.05)), (1, 'e2', (0.1, 0.05)), (2, None, (0.2, 0.1)), (2, 'e4', (0.2, 0.1))):
        out = []
        for h in hs:
            sch = Scheme(S, s, pre)
            q = np.array(S.chi(th0), float)
            p = np.zeros(S.n)
            H = lambda q, p: 0.5 * p @ (S.Minv * p) + S.V(q)
            H0, dH = H(q, p), 0.0
            for _ in range(int(periods * Te / h)):
                q, p = sch.step(q, p, h)
                dH = max(dH, abs(H(q, p) - H0))
            out.append(dH)
        print('  rod 90 deg s=%d %-5s h = %s: max|dH| = %s  order %.2f'
              % (s, pre or 'plain', hs, ' '.join('%.3e' % x for x in out), math.log2(out[0] / out[1])), flush=True)


def double_pendulum():
    """paper A's double pendulum (two 1 kg 1 m rods, both released at rest 30 deg from the
    downward vertical), h = 0.04, 20 s: E|dx|, E|dy| over both bodies and all steps against
    DOP853 (rtol = atol = 1e-13) on the angle ODE."""
    xs = sp.symbols('x1 y1 p1 x2 y2 p2')
    x1, y1, p1, x2, y2, p2 = xs
    V = G_ACC * (y1 + y2)
    Phi = [x1 - sp.cos(p1) / 2, y1 - sp.sin(p1) / 2,
           x2 - sp.cos(p2) / 2 - (x1 + sp.cos(p1) / 2), y2 - sp.sin(p2) / 2 - (y1 + sp.sin(p1) / 2)]
    chi = lambda t: [sp.cos(t) / 2, sp.sin(t) / 2, t, sp.cos(t) + sp.cos(t) / 2, sp.sin(t) + sp.sin(t) / 2, t]  # unused (one angle)
    S = System(list(xs), [1, 1, 1 / 12] * 2, V, Phi, chi, lambda q: q[2], 'dp')
    a0 = -math.pi / 2 + math.radians(30)
    # reduced angle ODE
    t1, t2, w1, w2 = sp.symbols('t1 t2 w1 w2')
    pos = sp.Matrix([sp.cos(t1) / 2, sp.sin(t1) / 2, t1, sp.cos(t1) + sp.cos(t2) / 2, sp.sin(t1) + sp.sin(t2) / 2, t2])
    Jm = pos.jacobian(sp.Matrix([t1, t2]))
    Mm = sp.diag(1, 1, sp.Rational(1, 12), 1, 1, sp.Rational(1, 12))
    Mh = sp.simplify(Jm.T * Mm * Jm)
    om = sp.Matrix([w1, w2])
    Lr = (om.T * Mh * om)[0] / 2 - G_ACC * (pos[1] + pos[4])
    rhs = sp.Matrix([sp.diff(Lr, t) for t in (t1, t2)]) - sp.Matrix([[sp.diff(Lr, w, t) for t in (t1, t2)] for w in (w1, w2)]) * om
    fM, frhs, fpos = sp.lambdify([t1, t2], Mh), sp.lambdify([t1, t2, w1, w2], rhs), sp.lambdify([t1, t2], pos)
    f = lambda t, z: np.concatenate([z[2:], np.linalg.solve(np.array(fM(z[0], z[1]), float), np.array(frhs(*z), float).ravel())])
    h, n = 0.04, 500
    ref = solve_ivp(f, (0, n * h), [a0, a0, 0, 0], method='DOP853', rtol=1e-13, atol=1e-13, t_eval=np.arange(n + 1) * h)
    refq = [np.array(fpos(ref.y[0, k], ref.y[1, k]), float).ravel() for k in range(n + 1)]
    q0 = refq[0]
    for s, pre in ((1, None), (1, 'e2'), (2, None)):
        sch = Scheme(S, s, pre)
        q, p = q0.copy(), np.zeros(6)
        ex = ey = 0.0
        for k in range(1, n + 1):
            q, p = sch.step(q, p, h)
            ex += abs(q[0] - refq[k][0]) + abs(q[3] - refq[k][3])
            ey += abs(q[1] - refq[k][1]) + abs(q[4] - refq[k][4])
        print('  double pendulum h = 0.04, 20 s, s=%d %-5s: E|dx| = %.4e, E|dy| = %.4e' % (s, pre or 'plain', ex / (2 * n), ey / (2 * n)), flush=True)


def unconstrained_test(hs=(0.1, 0.05, 0.025), T=6.0):
    """(2,2) on a 2-DOF unconstrained non-linear system with M = diag(1, 2) (a third coordinate
    z = 0 is constrained linearly to reuse the code): global error at t = T against DOP853, plain
    vs + h^4 e4 with the candidate n-DOF tensor form of the 1-DOF e4 (section 3)."""
    x, y, z = sp.symbols('x y z')
    V = (3 * x**2 + 5 * y**2) / 2 + 2 * x**2 * y - y**3 + x**4 / 2
    S = System([x, y, z], [1.0, 2.0, 1.0], V, [z], lambda t: [t, 0 * t, 0 * t], lambda q: q[0], 'hh')
    qs = [x, y, z]
    a = sp.symbols('a0:3')
    b = sp.symbols('b0:3')
    D3 = sum(sp.diff(V, qs[i], qs[j], qs[k]) * a[i] * b[j] * b[k] for i in range(3) for j in range(3) for k in range(3))
    D4 = sum(sp.diff(V, qs[i], qs[j], qs[k], qs[l]) * b[i] * b[j] * b[k] * b[l]
             for i in range(3) for j in range(3) for k in range(3) for l in range(3))
    fD3 = sp.lambdify([qs, a, b], D3, 'numpy')
    fD4 = sp.lambdify([qs, b], D4, 'numpy')
    Mi = S.Minv.copy()
    Mi[2] = 0.0  # the dummy coordinate is frozen: no motion in z

    def e4(q, v):
        g, H = S.gradV(q), S.hessV(q)
        u = Mi * g
        return (-(u @ H @ u) / 1440 + fD3(q, u, v) / 720 - (H @ v) @ (Mi * (H @ v)) / 1440 - fD4(q, v) / 4320)

    class Pre(Scheme):
        def Ed(self, Q0, Q1, h):
            if self.pre is None:
                return 0.0
            v = (Q1 - Q0) / h
            return h**5 / 2 * (e4(Q0, v) + e4(Q1, v))

    gV = sp.lambdify([x, y], [sp.diff(V, x), sp.diff(V, y) / 2])
    q0, v0 = np.array([0.4, 0.3, 0.0]), np.array([0.5, -0.6, 0.0])
    ref = solve_ivp(lambda t, w: [w[2], w[3], *[-c for c in gV(w[0], w[1])]], (0, T), [q0[0], q0[1], v0[0], v0[1]],
                    method='DOP853', rtol=2.3e-14, atol=1e-14)
    qT = ref.y[:2, -1]
    for pre in (None, 'e4'):
        errs = []
        for h in hs:
            sch = Pre(S, 2, None)
            sch.pre = pre
            q, p = q0.copy(), S.M * v0
            for _ in range(int(round(T / h))):
                q, p = sch.step(q, p, h)
            errs.append(np.max(np.abs(q[:2] - qT)))
        print('  unconstrained 2-DOF (2,2) %-5s h = %s: |q(T) - q_ref(T)| = %s  orders %s' % (
            pre or 'plain', hs, ' '.join('%.4e' % e for e in errs),
            ' '.join('%.2f' % math.log2(errs[k] / errs[k + 1]) for k in range(len(errs) - 1))), flush=True)


if __name__ == '__main__':
    what = sys.argv[1] if len(sys.argv) > 1 else 'all'
    amps = (10.0, 45.0, 90.0, 120.0)
    if what in ('s1', 'all'):
        for S in (circle(), rod()):
            table(S, 1, None, (0.1, 0.05, 0.025), amps, 10)
            table(S, 1, 'e2', (0.1, 0.05, 0.025), amps, 10)
    if what in ('s2', 'all'):
        for S in (circle(), rod()):
            table(S, 2, None, (0.2, 0.1, 0.05), amps, 20)
            table(S, 2, 'e4', (0.2, 0.1, 0.05), amps, 20)
    if what == 's2pre':
        for S in (circle(), rod()):
            table(S, 2, 'e4', (0.2, 0.1, 0.05), amps, 20)
    if what == 's2small':  # smaller steps where h = 0.2 is outside the asymptotic range
        for S in (circle(), rod()):
            table(S, 2, 'e4', (0.1, 0.05, 0.025), (90.0, 120.0), 20)
    if what == 's2rodplain':
        table(rod(), 2, None, (0.2, 0.1, 0.05), amps, 20)
    if what in ('spring', 'all'):
        spring_test()
    if what == 'spring2':  # anchor out of the tip's reach, smaller steps
        spring_test(hs=(0.05, 0.025, 0.0125), spring=(30.0, 0.5, (0.6, -1.6)), amps=(90.0, 120.0),
                    variants=((None, 'mid'), ('e2', 'mid'), ('e2', 'trap')))
    if what in ('energy', 'all'):
        energy_test()
    if what in ('free', 'all'):
        unconstrained_test()
    if what in ('dp', 'all'):
        double_pendulum()

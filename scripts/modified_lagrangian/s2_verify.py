"""The (2,2) scheme + h^5 e4(qbar, v) with the Cartesian-invariant e4 of s2_cartesian.py, evaluated
at the chord midpoint qbar = (q0 + q1)/2 with the chord velocity v = (q1 - q0)/h (the library's
evaluation rule for the s = 1 term), in the Cartesian prototype of prototype.py.

    python3 s2_verify.py rod       rod pendulum, 10/45/90/120 deg, h = 0.2/0.1/0.05 (+0.025 at 90/120)
    python3 s2_verify.py spring    rod + non-linear spring (anchor (0.6, -1.6)), 45/90 deg
    python3 s2_verify.py spring90  the same at 90 deg with h = 0.05/0.025/0.0125
    python3 s2_verify.py dp        paper A's double pendulum, h = 0.04, 20 s, E|dx|, E|dy|
    python3 s2_verify.py dpspring  double pendulum + non-linear spring, global error at t = 4 vs DOP853
"""
import sys, os, math, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
import prototype as P
from s2_cartesian import Tensors


class E4Scheme(P.Scheme):
    def __init__(self, sysm, tens, pre):
        super().__init__(sysm, 2, None)
        self.pre = pre
        self.T = tens
        self.Mmat = np.diag(sysm.M)

    def Ed(self, Q0, Q1, h):
        if self.pre is None:
            return 0.0
        return h**5 * self.T.e4(self.Mmat, (Q0 + Q1) / 2, (Q1 - Q0) / h)

    def dEd(self, Q0, Q1, h):
        """chain rule: E_d = h^5 e4(qbar, v), qbar = (Q0 + Q1)/2, v = (Q1 - Q0)/h."""
        n = self.S.n
        if self.pre is None:
            return np.zeros(n), np.zeros(n)
        _, gq, gv = self.T.e4_grad(self.Mmat, (Q0 + Q1) / 2, (Q1 - Q0) / h)
        return h**5 * (gq / 2 - gv / h), h**5 * (gq / 2 + gv / h)


def rod_sym(spring=None):
    x, y, p = sp.symbols('x y p')
    l, m = 1.0, 1.0
    V = m * P.G_ACC * y
    if spring is not None:
        k, L0, A = spring
        tx, ty = x + l / 2 * sp.cos(p), y + l / 2 * sp.sin(p)
        V = V + k / 2 * (sp.sqrt((tx - A[0])**2 + (ty - A[1])**2) - L0)**2
    return Tensors([x, y, p], V, [x - l / 2 * sp.cos(p), y - l / 2 * sp.sin(p)])


def rod_table(hs_main=(0.2, 0.1, 0.05), amps=(10.0, 45.0, 90.0, 120.0), periods=20, extra=(90.0, 120.0)):
    S = P.rod()
    T = rod_sym()
    for pre in (None, 'e4c'):
        for deg in amps:
            hs = hs_main + ((0.025,) if (pre and deg in extra) else ())
            th0 = math.radians(deg)
            Te = P.exact_period(S, th0)
            t0 = time.time()
            errs = [P.measured_period(E4Scheme(S, T, pre), th0, h, periods, Te) for h in hs]
            ords = [math.log2(abs(errs[k] / errs[k + 1])) for k in range(len(errs) - 1)]
            print('  rod (2,2) %-9s %5.0f deg, h = %s: ' % (pre or 'plain', deg, hs)
                  + ' '.join('%+.4e' % e for e in errs) + '  orders ' + ' '.join('%.2f' % o for o in ords)
                  + '  (%.0fs)' % (time.time() - t0), flush=True)


def spring_ref(spring, th0):
    th = sp.Symbol('th')
    tx, ty = 0.5 * sp.sin(th) + 0.5 * sp.cos(th - sp.pi / 2), -0.5 * sp.cos(th) + 0.5 * sp.sin(th - sp.pi / 2)
    k, L0, A = spring
    Ured = P.G_ACC * (-0.5 * sp.cos(th)) + k / 2 * (sp.sqrt((tx - A[0])**2 + (ty - A[1])**2) - L0)**2
    dU = sp.lambdify(th, sp.diff(Ured, th))
    I = 1.0 / 3.0
    ev = lambda t, z: z[1]
    sol = solve_ivp(lambda t, z: [z[1], -dU(z[0]) / I], (0, 20), [th0, 0.0], method='DOP853',
                    rtol=1e-13, atol=1e-13, events=ev, dense_output=True)
    te = sol.t_events[0]
    te = te[te > 1e-9]
    return 2 * te[0], 0.5 * (th0 + sol.sol(te[0])[0])


def spring_table(hs=(0.1, 0.05, 0.025), amps=(45.0, 90.0), periods=20, spring=(30.0, 0.5, (0.6, -1.6))):
    S = P.rod(spring)
    T = rod_sym(spring)
    for deg in amps:
        th0 = math.radians(deg)
        Tref, level = spring_ref(spring, th0)
        for pre in (None, 'e4c'):
            t0 = time.time()
            errs = [P.measured_period(E4Scheme(S, T, pre), th0, h, periods, Tref, level) for h in hs]
            ords = [math.log2(abs(errs[k] / errs[k + 1])) for k in range(len(errs) - 1)]
            print('  rod+spring (2,2) %-9s %5.0f deg (T = %.10f), h = %s: ' % (pre or 'plain', deg, Tref, hs)
                  + ' '.join('%+.4e' % e for e in errs) + '  orders ' + ' '.join('%.2f' % o for o in ords)
                  + '  (%.0fs)' % (time.time() - t0), flush=True)


def dp_system(spring=None):
    xs = sp.symbols('x1 y1 p1 x2 y2 p2')
    x1, y1, p1, x2, y2, p2 = xs
    V = P.G_ACC * (y1 + y2)
    if spring is not None:
        k, L0, A = spring
        tx, ty = x2 + sp.cos(p2) / 2, y2 + sp.sin(p2) / 2
        V = V + k / 2 * (sp.sqrt((tx - A[0])**2 + (ty - A[1])**2) - L0)**2
    Phi = [x1 - sp.cos(p1) / 2, y1 - sp.sin(p1) / 2,
           x2 - sp.cos(p2) / 2 - (x1 + sp.cos(p1) / 2), y2 - sp.sin(p2) / 2 - (y1 + sp.sin(p1) / 2)]
    S = P.System(list(xs), [1, 1, 1 / 12] * 2, V, Phi, lambda t: [t] * 6, lambda q: q[2], 'dp')
    T = Tensors(list(xs), V, Phi)
    # reduced angle ODE for the reference
    t1, t2, w1, w2 = sp.symbols('t1 t2 w1 w2')
    pos = sp.Matrix([sp.cos(t1) / 2, sp.sin(t1) / 2, t1, sp.cos(t1) + sp.cos(t2) / 2, sp.sin(t1) + sp.sin(t2) / 2, t2])
    Jm = pos.jacobian(sp.Matrix([t1, t2]))
    Mm = sp.diag(1, 1, sp.Rational(1, 12), 1, 1, sp.Rational(1, 12))
    Mh = sp.simplify(Jm.T * Mm * Jm)
    om = sp.Matrix([w1, w2])
    Lr = (om.T * Mh * om)[0] / 2 - V.subs(dict(zip(xs, list(pos))))
    rhs = sp.Matrix([sp.diff(Lr, t) for t in (t1, t2)]) - sp.Matrix([[sp.diff(Lr, w, t) for t in (t1, t2)] for w in (w1, w2)]) * om
    fM, frhs, fpos = sp.lambdify([t1, t2], Mh), sp.lambdify([t1, t2, w1, w2], rhs), sp.lambdify([t1, t2], pos)
    f = lambda t, z: np.concatenate([z[2:], np.linalg.solve(np.array(fM(z[0], z[1]), float), np.array(frhs(*z), float).ravel())])
    return S, T, f, fpos


def dp_paperA():
    S, T, f, fpos = dp_system()
    a0 = -math.pi / 2 + math.radians(30)
    h, n = 0.04, 500
    ref = solve_ivp(f, (0, n * h), [a0, a0, 0, 0], method='DOP853', rtol=1e-13, atol=1e-13, t_eval=np.arange(n + 1) * h)
    refq = [np.array(fpos(ref.y[0, k], ref.y[1, k]), float).ravel() for k in range(n + 1)]
    for pre in (None, 'e4c'):
        t0 = time.time()
        sch = E4Scheme(S, T, pre)
        q, p = refq[0].copy(), np.zeros(6)
        ex = ey = 0.0
        for k in range(1, n + 1):
            q, p = sch.step(q, p, h)
            ex += abs(q[0] - refq[k][0]) + abs(q[3] - refq[k][3])
            ey += abs(q[1] - refq[k][1]) + abs(q[4] - refq[k][4])
        print('  double pendulum h = 0.04, 20 s, (2,2) %-5s: E|dx| = %.4e, E|dy| = %.4e  (%.0fs)'
              % (pre or 'plain', ex / (2 * n), ey / (2 * n), time.time() - t0), flush=True)


def dp_spring(hs=(0.04, 0.02, 0.01), Tend=2.0, spring=(20.0, 0.6, (1.2, -1.0))):
    """double pendulum + a non-linear spring from the second rod's tip to a fixed point, released
    at rest (30 deg, 60 deg from the downward vertical), max-norm position error at t = Tend."""
    S, T, f, fpos = dp_system(spring)
    a1, a2 = -math.pi / 2 + math.radians(30), -math.pi / 2 + math.radians(60)
    ref = solve_ivp(f, (0, Tend), [a1, a2, 0, 0], method='DOP853', rtol=1e-13, atol=1e-13)
    qT = np.array(fpos(ref.y[0, -1], ref.y[1, -1]), float).ravel()
    q00 = np.array(fpos(a1, a2), float).ravel()
    for pre in (None, 'e4c'):
        errs = []
        t0 = time.time()
        for h in hs:
            sch = E4Scheme(S, T, pre)
            q, p = q00.copy(), np.zeros(6)
            for _ in range(int(round(Tend / h))):
                q, p = sch.step(q, p, h)
            errs.append(np.max(np.abs(q - qT)))
        print('  double pendulum + spring (2,2) %-5s h = %s: |q(T) - q_ref(T)| = %s  orders %s  (%.0fs)' % (
            pre or 'plain', hs, ' '.join('%.4e' % e for e in errs),
            ' '.join('%.2f' % math.log2(errs[k] / errs[k + 1]) for k in range(len(errs) - 1)), time.time() - t0), flush=True)


if __name__ == '__main__':
    what = sys.argv[1] if len(sys.argv) > 1 else 'rod'
    if what == 'rod':
        rod_table()
    if what == 'rodquick':
        rod_table(hs_main=(0.2, 0.1), amps=(45.0,), periods=5, extra=())
    if what == 'spring':
        spring_table()
    if what == 'spring90':  # h = 0.1 is outside the asymptotic range at 90 deg
        spring_table(hs=(0.05, 0.025, 0.0125), amps=(90.0,))
    if what == 'dp':
        dp_paperA()
    if what == 'dpspring':
        dp_spring()

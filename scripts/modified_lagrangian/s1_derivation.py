"""s = 1: the h^2 term of the modified Lagrangian of the constrained (1,1) scheme, derived in
reduced coordinates and checked against the Cartesian-invariant form.

Prints
 1. the h^2 coefficient c2 of the exact discrete Lagrangian of L = 1/2 m(q) v^2 - U(q) in midpoint
    variables (series solution), against 1/24 [L_qq(v,v) - a^T L_vv a];
 2. ellipse x = a cos th, y = b sin th, M = mass I, nonlinear V = g y + k x^4/4 + c x y
    (+ spring to a point): reduced e = c2_exact - c2_scheme for the library's (1,1) scheme
    (potential at the chord midpoint) and for the trapezoid variant, minus the Cartesian forms
    e_mid and e_trap (both must simplify to 0);
 3. double pendulum of rods (library geometry) + a nonlinear spring, random points: the same
    comparison numerically (reduced angles vs Cartesian x, y, theta with M = diag(m, m, m l^2/12)).
"""
import sys, os, random
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sympy as sp
from exact_dl import exact_dl, coeff_h, to_sympy

h = sp.Symbol('h')


def cartesian_e(q, vv, Mdiag, V, Phi, which):
    """Cartesian e(q, v): which = 'mid' (library: V at the chord midpoint) or 'trap'."""
    n = len(q)
    Mi = sp.diag(*[1 / x for x in Mdiag])
    g = sp.Matrix([sp.diff(V, x) for x in q])
    HV = sp.hessian(V, q)
    G = sp.Matrix([[sp.diff(p, x) for x in q] for p in Phi])
    S = G * Mi * G.T
    Si = S.inv()
    mu0 = Si * G * Mi * g
    fT = -g + G.T * mu0
    HPmu = sp.zeros(n, n)
    gam = []
    for k, p in enumerate(Phi):
        Hk = sp.hessian(p, q)
        HPmu += mu0[k] * Hk
        gam.append((vv.T * Hk * vv)[0])
    gam = sp.Matrix(gam)
    fMf = (fT.T * Mi * fT)[0]
    vHv = (vv.T * HV * vv)[0]
    vPv = (vv.T * HPmu * vv)[0]
    gSg = (gam.T * Si * gam)[0]
    if which == 'trap':   # the prototype: 1/12 v^T A v, A = Hess V - mu0 . Hess Phi
        return -fMf / 24 + (vHv - vPv) / 12 + gSg / 24
    return -fMf / 24 - (vHv + 2 * vPv) / 24 + gSg / 24


def reduced_e(th, om, chi, Mdiag, V, qsyms, which, numeric=None):
    """c2_exact - c2_scheme in reduced coordinates (th, om vectors; chi: list of exprs in th)."""
    nd = len(th)
    M = sp.diag(*Mdiag)
    chiv = sp.Matrix(chi)
    J = chiv.jacobian(sp.Matrix(th))
    Vr = V.subs(dict(zip(qsyms, chi)))
    omv = sp.Matrix(om)
    Lr = (omv.T * J.T * M * J * omv)[0] / 2 - Vr
    if numeric is not None:
        pass
    # exact c2 = 1/24 [L_thth(om,om) - a^T Mhat a], a from Euler-Lagrange at (th, om)
    Lqq = sum(sp.diff(Lr, th[i], th[j]) * om[i] * om[j] for i in range(nd) for j in range(nd))
    Mh = J.T * M * J
    Lq = sp.Matrix([sp.diff(Lr, x) for x in th])
    Lvq = sp.Matrix([[sp.diff(Lr, om[i], th[j]) for j in range(nd)] for i in range(nd)])
    if numeric is not None:
        Lqq, Mh, Lq, Lvq = [sp.N(x.subs(numeric), 30) for x in (Lqq, Mh, Lq, Lvq)]
    a = Mh.LUsolve(Lq - Lvq * omv if numeric is None else (Lq - Lvq * sp.Matrix([numeric[o] for o in om])))
    c2E = (Lqq - (a.T * Mh * a)[0]) / 24
    # scheme: h^-1 L_d(th - h om/2, th + h om/2), series in h
    sub0 = {t: t - h * o / 2 for t, o in zip(th, om)}
    sub1 = {t: t + h * o / 2 for t, o in zip(th, om)}
    c0, c1 = chiv.subs(sub0, simultaneous=True), chiv.subs(sub1, simultaneous=True)
    if numeric is not None:
        c0, c1 = c0.subs(numeric), c1.subs(numeric)
    vc = (c1 - c0) / h
    kin = (vc.T * M * vc)[0] / 2
    if which == 'mid':
        pot = V.subs(dict(zip(qsyms, (c0 + c1) / 2)), simultaneous=True)
    else:
        pot = (V.subs(dict(zip(qsyms, c0)), simultaneous=True) + V.subs(dict(zip(qsyms, c1)), simultaneous=True)) / 2
    if numeric is None:
        c2S = sp.series(kin - pot, h, 0, 3).removeO().coeff(h, 2)
    else:
        c2S = sp.diff(kin - pot, h, 2).subs(h, 0) / 2
    return c2E - c2S


def part1():
    I, _ = exact_dl(2)
    im0, m0 = sp.symbols('im0 m0')
    c2 = sp.expand(to_sympy(coeff_h(I, 2)).subs(im0, 1 / m0))
    m0, m1, m2, U1, U2, v = sp.symbols('m0 m1 m2 U1 U2 v')
    a = -(m1 * v**2 / 2 + U1) / m0
    Lqq = (m2 * v**2 / 2 - U2) * v**2
    formula = (Lqq - m0 * a**2) / 24
    print('1. exact c2 =', sp.factor(c2))
    print('   c2 - 1/24 [L_qq(v,v) - a^T L_vv a] =', sp.simplify(c2 - formula))


def part2():
    th, om = sp.symbols('theta omega')
    x, y = sp.symbols('x y')
    A, B, mass, g, k, c, ks, px, py, L0 = sp.symbols('a b mass g k c k_s p_x p_y L0', positive=True)
    V = mass * g * y + k * x**4 / 4 + c * x * y + ks / 2 * ((x - px)**2 + (y - py)**2)
    Phi = [x**2 / A**2 + y**2 / B**2 - 1]
    chi = [A * sp.cos(th), B * sp.sin(th)]
    q = [x, y]
    for which in ('mid', 'trap'):
        er = reduced_e([th], [om], chi, [mass, mass], V, q, which)
        ec = cartesian_e(q, sp.Matrix([sp.diff(chi[0], th) * om, sp.diff(chi[1], th) * om]), [mass, mass], V, Phi, which)
        ec = ec.subs({x: chi[0], y: chi[1]}, simultaneous=True)
        d = sp.simplify(sp.expand_trig(er - ec))
        print('2. ellipse + nonlinear V, scheme %-4s: reduced e - Cartesian e_%s = %s' % (which, which, d))
        # and the cross-check: the prototype form on the library scheme
        if which == 'mid':
            et = cartesian_e(q, sp.Matrix([sp.diff(chi[0], th) * om, sp.diff(chi[1], th) * om]), [mass, mass], V, Phi, 'trap')
            et = et.subs({x: chi[0], y: chi[1]}, simultaneous=True)
            dd = sp.simplify(er - et)
            vv = sp.Matrix([sp.diff(chi[0], th) * om, sp.diff(chi[1], th) * om])
            vHv = (vv.T * sp.hessian(V, q) * vv)[0].subs({x: chi[0], y: chi[1]}, simultaneous=True)
            print('   library scheme: reduced e - prototype e_trap = %s  (= -1/8 v^T HessV v: %s)'
                  % (sp.factor(dd), sp.simplify(dd + vHv / 8) == 0))


def part3():
    """double pendulum + spring: numerically (mpmath, 40 digits). Exact c2 from the formula of
    part 1 (generic n-DOF form 1/24 [L_qq(w,w) - a^T Mhat a]); the scheme's c2 from
    (f(h) - f(0)) / h^2 at h = 1e-8 with f = L_d/h of the Cartesian scheme restricted to the
    manifold: (f(2h) - f(h)) / (3 h^2), h = 1e-10, 60 digits (truncation ~h^2 c4/c2 ~ 1e-20)."""
    import mpmath as mp
    mp.mp.dps = 60
    random.seed(1)
    th1, th2, w1, w2, hh = sp.symbols('th1 th2 w1 w2 hh')
    qs = sp.symbols('x1 y1 p1 x2 y2 p2')
    x1, y1, p1, x2, y2, p2 = qs
    m_, l_, g_ = 1, 1, sp.Rational(981, 100)
    Md = [m_, m_, sp.Rational(m_ * l_**2, 12)] * 2
    ks, L0, P = 40, sp.Rational(7, 10), (sp.Rational(13, 10), -sp.Rational(2, 5))
    tip = (x2 + l_ / sp.Integer(2) * sp.cos(p2), y2 + l_ / sp.Integer(2) * sp.sin(p2))
    V = m_ * g_ * (y1 + y2) + ks * (sp.sqrt((tip[0] - P[0])**2 + (tip[1] - P[1])**2) - L0)**2 / 2
    Phi = [x1 - sp.cos(p1) / 2, y1 - sp.sin(p1) / 2,
           x2 - sp.cos(p2) / 2 - (x1 + sp.cos(p1) / 2), y2 - sp.sin(p2) / 2 - (y1 + sp.sin(p1) / 2)]
    chi = sp.Matrix([sp.cos(th1) / 2, sp.sin(th1) / 2, th1,
                     sp.cos(th1) + sp.cos(th2) / 2, sp.sin(th1) + sp.sin(th2) / 2, th2])
    th, om = sp.Matrix([th1, th2]), sp.Matrix([w1, w2])
    M = sp.diag(*Md)
    J = chi.jacobian(th)
    Vr = V.subs(dict(zip(qs, chi)), simultaneous=True)
    Lr = (om.T * J.T * M * J * om)[0] / 2 - Vr
    Lqq = sum(sp.diff(Lr, th[i], th[j]) * om[i] * om[j] for i in range(2) for j in range(2))
    Mh = J.T * M * J
    rhs = sp.Matrix([sp.diff(Lr, th[i]) - sum(sp.diff(Lr, om[i], th[j]) * om[j] for j in range(2)) for i in range(2)])
    f_exact = sp.lambdify([th1, th2, w1, w2], [Lqq, Mh, rhs], 'mpmath')
    res = {}
    for which in ('mid', 'trap'):
        c0 = chi.subs({th1: th1 - hh * w1 / 2, th2: th2 - hh * w2 / 2}, simultaneous=True)
        c1 = chi.subs({th1: th1 + hh * w1 / 2, th2: th2 + hh * w2 / 2}, simultaneous=True)
        vc = (c1 - c0) / hh
        kin = (vc.T * M * vc)[0] / 2
        if which == 'mid':
            pot = V.subs(dict(zip(qs, (c0 + c1) / 2)), simultaneous=True)
        else:
            pot = (V.subs(dict(zip(qs, c0)), simultaneous=True) + V.subs(dict(zip(qs, c1)), simultaneous=True)) / 2
        res[which] = sp.lambdify([th1, th2, w1, w2, hh], kin - pot, 'mpmath')
        vv = J * om
        ec = cartesian_e(list(qs), vv, Md, V, Phi, which).subs(dict(zip(qs, chi)), simultaneous=True)
        res[which + 'c'] = sp.lambdify([th1, th2, w1, w2], ec, 'mpmath')
    for trial in range(3):
        pt = [mp.mpf(random.uniform(-3, 3)) for _ in range(4)]
        Lqq_, Mh_, rhs_ = f_exact(*pt)
        Mh_, rhs_ = mp.matrix(Mh_), mp.matrix(rhs_)
        a = mp.lu_solve(Mh_, rhs_)
        c2E = (Lqq_ - (a.T * Mh_ * a)[0]) / 24
        for which in ('mid', 'trap'):
            hv = mp.mpf('1e-10')
            c2S = (res[which](*pt, 2 * hv) - res[which](*pt, hv)) / (3 * hv**2)
            er, ec = c2E - c2S, res[which + 'c'](*pt)
            print('3. double pendulum + spring, point %d, scheme %-4s: reduced e = %s, Cartesian e_%s = %s, diff %s'
                  % (trial, which, mp.nstr(er, 15), which, mp.nstr(ec, 15), mp.nstr(abs(er - ec), 3)))


if __name__ == '__main__':
    which = sys.argv[1:] or ['1', '2', '3']
    if '1' in which:
        part1()
    if '2' in which:
        part2()
    if '3' in which:
        part3()

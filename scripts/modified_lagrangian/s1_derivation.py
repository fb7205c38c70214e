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
    random.seed(1)
    th1, th2, w1, w2 = sp.symbols('th1 th2 w1 w2')
    qs = sp.symbols('x1 y1 p1 x2 y2 p2')
    x1, y1, p1, x2, y2, p2 = qs
    m_, l_, g_ = 1.0, 1.0, 9.81
    Md = [m_, m_, m_ * l_**2 / 12] * 2
    ks, L0, P = 40.0, 0.7, (1.3, -0.4)
    tip = (x2 + l_ / 2 * sp.cos(p2), y2 + l_ / 2 * sp.sin(p2))
    V = m_ * g_ * (y1 + y2) + ks / 2 * (sp.sqrt((tip[0] - P[0])**2 + (tip[1] - P[1])**2) - L0)**2
    Phi = [x1 - l_ / 2 * sp.cos(p1), y1 - l_ / 2 * sp.sin(p1),
           x2 - l_ / 2 * sp.cos(p2) - (x1 + l_ / 2 * sp.cos(p1)), y2 - l_ / 2 * sp.sin(p2) - (y1 + l_ / 2 * sp.sin(p1))]
    chi = [l_ / 2 * sp.cos(th1), l_ / 2 * sp.sin(th1), th1,
           l_ * sp.cos(th1) + l_ / 2 * sp.cos(th2), l_ * sp.sin(th1) + l_ / 2 * sp.sin(th2), th2]
    J = sp.Matrix(chi).jacobian(sp.Matrix([th1, th2]))
    for trial in range(3):
        num = {th1: random.uniform(-3, 3), th2: random.uniform(-3, 3), w1: random.uniform(-3, 3), w2: random.uniform(-3, 3)}
        for which in ('mid', 'trap'):
            er = sp.N(reduced_e([th1, th2], [w1, w2], chi, Md, V, list(qs), which, numeric=num).subs(num), 20)
            vv = (J * sp.Matrix([w1, w2])).subs(num)
            ec = cartesian_e(list(qs), vv, Md, V, Phi, which)
            ec = sp.N(ec.subs(dict(zip(qs, [c.subs(num) for c in chi]))), 20)
            print('3. double pendulum + spring, point %d, scheme %-4s: reduced e = %+.15e, Cartesian e = %+.15e, diff %.1e'
                  % (trial, which, er, ec, abs(er - ec)))


if __name__ == '__main__':
    part1()
    part2()
    part3()

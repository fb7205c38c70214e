"""s = 2 with a constraint, in the reduced coordinate: the family 'point at radius r on a
pendulum with extra rotational inertia J' -- Cartesian q = (r sin th, -r cos th, th),
M = diag(m, m, J), V = m g y (J = 0, r = 1: point mass on the unit circle; r = l/2,
J = m l^2/12: the library's rod pendulum with theta = th - pi/2).

The (2,2) scheme restricted to the manifold: quadratic through Q0 = chi(th - h w/2),
Q1 = chi(th + zeta), Q2 = chi(th + h w/2) (constraints at all three control points), kinetic
energy integrated exactly (it is by the 2-point Gauss rule), potential by the 2-point Gauss rule
(exact here: V linear), zeta = h^2 a stationary (an O(h^4) error in zeta changes L_d/h by O(h^6)).

Prints c2, c4 of L_d/h (scheme and exact) and e4(th, w) = c4_exact - c4_scheme, and writes it to
e4_pendulum.txt (sympy srepr) for the prototype.
"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sympy as sp
from exact_dl import exact_dl, coeff_h, to_sympy

h, th, w, a = sp.symbols('h theta omega a')
mm, r, J, g = sp.symbols('m r J g', positive=True)


def chi(t):
    return sp.Matrix([r * sp.sin(t), -r * sp.cos(t), t])


M = sp.diag(mm, mm, J)


def V(q):
    return mm * g * q[1]


def scheme_series():
    Q0, Q2 = chi(th - h * w / 2), chi(th + h * w / 2)
    Q1 = chi(th + h**2 * a)
    d1 = Q2 - Q0
    d2 = Q0 + Q2 - 2 * Q1
    kin = ((d1.T * M * d1)[0] + sp.Rational(4, 3) * (d2.T * M * d2)[0]) / (2 * h**2)
    s = 1 / (2 * sp.sqrt(3))
    pot = (V(Q1 + s * d1 + d2 / 6) + V(Q1 - s * d1 + d2 / 6)) / 2
    F = sp.series(kin - pot, h, 0, 5).removeO()
    F = sp.expand(sp.simplify(F))
    F2, F4 = F.coeff(h, 2), F.coeff(h, 4)
    astar = sp.solve(sp.diff(F2, a), a)
    if not astar:
        astar = sp.solve(sp.diff(F4, a), a)
    astar = astar[0]
    return F.coeff(h, 0), sp.simplify(F2.subs(a, astar)), sp.simplify(F4.subs(a, astar)), astar


def exact_series():
    E, _ = exact_dl(4, mass=False)
    I = mm * r**2 + J
    Ured = -mm * g * r * sp.cos(th)
    sub = {sp.Symbol('U%d' % j): sp.diff(Ured, th, j) / I for j in range(1, 6)}
    sub[sp.Symbol('v')] = w
    c2 = I * to_sympy(coeff_h(E, 2)).subs(sub)
    c4 = I * to_sympy(coeff_h(E, 4)).subs(sub)
    return sp.simplify(c2), sp.simplify(c4)


if __name__ == '__main__':
    F0, S2, S4, astar = scheme_series()
    E2, E4 = exact_series()
    print('zeta = h^2 a, a =', astar)
    print('scheme c0 =', sp.simplify(F0))
    print('scheme c2 =', S2)
    print('exact  c2 =', E2)
    print('c2 difference =', sp.simplify(sp.expand_trig(S2 - E2)))
    e4 = sp.simplify(sp.expand_trig(E4 - S4))
    e4 = sp.simplify(sp.collect(sp.expand(e4), w))
    print('e4 = c4_exact - c4_scheme =', e4)
    for lab, sub in (('unit circle (m = 1, r = 1, J = 0)', {mm: 1, r: 1, J: 0}),
                     ('rod (m, l: r = l/2, J = m l^2/12)', {r: sp.Symbol('l') / 2, J: mm * sp.Symbol('l')**2 / 12})):
        print('  ', lab, ':', sp.factor(sp.expand(e4.subs(sub))))
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), 'e4_pendulum.txt'), 'w') as f:
        f.write(sp.srepr(e4))

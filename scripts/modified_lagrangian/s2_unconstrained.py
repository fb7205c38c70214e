"""s = 2, unconstrained 1-DOF: L = v^2/2 - U(q). The (2,2) scheme of the library: quadratic
through Q0 = qbar - h v/2, Q1 = qbar + z (midpoint control point), Q2 = qbar + h v/2, action by
the 2-point Gauss rule (kinetic part exact), z eliminated by stationarity. Prints the h^2 and
h^4 coefficients of L_d/h for the exact discrete Lagrangian and for the scheme (midpoint
variables; U_j = U^(j)(qbar)), and e4 = c4_exact - c4_scheme, the h^4 preadjustment term
(L~ = L + h^4 e4; the scheme's modified Lagrangian is L - h^4 e4 + O(h^6)).
Also the same for the (1,1) scheme (h^2 term) as a check of the machinery.
"""
import sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sympy as sp
from sympy.polys.domains import QQ
from exact_dl import R, h, v, cc, U, trunc, taylor, exact_dl, coeff_h, to_sympy

ORDER = 6  # keep h^0..h^4 of L_d/h (+ slack)


def sym_c(p):
    """p(c) + p(-c) over 2, then c^2 -> h^2 v^2 / 12 (2-point Gauss nodes +-h v/(2 sqrt 3))."""
    out = R(0)
    for k, co in p.items():
        if k[4] % 2 == 1:
            continue
        e = k[4] // 2
        kk = list(k)
        kk[4] = 0
        out += R({tuple(kk): co}) * (h**2 * v**2 * QQ(1, 12))**e
    return out


def scheme22():
    N = ORDER
    z = R(0)
    for _ in range(4):
        up = R(0)
        d = cc + QQ(2, 3) * z
        up = taylor(U, d, N, 1)
        z = trunc(QQ(1, 8) * h**2 * sym_c(up), N)
    d = cc + QQ(2, 3) * z
    pot = sym_c(taylor(U, d, N, 0))
    # kinetic: v^2/2 + 8 z^2 / (3 h^2)
    kin = QQ(1, 2) * v**2 + QQ(8, 3) * R({(k[0] - 2,) + k[1:]: c for k, c in trunc(z * z, N + 2).items()})
    return trunc(kin - pot, 4), z


def scheme11():
    return trunc(QQ(1, 2) * v**2 - taylor(U, R(0), 4, 0), 4)


if __name__ == '__main__':
    E, _ = exact_dl(4, mass=False)
    S, z = scheme22()
    c2E, c4E = [sp.factor(to_sympy(coeff_h(E, k))) for k in (2, 4)]
    c2S, c4S = [sp.factor(to_sympy(coeff_h(S, k))) for k in (2, 4)]
    print('exact  c2 =', c2E)
    print('exact  c4 =', c4E)
    print('(2,2)  c2 =', c2S)
    print('(2,2)  c4 =', c4S)
    print('midpoint control point: z =', sp.factor(to_sympy(z)))
    print('c2 exact - c2 (2,2) =', sp.simplify(c2E - c2S))
    e4 = sp.expand(c4E - c4S)
    print('e4 = c4_exact - c4_(2,2) =', sp.factor(e4), ' =', e4)
    S1 = scheme11()
    print('(1,1): e2 = c2_exact - c2_(1,1) =', sp.factor(c2E - to_sympy(coeff_h(S1, 2))))

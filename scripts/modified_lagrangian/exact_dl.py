"""Shared helper: h-expansion of the exact discrete Lagrangian of a 1-DOF Lagrangian
L = 1/2 m(q) v^2 - U(q) in midpoint variables (qbar = (q0+q1)/2, v = (q1-q0)/h).

m(qbar + d) = sum_j m_j d^j / j!, U(qbar + d) = sum_j U_j d^j / j! (the m_j, U_j are symbols:
derivatives at the midpoint; im0 = 1/m0). The exact solution on tau in [-1/2, 1/2] (t = h tau)
is qbar + d(tau) with d(+-1/2) = +-h v/2, found by Picard iteration of
d'' = -(1/2 m'(q) d'^2 + h^2 U'(q)) / m(q) with those boundary values; every object is a
polynomial (sympy sparse ring over QQ) truncated at a power of h.
"""
import sympy as sp
from sympy.polys.rings import ring
from sympy.polys.domains import QQ

NJ = 9
names = ['h', 'tau', 'v', 'im0', 'c', 'z2', 'z4'] + ['m%d' % j for j in range(NJ)] + ['U%d' % j for j in range(NJ)]
R, *gens = ring(','.join(names), QQ)
h, tau, v, im0, cc, z2, z4 = gens[:7]
m = gens[7:7 + NJ]
U = gens[7 + NJ:]
HALF = QQ(1, 2)


def trunc(p, n):
    return R({k: c for k, c in p.items() if k[0] <= n})


def dtau(p):
    return p.diff(tau)


def itau(p):
    """antiderivative in tau (from 0)."""
    return R({(k[0], k[1] + 1) + k[2:]: c / (k[1] + 1) for k, c in p.items()})


def at_tau(p, val):
    return p.evaluate(tau, val) if False else R(p.compose(tau, R(val)))


def taylor(coeffs, d, n, start=0):
    out, dp, f = R(0), R(1), 1
    for j in range(0, n + 1):
        out += coeffs[j + start] * dp * QQ(1, f)
        dp = trunc(dp * d, n)
        f *= (j + 1)
    return trunc(out, n)


def bvp_zero(Rh):
    y = itau(itau(Rh))
    a, b = at_tau(y, -HALF), at_tau(y, HALF)
    return y - (a + (b - a) * (tau + HALF))


def integrate_sym(p):
    P = itau(p)
    return at_tau(P, HALF) - at_tau(P, -HALF)


def _unused(): pass


def exact_dl(order, mass=True):
    """(L_d^E / h) up to h^order as a ring element (and d(tau))."""
    N = order + 2
    mm = list(m) if mass else [R(1)] + [R(0)] * (NJ - 1)
    inv0 = im0 if mass else R(1)
    d = h * v * tau
    for _ in range(order // 2 + 2):
        dt = dtau(d)
        mp = taylor(mm, d, N, 1)
        up = taylor(U, d, N, 1)
        x = trunc((taylor(mm, d, N, 0) - mm[0]) * inv0, N)
        inv, xp = R(0), R(1)
        for _k in range(N + 1):
            inv += xp
            xp = trunc(-xp * x, N)
        inv = trunc(inv * inv0, N)
        Rh = trunc(-(HALF * mp * trunc(dt**2, N + 2) + h**2 * up) * inv, N + 2)
        d = h * v * tau + bvp_zero(Rh)
    dt = dtau(d)
    lag = HALF * taylor(mm, d, N + 2, 0) * trunc(dt**2, N + 2) - h**2 * taylor(U, d, N, 0)
    lag = trunc(lag, order + 2)
    I = integrate_sym(lag)
    # divide by h^2
    I = R({(k[0] - 2,) + k[1:]: c for k, c in I.items()})
    return I, d


def coeff_h(p, k):
    return R({(0,) + kk[1:]: c for kk, c in p.items() if kk[0] == k})


def to_sympy(p):
    return p.as_expr()

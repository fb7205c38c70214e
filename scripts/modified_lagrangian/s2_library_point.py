"""Reference values of the 23 terms of e4 (s2_cartesian.py) at two states of library models, for
the Rust unit test of Preadjustment::modified_terms_s2: (A) paper A's double pendulum (two 1 kg,
1 m rods, revolute chain, gravity 9.81) at body angles -60, -60 deg with joint-angle rates
(0.7, -1.1); (B) a 1 kg, 1 m rod pinned at one end to the origin with a spring (30 N/m, rest
0.5 m) from its tip to the ground point (0.6, -1.6), body angle -45 deg, rate 0.9.

    python3 s2_library_point.py
"""
import numpy as np
import sympy as sp
from s2_cartesian import Tensors, e4_terms, COEFFS

g0 = 9.81


def double_pendulum():
    x1, y1, t1, x2, y2, t2 = qs = sp.symbols('x1 y1 t1 x2 y2 t2')
    Phi = [x1 - 0.5 * sp.cos(t1), y1 - 0.5 * sp.sin(t1),
           x1 + 0.5 * sp.cos(t1) - x2 + 0.5 * sp.cos(t2), y1 + 0.5 * sp.sin(t1) - y2 + 0.5 * sp.sin(t2)]
    V = g0 * (y1 + y2)
    M = np.diag([1, 1, 1 / 12, 1, 1, 1 / 12])

    def chi(th):
        a, b = th
        c1 = np.array([0.5 * np.cos(a), 0.5 * np.sin(a)])
        tip = 2 * c1
        c2 = tip + np.array([0.5 * np.cos(b), 0.5 * np.sin(b)])
        return np.array([c1[0], c1[1], a, c2[0], c2[1], b])
    return Tensors(list(qs), V, Phi), M, chi, np.radians([-60.0, -60.0]), np.array([0.7, -1.1])


def rod_spring():
    x, y, t = qs = sp.symbols('x y t')
    Phi = [x - 0.5 * sp.cos(t), y - 0.5 * sp.sin(t)]
    tipx, tipy = x + 0.5 * sp.cos(t), y + 0.5 * sp.sin(t)
    d = sp.sqrt((tipx - 0.6) ** 2 + (tipy + 1.6) ** 2)
    V = g0 * y + sp.Rational(1, 2) * 30 * (d - sp.Rational(1, 2)) ** 2
    M = np.diag([1, 1, 1 / 12])

    def chi(th):
        a = th[0]
        return np.array([0.5 * np.cos(a), 0.5 * np.sin(a), a])
    return Tensors(list(qs), V, Phi), M, chi, np.radians([-45.0]), np.array([0.9])


def velocity(th, om):
    # exact d chi / dt for the chains above: centre i moves with the tips before it
    out, tip_v = [], np.zeros(2)
    for a, w in zip(th, om):
        d = np.array([-np.sin(a), np.cos(a)]) * w
        out += [*(tip_v + 0.5 * d), w]
        tip_v = tip_v + d
    return np.array(out)


for name, (T, M, chi, th, om) in (('double pendulum', double_pendulum()), ('rod + spring', rod_spring())):
    q = chi(th)
    v = velocity(th, om)
    Vt, P = T.at(q)
    terms = e4_terms(M, Vt[0], Vt[1], Vt[2], Vt[3], P[0], P[1], P[2], P[3], v)
    print(name)
    print('q =', repr(list(q)))
    print('v =', repr(list(v)))
    print('terms =', ', '.join('%.15e' % terms[k] for k in COEFFS))
    print('e4 =', '%.15e' % sum(float(COEFFS[k]) * terms[k] for k in COEFFS))

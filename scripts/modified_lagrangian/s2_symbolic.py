"""Symbolic check of the fitted e4:  python3 s2_symbolic.py [d m]  (default 1 1: a curve in the plane).
Graph frame, M = I, all jet data symbolic (F_2, F_3, F_4, V_1..V_4, w), the oracle run over the
polynomial ring, minus the grouped formula of s2_cartesian.py written out symbolically (Phi = y - f(x)).
Prints the difference (0: for that (d, m) the formula is proved, for every V and every manifold).
"""
import sys, os, time, itertools
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import sympy as sp
from s2_oracle import Oracle


def main(d=1, m=1):
    t0 = time.time()
    n = d + m
    Fkeys = {k: [(i, idx) for i in range(m) for idx in itertools.combinations_with_replacement(range(d), k)] for k in (2, 3, 4)}
    Vkeys = {k: list(itertools.combinations_with_replacement(range(n), k)) for k in (1, 2, 3, 4)}
    fname = lambda k, i, idx: 'F%d_%d_%s' % (k, i, ''.join(map(str, idx)))
    vname = lambda k, idx: 'V%d_%s' % (k, ''.join(map(str, idx)))
    names = ['W%d' % j for j in range(d)] + [fname(k, i, idx) for k in (2, 3, 4) for i, idx in Fkeys[k]] \
        + [vname(k, idx) for k in (1, 2, 3, 4) for idx in Vkeys[k]]
    O = Oracle(d, m, extra=names)
    X = dict(zip(names, O.extra))
    F = {k: [{idx: X[fname(k, i, tuple(sorted(idx)))] for idx in itertools.product(range(d), repeat=k)} for i in range(m)]
         for k in (2, 3, 4)}
    Vt = {k: {idx: X[vname(k, tuple(sorted(idx)))] for idx in itertools.product(range(n), repeat=k)} for k in (1, 2, 3, 4)}
    e = O.e4_symbolic(F, Vt, [X['W%d' % j] for j in range(d)])
    print('oracle (symbolic, d = %d, m = %d, %d symbols) done, %.1fs, %d terms'
          % (d, m, len(names), time.time() - t0, len(sp.Add.make_args(e))), flush=True)
    # the formula, symbolically: graph frame, M = I, Phi = y - f(x), G = [0 | I], S = I
    S = {nm: sp.Symbol(nm) for nm in names}

    def vt(k):
        T = np.empty((n,) * k, dtype=object)
        for idx in itertools.product(range(n), repeat=k):
            T[idx] = S[vname(k, tuple(sorted(idx)))]
        return T

    def pt(k):  # D^k Phi_i = -F_k[i] on the tangent block, 0 elsewhere
        T = np.zeros((m,) + (n,) * k, dtype=object)
        for i in range(m):
            for idx in itertools.product(range(d), repeat=k):
                T[(i,) + idx] = -S[fname(k, i, tuple(sorted(idx)))]
        return T

    g, H, D3V, D4V = vt(1), vt(2), vt(3), vt(4)
    HP, D3P, D4P = pt(2), pt(3), pt(4)
    G = np.zeros((m, n), dtype=object)
    for i in range(m):
        G[i, d + i] = 1
    Pi = np.zeros((n, n), dtype=object)
    for j in range(d):
        Pi[j, j] = 1
    Si = np.eye(m, dtype=object)
    E = G.T
    v = np.array([S['W%d' % j] for j in range(d)] + [0] * m, dtype=object)
    R = range(n)
    c2 = lambda T, a, b: np.array([sum(T[k, i, j] * a[i] * b[j] for i in R for j in R) for k in range(m)], dtype=object)
    c3 = lambda T, a, b, c: np.array([sum(T[k, i, j, l] * a[i] * b[j] * c[l] for i in R for j in R for l in R) for k in range(m)], dtype=object)
    c4 = lambda T, a: np.array([sum(T[(k,) + ix] * a[ix[0]] * a[ix[1]] * a[ix[2]] * a[ix[3]] for ix in itertools.product(R, repeat=4)) for k in range(m)], dtype=object)
    mu0 = G @ g
    u = -Pi @ g
    gam = c2(HP, v, v)
    sig = Si @ gam
    nn = -E @ gam
    rho = sig - mu0
    Hrho = sum(rho[k] * HP[k] for k in range(m))
    beta = c2(HP, u, v)
    K2uv = -E @ beta
    kap3 = c3(D3P, v, v, v) + 3 * c2(HP, nn, v)
    K3 = -E @ kap3
    kap3u = c3(D3P, u, v, v) + 2 * c2(HP, K2uv, v) + c2(HP, nn, u)
    kap4 = c4(D4P, v) + 6 * c3(D3P, nn, v, v) + 3 * c2(HP, nn, nn) + 4 * c2(HP, K3, v)
    D3 = lambda a, b, c: sum(D3V[i, j, l] * a[i] * b[j] * c[l] for i in R for j in R for l in R)
    D4 = sum(D4V[ix] * v[ix[0]] * v[ix[1]] * v[ix[2]] * v[ix[3]] for ix in itertools.product(R, repeat=4))
    Q = sp.Rational
    form = (-Q(1, 1440) * u @ H @ u - Q(1, 720) * D3(u, v, v) - Q(1, 1440) * v @ H @ Pi @ H @ v - Q(1, 4320) * D4
            - Q(1, 720) * u @ H @ nn - Q(1, 1440) * nn @ H @ nn - Q(1, 720) * D3(nn, v, v) + Q(1, 720) * v @ H @ K3
            + Q(1, 240) * v @ H @ K2uv - Q(1, 720) * v @ H @ Pi @ Hrho @ v
            + Q(1, 960) * u @ Hrho @ u + Q(1, 480) * rho @ kap3u + Q(1, 2880) * rho @ kap4
            - Q(1, 1440) * v @ Hrho @ Pi @ Hrho @ v
            + Q(1, 160) * beta @ Si @ beta + Q(1, 240) * kap3 @ Si @ beta + Q(1, 1440) * kap3 @ Si @ kap3)
    diff = sp.expand(e - sp.expand(form))
    print('symbolic e4 (d = %d, m = %d) minus the fitted formula:' % (d, m), diff, ' (%.1fs)' % (time.time() - t0))
    return diff


if __name__ == '__main__':
    a = sys.argv[1:]
    main(*(int(x) for x in a[:2])) if len(a) >= 2 else main()

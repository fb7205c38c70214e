"""The Cartesian-invariant h^4 preadjustment term e4(q, v) of the constrained (2,2) scheme
(fitted exactly in the graph frame by s2_fit.py, translated to Cartesian form here), and checks.

    python3 s2_cartesian.py            checks: (1) graph-frame samples with a random linear change
                                       of coordinates (M not I) and a non-canonical constraint
                                       representation Phi -> A(q) Phi, against the exact oracle;
                                       (2) the pendulum family (rod, M = diag(m, m, J)) against
                                       the reduced e4 of s2_constrained.py.

Notation (q on the manifold, v tangent, M constant SPD, G = Phi_q, S = G M^-1 G^T,
Pi = M^-1 - M^-1 G^T S^-1 G M^-1, <a, b> = a^T M b):
    mu0 = S^-1 G M^-1 g                   u = -Pi g  (tangent acceleration)
    gamma_k = Hess Phi_k(v, v)            sigma = S^-1 gamma,   n = -M^-1 G^T sigma
    H_mu = mu0 . Hess Phi,  H_sig = sigma . Hess Phi   (n x n)
    beta_k  = Hess Phi_k(u, v)
    kap3_k  = D3 Phi_k(v, v, v) + 3 Hess Phi_k(n, v)
    K3      = -M^-1 G^T S^-1 kap3          (the graph's third-order coefficient f3(v, v, v))
    kap3u_k = D3 Phi_k(u, v, v) + 2 Hess Phi_k(K2uv, v) + Hess Phi_k(n, u),  K2uv = -M^-1 G^T S^-1 beta
    kap4_k  = D4 Phi_k(v,v,v,v) + 6 D3 Phi_k(n, v, v) + 3 Hess Phi_k(n, n) + 4 Hess Phi_k(K3, v)
"""
import sys, os, itertools
import numpy as np
import sympy as sp

HERE = os.path.dirname(os.path.abspath(__file__))

# (coefficient, term) -- see e4_terms below; the graph-frame names in s2_fit.py's output
COEFFS = {
    'vHsig Pi Hmu v': sp.Rational(1, 720),        # g(f2_N(f2_T(f2_N(v,v),v),v))
    'vHmu Pi Hmu v': sp.Rational(-1, 1440),       # g(f2_N(f2_T(g_N,v),v))
    'u Hmu u': sp.Rational(-1, 960),              # g(f2_N(g_T,g_T))
    'vHmu Pi H v': sp.Rational(1, 720),           # g(f2_N(H_T(v),v))
    'beta S beta': sp.Rational(1, 160),           # g(f2_T(f2_N(g_T,v),v))
    'u Hsig u': sp.Rational(1, 960),              # g(f2_T(f2_N(v,v),g_T))
    'kap3 S beta': sp.Rational(1, 240),           # g(f2_T(f3_N(v,v,v),v))
    'vH K2uv': sp.Rational(1, 240),               # g(f2_T(H_N(v),v))
    'mu kap3u': sp.Rational(-1, 480),             # g(f3_N(g_T,v,v))
    'sig kap3u': sp.Rational(1, 480),             # g(f3_T(f2_N(v,v),v,v))
    'mu kap4': sp.Rational(-1, 2880),             # g(f4_N(v,v,v,v))
    'u H n': sp.Rational(-1, 720),                # g(H_T(f2_N(v,v)))
    'u H u': sp.Rational(-1, 1440),               # g(H_T(g_T))
    'D3V u v v': sp.Rational(-1, 720),            # g(V3_T(v,v))
    'n H n': sp.Rational(-1, 1440),               # H(f2_N(v,v),f2_N(v,v))
    'vH Pi Hsig v': sp.Rational(-1, 720),         # H(f2_T(f2_N(v,v),v),v)
    'vH K3': sp.Rational(1, 720),                 # H(f3_N(v,v,v),v)
    'D3V n v v': sp.Rational(-1, 720),            # V3(f2_N(v,v),v,v)
    'vH Pi H v': sp.Rational(-1, 1440),           # H(H_T(v),v)
    'D4V v4': sp.Rational(-1, 4320),              # V4(v,v,v,v)
    'vHsig Pi Hsig v': sp.Rational(-1, 1440),     # f2(f2_N(f2_T(f2_N(v,v),v),v),v,v)
    'sig kap4': sp.Rational(1, 2880),             # f2(f4_N(v,v,v,v),v,v)
    'kap3 S kap3': sp.Rational(1, 1440),          # f3(f3_N(v,v,v),v,v,v)
}


def e4_terms(M, g, H, D3V, D4V, G, HP, D3P, D4P, v):
    """all terms (dict) from the tensors at q: M (n x n), g (n), H (n x n), D3V (n^3), D4V (n^4),
    G (m x n), HP (m x n x n), D3P (m x n^3), D4P (m x n^4); v tangent."""
    Mi = np.linalg.inv(M)
    S = G @ Mi @ G.T
    Si = np.linalg.inv(S)
    Pi = Mi - Mi @ G.T @ Si @ G @ Mi
    E = Mi @ G.T @ Si          # n x m: normal vector from a constraint-space residual
    mu0 = Si @ G @ Mi @ g
    u = -Pi @ g
    gam = np.einsum('kij,i,j->k', HP, v, v)
    sig = Si @ gam
    n = -E @ gam
    Hmu = np.einsum('k,kij->ij', mu0, HP)
    Hsig = np.einsum('k,kij->ij', sig, HP)
    beta = np.einsum('kij,i,j->k', HP, u, v)
    K2uv = -E @ beta
    kap3 = np.einsum('kijl,i,j,l->k', D3P, v, v, v) + 3 * np.einsum('kij,i,j->k', HP, n, v)
    K3 = -E @ kap3
    kap3u = (np.einsum('kijl,i,j,l->k', D3P, u, v, v) + 2 * np.einsum('kij,i,j->k', HP, K2uv, v)
             + np.einsum('kij,i,j->k', HP, n, u))
    kap4 = (np.einsum('kijlm,i,j,l,m->k', D4P, v, v, v, v) + 6 * np.einsum('kijl,i,j,l->k', D3P, n, v, v)
            + 3 * np.einsum('kij,i,j->k', HP, n, n) + 4 * np.einsum('kij,i,j->k', HP, K3, v))
    T = {
        'vHsig Pi Hmu v': v @ Hsig @ Pi @ Hmu @ v,
        'vHmu Pi Hmu v': v @ Hmu @ Pi @ Hmu @ v,
        'u Hmu u': u @ Hmu @ u,
        'vHmu Pi H v': v @ Hmu @ Pi @ H @ v,
        'beta S beta': beta @ Si @ beta,
        'u Hsig u': u @ Hsig @ u,
        'kap3 S beta': kap3 @ Si @ beta,
        'vH K2uv': v @ H @ K2uv,
        'mu kap3u': mu0 @ kap3u,
        'sig kap3u': sig @ kap3u,
        'mu kap4': mu0 @ kap4,
        'u H n': u @ H @ n,
        'u H u': u @ H @ u,
        'D3V u v v': np.einsum('ijl,i,j,l', D3V, u, v, v),
        'n H n': n @ H @ n,
        'vH Pi Hsig v': v @ H @ Pi @ Hsig @ v,
        'vH K3': v @ H @ K3,
        'D3V n v v': np.einsum('ijl,i,j,l', D3V, n, v, v),
        'vH Pi H v': v @ H @ Pi @ H @ v,
        'D4V v4': np.einsum('ijlm,i,j,l,m', D4V, v, v, v, v),
        'vHsig Pi Hsig v': v @ Hsig @ Pi @ Hsig @ v,
        'sig kap4': sig @ kap4,
        'kap3 S kap3': kap3 @ Si @ kap3,
    }
    return T


def e4_grouped(M, g, H, D3V, D4V, G, HP, D3P, D4P, v):
    """the same e4 written with rho = sigma - mu0 (= -lambda, the true multiplier) as in the doc."""
    Mi = np.linalg.inv(M)
    S = G @ Mi @ G.T
    Si = np.linalg.inv(S)
    Pi = Mi - Mi @ G.T @ Si @ G @ Mi
    E = Mi @ G.T @ Si
    mu0 = Si @ G @ Mi @ g
    u = -Pi @ g
    gam = np.einsum('kij,i,j->k', HP, v, v)
    sig = Si @ gam
    n = -E @ gam
    rho = sig - mu0
    Hrho = np.einsum('k,kij->ij', rho, HP)
    beta = np.einsum('kij,i,j->k', HP, u, v)
    K2uv = -E @ beta
    kap3 = np.einsum('kijl,i,j,l->k', D3P, v, v, v) + 3 * np.einsum('kij,i,j->k', HP, n, v)
    K3 = -E @ kap3
    kap3u = (np.einsum('kijl,i,j,l->k', D3P, u, v, v) + 2 * np.einsum('kij,i,j->k', HP, K2uv, v)
             + np.einsum('kij,i,j->k', HP, n, u))
    kap4 = (np.einsum('kijlm,i,j,l,m->k', D4P, v, v, v, v) + 6 * np.einsum('kijl,i,j,l->k', D3P, n, v, v)
            + 3 * np.einsum('kij,i,j->k', HP, n, n) + 4 * np.einsum('kij,i,j->k', HP, K3, v))
    D3 = lambda a, b, c: np.einsum('ijl,i,j,l', D3V, a, b, c)
    return (-u @ H @ u / 1440 - D3(u, v, v) / 720 - v @ H @ Pi @ H @ v / 1440
            - np.einsum('ijlm,i,j,l,m', D4V, v, v, v, v) / 4320
            - u @ H @ n / 720 - n @ H @ n / 1440 - D3(n, v, v) / 720 + v @ H @ K3 / 720 + v @ H @ K2uv / 240
            - v @ H @ Pi @ Hrho @ v / 720
            + u @ Hrho @ u / 960 + rho @ kap3u / 480 + rho @ kap4 / 2880 - v @ Hrho @ Pi @ Hrho @ v / 1440
            + beta @ Si @ beta / 160 + kap3 @ Si @ beta / 240 + kap3 @ Si @ kap3 / 1440)


def check_grouped(N=20, seed=5):
    """e4_grouped == e4_cart on random tensors (n = 5, m = 2, M SPD non-diagonal)."""
    rng = np.random.default_rng(seed)
    n, m = 5, 2
    worst = 0.0

    def sym(k, lead=()):
        A = rng.standard_normal(lead + (n,) * k)
        out = np.zeros_like(A)
        perms = list(itertools.permutations(range(k)))
        off = len(lead)
        for p in perms:
            out += np.transpose(A, tuple(range(off)) + tuple(off + i for i in p))
        return out / len(perms)

    for _ in range(N):
        B = rng.standard_normal((n, n))
        M = B @ B.T + n * np.eye(n)
        G = rng.standard_normal((m, n))
        args = (M, rng.standard_normal(n), sym(2), sym(3), sym(4), G, sym(2, (m,)), sym(3, (m,)), sym(4, (m,)))
        Mi = np.linalg.inv(M)
        Pi = Mi - Mi @ G.T @ np.linalg.inv(G @ Mi @ G.T) @ G @ Mi
        v = Pi @ rng.standard_normal(n)
        a, b = e4_cart(*args, v), e4_grouped(*args, v)
        worst = max(worst, abs(a - b) / max(1.0, abs(a)))
    return worst


def e4_cart(*args, coeffs=None):
    T = e4_terms(*args)
    C = COEFFS if coeffs is None else coeffs
    return sum(float(C[k]) * T[k] for k in C)


class Tensors:
    """lambdified derivative tensors of V and Phi (sympy expressions in the symbols qs)."""
    def __init__(self, qs, V, Phi):
        self.n, self.m = len(qs), len(Phi)
        arr = sp.Array
        dV = [sp.derive_by_array(V, qs)]
        for _ in range(3):
            dV.append(sp.derive_by_array(dV[-1], qs))
        P = arr(Phi)
        dP = [sp.derive_by_array(P, qs)]
        for _ in range(3):
            dP.append(sp.derive_by_array(dP[-1], qs))
        self.fV = [sp.lambdify([qs], x, 'numpy', cse=True) for x in dV]
        self.fP = [sp.lambdify([qs], x, 'numpy', cse=True) for x in dP]

    def at(self, q):
        n, m = self.n, self.m
        V = [np.array(f(q), float).reshape((n,) * (k + 1)) for k, f in enumerate(self.fV)]
        # derive_by_array puts the new index first: dP[k] has shape (n,)*(k+1) + (m,)
        P = [np.moveaxis(np.array(f(q), float).reshape((n,) * (k + 1) + (m,)), -1, 0) for k, f in enumerate(self.fP)]
        return V, P

    def e4(self, M, q, v, coeffs=None):
        V, P = self.at(q)
        return e4_cart(M, V[0], V[1], V[2], V[3], P[0], P[1], P[2], P[3], v, coeffs=coeffs)

    def e4_grad(self, M, q, v, d=1e-6):
        """e4 and its central-difference gradients in q and v (the tensors are evaluated once per q)."""
        n = len(q)
        V, P = self.at(q)
        f = lambda vv: e4_cart(M, V[0], V[1], V[2], V[3], P[0], P[1], P[2], P[3], vv)
        e = f(v)
        gv, gq = np.zeros(n), np.zeros(n)
        for i in range(n):
            dv = np.zeros(n)
            dv[i] = d
            gv[i] = (f(v + dv) - f(v - dv)) / (2 * d)
            gq[i] = (self.e4(M, q + dv, v) - self.e4(M, q - dv, v)) / (2 * d)
        return e, gq, gv


# ------------------------------------------------------------------ checks
def check_pendulum():
    """rod pendulum family: q = (x, y, p), Phi = (x - r cos p', ...) in the library geometry:
    Phi = [x - r cos p, y - r sin p] (p = theta - pi/2), M = diag(m, m, J), V = m g y."""
    e4 = sp.sympify(eval(open(os.path.join(HERE, 'e4_pendulum.txt')).read(), sp.__dict__))
    sy = {s.name: s for s in e4.free_symbols}
    x, y, p = sp.symbols('x y p')
    worst = 0.0
    for (mm, r, J, g) in ((1.0, 0.5, 1 / 12, 9.81), (2.0, 0.7, 0.3, 3.0), (1.0, 1.0, 0.0, 9.81)):
        Phi = [x - r * sp.cos(p), y - r * sp.sin(p)]
        T = Tensors([x, y, p], mm * g * y, Phi)
        M = np.diag([mm, mm, J if J > 0 else 1e-300])
        if J == 0:
            # point mass on the circle: drop the angle coordinate (q = (x, y), Phi = x^2 + y^2 - r^2)
            T = Tensors([x, y], mm * g * y, [x**2 + y**2 - r**2])
            M = np.diag([mm, mm])
        f = sp.lambdify([sy['theta'], sy['omega']], e4.subs({sy['m']: mm, sy['r']: r, sy['J']: J, sy['g']: g}))
        for th, w in ((0.3, 1.1), (1.2, -0.7), (2.5, 2.0)):
            if J == 0:
                q = np.array([r * np.sin(th), -r * np.cos(th)])
                v = np.array([r * np.cos(th), r * np.sin(th)]) * w
            else:
                q = np.array([r * np.sin(th), -r * np.cos(th), th - np.pi / 2])
                v = np.array([r * np.cos(th), r * np.sin(th), 1.0]) * w
            a, b = T.e4(M, q, v), float(f(th, w))
            worst = max(worst, abs(a - b) / max(1.0, abs(b)))
            print('  pendulum m=%g r=%g J=%.4g g=%g th=%.2f w=%.2f: Cartesian %.15e reduced %.15e diff %.1e'
                  % (mm, r, J, g, th, w, a, b, a - b))
    return worst


def check_graph(ns=20, seed=3, offset=True):
    """graph-frame samples, then a random linear change of coordinates q = B qt (M = B^T B) and a
    random non-canonical constraint representation Phi(q) = A(q) (y - f(x)), against the oracle."""
    sys.path.insert(0, HERE)
    from s2_fit import sample, oracle_input
    from s2_oracle import Oracle
    import random
    rng = random.Random(seed)
    nrng = np.random.default_rng(seed)
    worst = 0.0
    for d, m in ((1, 1), (2, 1), (1, 2), (2, 2)):
        O = Oracle(d, m)
        n = d + m
        qs = sp.symbols('q0:%d' % n)
        for k in range(ns // 4):
            D = sample(rng, d, m)
            e_exact, _ = O.e4(*oracle_input(D))
            # the graph-frame system as sympy expressions in the tilde coordinates z
            z = sp.symbols('z0:%d' % n)
            xs, ys = z[:d], z[d:]
            fexpr = [sum(sp.Rational(D.F[k2][i][idx]) * sp.Mul(*[xs[j] for j in idx]) / sp.factorial(k2)
                         for k2 in (2, 3, 4) for idx in itertools.product(range(d), repeat=k2)) for i in range(m)]
            Vexpr = sum(sp.Rational(D.V[k2][idx]) * sp.Mul(*[z[j] for j in idx]) / sp.factorial(k2)
                        for k2 in (1, 2, 3, 4) for idx in itertools.product(range(n), repeat=k2))
            Phit = [ys[i] - fexpr[i] for i in range(m)]
            # non-canonical representation: Phi -> A(z) Phi with A = I + random linear + quadratic
            A = sp.Matrix(m, m, lambda i, j: (1 if i == j else 0) + sum(sp.Rational(int(nrng.integers(-3, 4)), 4) * z[l] for l in range(n))
                          + sp.Rational(int(nrng.integers(-3, 4)), 5) * z[0]**2)
            Phit = list(A * sp.Matrix(Phit))
            # linear change of coordinates: q = B z + q0 (q0 an offset), M = B^-T B^-1 so that the
            # kinetic energy 1/2 |zdot|^2 = 1/2 qdot^T M qdot
            B = np.eye(n) + 0.4 * nrng.standard_normal((n, n))
            Bi = np.linalg.inv(B)
            q0 = nrng.standard_normal(n) * (1.0 if offset else 0.0)
            zq = [sum(float(Bi[i, j]) * (qs[j] - float(q0[j])) for j in range(n)) for i in range(n)]
            sub = dict(zip(z, zq))
            Vq = Vexpr.subs(sub)
            Phiq = [sp.expand(p.subs(sub)) for p in Phit]
            T = Tensors(list(qs), Vq, Phiq)
            M = Bi.T @ Bi
            w = np.array([float(x) for x in D.w])
            v = B @ np.concatenate([w, np.zeros(m)])
            e_c = T.e4(M, q0, v)
            Vt, Pt = T.at(q0)
            terms = e4_terms(M, Vt[0], Vt[1], Vt[2], Vt[3], Pt[0], Pt[1], Pt[2], Pt[3], v)
            scale = sum(abs(float(COEFFS[key]) * terms[key]) for key in COEFFS)
            rel = abs(e_c - float(e_exact)) / max(1.0, abs(float(e_exact)))
            worst = max(worst, rel)
            print('  graph d=%d m=%d sample %d: oracle %.15e  Cartesian %.15e  rel diff %.1e  (sum of |terms| %.1e, cond(B) %.1e)'
                  % (d, m, k, float(e_exact), e_c, rel, scale, np.linalg.cond(B)), flush=True)
    return worst


if __name__ == '__main__':
    print('grouped (rho) form vs the 23-term form, random tensors: worst rel diff %.1e' % check_grouped())
    print('pendulum family: worst rel diff %.1e' % check_pendulum())
    if len(sys.argv) > 1 and sys.argv[1] == 'nooffset':  # the same samples with q0 = 0 (roundoff test)
        print('graph samples, q0 = 0: worst rel diff %.1e' % check_graph(offset=False))
    else:
        print('graph samples, random linear map + non-canonical Phi: worst rel diff %.1e' % check_graph())

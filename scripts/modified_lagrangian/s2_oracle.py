"""Exact (rational) oracle for the h^4 preadjustment term e4 of the constrained (2,2) scheme.

Canonical local form ("graph frame").  M = I (any constant SPD M is reduced to this by the
linear change q -> M^(1/2) q, under which the scheme -- quadratic Lagrange interpolation,
Gauss quadrature, constraints at the control points -- is covariant), the point is q = 0, the
tangent space is the first d coordinates x, the constraint manifold is the graph
y = f(x) (m normal coordinates y), f(0) = 0, Df(0) = 0:

    f_i(x) = sum_{k=2..4} F_k[i](x, ..., x) / k!        (F_k[i] symmetric d^k tensors)
    V(q)   = sum_{k=1..4} V_k(q, ..., q) / k!            (V_k symmetric n^k tensors, n = d + m)

Every smooth (M, V, Phi) at every point of its manifold is, after a Euclidean motion, of this
form up to terms that cannot enter e4 (f5, V5: by the scaling argument of
docs/modified-lagrangian.md section 3, e4 has length dimension that excludes them).  The
manifold is parametrised by chi(theta) = (theta, f(theta)); the midpoint variables are
theta_bar = 0, w in R^d, so e4 is evaluated at q = 0, v = (w, 0).

c4^E: series solution (Picard iteration in tau = t/h in [-1/2, 1/2]) of the reduced
Euler-Lagrange equation  (I + Df^T Df) theta'' = -Df^T D2f(theta', theta') - grad_x V - Df^T grad_y V
with theta(-+1/2) = -+ h w / 2, action integrated exactly; c4^S: the library's (2,2) scheme
through chi(-h w/2), chi(h^2 a), chi(h w/2), 2-point Gauss rule (nodes tau - 1/2 = s,
s^2 = 1/12, odd powers cancel), a stationary (an O(h^4) error in the midpoint control point
changes L_d/h by O(h^6)).  All arithmetic exact over QQ (sympy sparse polynomial rings).

e4(F, Vt, w) = c4^E - c4^S, an exact rational.
"""
import itertools
from fractions import Fraction
from math import factorial
from sympy.polys.rings import ring
from sympy.polys.domains import QQ

NH = 7  # keep powers of h up to NH


def sym_monos(T, k, nvar):
    """monomial dict {exponent tuple: coeff} of T(x,...,x)/k! (T: dict index-tuple -> Fraction,
    full symmetric tensor, or callable)."""
    out = {}
    for idx in itertools.product(range(nvar), repeat=k):
        c = T[idx]
        if c == 0:
            continue
        e = [0] * nvar
        for i in idx:
            e[i] += 1
        e = tuple(e)
        if isinstance(c, (int, Fraction)):
            c = Fraction(c) / factorial(k)
        else:  # a ring element (symbolic data, s2_symbolic.py)
            c = c * QQ(1, factorial(k))
        out[e] = out.get(e, 0) + c
    return {e: c for e, c in out.items() if c != 0}


def _const(R, c):
    if isinstance(c, (int, Fraction)):
        c = Fraction(c)
        return R(QQ(c.numerator, c.denominator))
    return c


def mono_diff(monos, j):
    out = {}
    for e, c in monos.items():
        if e[j] > 0:
            ee = list(e)
            ee[j] -= 1
            out[tuple(ee)] = out.get(tuple(ee), 0) + c * e[j]
    return out


class Oracle:
    def __init__(self, d, m, extra=()):
        """extra: names of additional generators (symbolic data, see s2_symbolic.py)."""
        self.d, self.m, self.n = d, m, d + m
        names = ['h', 'tau', 's'] + ['a%d' % i for i in range(d)] + list(extra)
        self.R, *gens = ring(','.join(names), QQ)
        self.h, self.tau, self.s = gens[:3]
        self.a = gens[3:3 + d]
        self.extra = gens[3 + d:]

    # -- truncated arithmetic
    def tr(self, p, N=NH):
        return self.R({k: c for k, c in p.items() if k[0] <= N})

    def mul(self, p, q, N=NH):
        return self.tr(p * q, N)

    def evalpoly(self, monos, args, N=NH):
        """sum c prod args^e, truncated in h."""
        nv = len(args)
        maxdeg = [max([e[i] for e in monos] + [0]) for i in range(nv)]
        pw = []
        for i in range(nv):
            l = [self.R(1)]
            for _ in range(maxdeg[i]):
                l.append(self.mul(l[-1], args[i], N))
            pw.append(l)
        out = self.R(0)
        for e, c in monos.items():
            t = _const(self.R, c)
            for i in range(nv):
                if e[i]:
                    t = self.mul(t, pw[i][e[i]], N)
            out += t
        return out

    def setup(self, F, Vt):
        """F[k]: list over i < m of symmetric d^k tensors (dict idx -> Fraction), k = 2, 3, 4;
        Vt[k]: symmetric n^k tensor, k = 1..4."""
        d, m, n = self.d, self.m, self.n
        self.f = []
        for i in range(m):
            mon = {}
            for k in (2, 3, 4):
                for e, c in sym_monos(F[k][i], k, d).items():
                    mon[e] = mon.get(e, 0) + c
            self.f.append(mon)
        self.df = [[mono_diff(self.f[i], j) for j in range(d)] for i in range(m)]
        self.ddf = [[[mono_diff(self.df[i][j], k) for k in range(d)] for j in range(d)] for i in range(m)]
        V = {}
        for k in (1, 2, 3, 4):
            for e, c in sym_monos(Vt[k], k, n).items():
                V[e] = V.get(e, 0) + c
        self.V = V
        self.gV = [mono_diff(V, j) for j in range(n)]

    def chi(self, th, N=NH):
        return list(th) + [self.evalpoly(self.f[i], th, N) for i in range(self.m)]

    def exact_c4(self, w):
        R, h, tau, d, m = self.R, self.h, self.tau, self.d, self.m
        half = QQ(1, 2)
        hw = [h * _const(R, wi) for wi in w]
        th = [hw[j] * tau for j in range(d)]

        def itau(p):
            return R({(k[0], k[1] + 1) + k[2:]: c / (k[1] + 1) for k, c in p.items()})

        def at(p, val):
            return R(p.compose(tau, R(val)))

        for it in range(5):
            tt = [p.diff(tau) for p in th]
            Df = [[self.evalpoly(self.df[i][j], th) for j in range(d)] for i in range(m)]
            D2 = [sum((self.mul(self.evalpoly(self.ddf[i][j][k], th), self.mul(tt[j], tt[k]))
                       for j in range(d) for k in range(d)), R(0)) for i in range(m)]
            q = self.chi(th)
            gv = [self.evalpoly(self.gV[j], q) for j in range(self.n)]
            rhs = []
            for j in range(d):
                r = -h**2 * gv[j]
                for i in range(m):
                    r -= self.mul(Df[i][j], D2[i] + h**2 * gv[d + i])
                rhs.append(self.tr(r))

            def Bapply(x):  # (Df^T Df) x
                y = [sum((self.mul(Df[i][k], x[k]) for k in range(d)), R(0)) for i in range(m)]
                return [sum((self.mul(Df[i][j], y[i]) for i in range(m)), R(0)) for j in range(d)]

            z, term = list(rhs), list(rhs)
            for _ in range(4):
                term = [-t for t in Bapply(term)]
                z = [z[j] + term[j] for j in range(d)]
            new = []
            for j in range(d):
                y = itau(itau(z[j]))
                ya, yb = at(y, -half), at(y, half)
                new.append(self.tr(hw[j] * tau + y - (ya + (yb - ya) * (tau + half))))
            th = new
        tt = [p.diff(tau) for p in th]
        q = self.chi(th)
        qt = [p.diff(tau) for p in q]
        lag = sum((self.mul(x, x) for x in qt), R(0)) * half - h**2 * self.evalpoly(self.V, q)
        P = itau(self.tr(lag))
        I = at(P, half) - at(P, -half)
        return self.coeff(I, 6)

    def coeff(self, p, k):
        """coefficient of h^k (tau-free) as a polynomial in the remaining generators."""
        return self.R({(0,) + kk[1:]: c for kk, c in p.items() if kk[0] == k})

    def scheme_c4(self, w):
        R, h, s, d, m = self.R, self.h, self.s, self.d, self.m
        hw = [h * _const(R, wi) for wi in w]
        q0 = self.chi([-x / 2 for x in hw])
        q1 = self.chi([x / 2 for x in hw])
        qm = self.chi([h**2 * ai for ai in self.a])
        D = [q1[i] - q0[i] for i in range(self.n)]
        D2 = [q0[i] + q1[i] - 2 * qm[i] for i in range(self.n)]
        kin = (sum((self.mul(x, x) for x in D), R(0)) + QQ(4, 3) * sum((self.mul(x, x) for x in D2), R(0))) / 2
        qc = [qm[i] + s * D[i] + 2 * s**2 * D2[i] for i in range(self.n)]
        pot = self.evalpoly(self.V, qc)
        # symmetric Gauss average: drop odd powers of s, s^2 -> 1/12
        ps = R(0)
        for k, c in pot.items():
            if k[2] % 2:
                continue
            ps += R({(k[0], k[1], 0) + k[3:]: c * QQ(1, 12)**(k[2] // 2)})
        F = self.tr(kin - h**2 * ps)  # = h^2 (L_d / h)
        F2, F4 = self.coeff(F, 4), self.coeff(F, 6)
        # stationary a: F2 quadratic in a
        import sympy as sp
        asym = sp.symbols('a0:%d' % d)
        F2e = F2.as_expr()
        sol = sp.solve([sp.diff(F2e, ai) for ai in asym], asym, dict=True)[0]
        F4e = F4.as_expr()
        if self.extra:
            return sp.expand(F4e.subs(sol)), sol
        return sp.Rational(F4e.subs(sol)), sol

    def e4_symbolic(self, F, Vt, w):
        """c4^E - c4^S as a sympy expression (data may contain the extra generators)."""
        import sympy as sp
        self.setup(F, Vt)
        cE = self.exact_c4(w).as_expr()
        cS, sol = self.scheme_c4(w)
        return sp.expand(cE - cS)

    def e4(self, F, Vt, w):
        self.setup(F, Vt)
        cE = self.exact_c4(w)
        cE = cE.as_expr()
        cS, sol = self.scheme_c4(w)
        import sympy as sp
        return Fraction(int(sp.numer(sp.nsimplify(cE - cS))), int(sp.denom(sp.nsimplify(cE - cS)))), (cE, cS, sol)


def full_sym(vals, k, nvar):
    """symmetric tensor dict from a function of sorted index tuples."""
    T = {}
    for idx in itertools.product(range(nvar), repeat=k):
        T[idx] = vals(tuple(sorted(idx)))
    return T

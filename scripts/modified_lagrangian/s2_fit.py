"""Fit of the constrained (2,2) e4 on the tree invariants of s2_trees.py, exact rational.

    python3 s2_fit.py [d m nsamples]      (default 2 2 40)

Random rational graph-frame samples (f_2, f_3, f_4, V_1..V_4, w small rationals), the exact e4
of each from s2_oracle.py, the candidate invariants (connected tree contractions) evaluated in
exact arithmetic, a maximal independent subset of candidates chosen on the samples, and the
exact linear solve; the remaining samples check the fit (exact residual).
"""
import sys, os, time, itertools, random
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fractions import Fraction as Fr
import numpy as np
import sympy as sp
from s2_oracle import Oracle
from s2_trees import rooted_trees, scalars, evaluate, name, Data


def rand_sym(rng, nvar, k, lo=-4, hi=4, den=3):
    T = np.empty((nvar,) * k, dtype=object)
    vals = {}
    for idx in itertools.product(range(nvar), repeat=k):
        key = tuple(sorted(idx))
        if key not in vals:
            vals[key] = Fr(rng.randint(lo, hi), rng.randint(1, den))
        T[idx] = vals[key]
    return T


def sample(rng, d, m):
    n = d + m
    V = {k: rand_sym(rng, n, k) for k in (1, 2, 3, 4)}
    F = {k: np.stack([rand_sym(rng, d, k) for _ in range(m)]) if m else np.zeros((0,) + (d,) * k, dtype=object)
         for k in (2, 3, 4)}
    w = np.array([Fr(rng.randint(-3, 3), rng.randint(1, 2)) or Fr(1) for _ in range(d)], dtype=object)
    return Data(d, m, V, F, w)


def oracle_input(D):
    Fd = {k: [{idx: D.F[k][i][idx] for idx in itertools.product(range(D.d), repeat=k)} for i in range(D.m)]
          for k in (2, 3, 4)}
    Vd = {k: {idx: D.V[k][idx] for idx in itertools.product(range(D.n), repeat=k)} for k in (1, 2, 3, 4)}
    return Fd, Vd, list(D.w)


def independent_subset(S, Ds):
    """greedy maximal independent subset of the candidates (float rank on random float data)."""
    A = np.array([[float(evaluate(D, s)) for s in S] for D in Ds])
    A = A / np.maximum(np.abs(A).max(axis=0), 1e-300)
    keep = []
    for j in range(len(S)):
        M = A[:, keep + [j]]
        if np.linalg.matrix_rank(M, tol=1e-9) == len(keep) + 1:
            keep.append(j)
    return keep


def main(d=2, m=2, ns=40, seed=12345):
    rng = random.Random(seed)
    t0 = time.time()
    T = rooted_trees()
    S = scalars(T)
    nrng = np.random.default_rng(0)
    from s2_trees import random_data
    keep = independent_subset(S, [random_data(max(d, 3), max(m, 3), nrng) for _ in range(80)])
    B = [S[j] for j in keep]
    print('candidates: %d roots, %d independent (generic d, m)' % (len(S), len(B)), flush=True)
    O = Oracle(d, m)
    rows, rhs = [], []
    for k in range(ns):
        D = sample(rng, d, m)
        if k % 10 == 0:
            print('  sample', k, '%.1fs' % (time.time() - t0), flush=True)
        e, _ = O.e4(*oracle_input(D))
        rows.append([Fr(evaluate(D, s)) for s in B])
        rhs.append(e)
    print('oracle: %d samples (d = %d, m = %d), %.1fs' % (ns, d, m, time.time() - t0), flush=True)
    from sympy.polys.matrices import DomainMatrix
    from sympy import QQ
    A = DomainMatrix([[QQ(x.numerator, x.denominator) for x in row] for row in rows], (ns, len(B)), QQ)
    b = DomainMatrix([[QQ(x.numerator, x.denominator)] for x in rhs], (ns, 1), QQ)
    r = A.rank()
    print('rank of the sample matrix:', r, 'of', len(B), flush=True)
    # exact least squares (normal equations; with a rank deficit: the pivot columns only)
    piv = list(A.transpose().rref()[1]) if r < len(B) else list(range(len(B)))
    if r < len(B):
        # pivots of A^T's rref are rows; we need independent *columns* of A
        piv = list(A.rref()[1])
        print('undetermined (dependent on the samples) candidates:', [name(B[j]) for j in range(len(B)) if j not in piv])
    Ap = A.extract(list(range(ns)), piv)
    AtA, Atb = Ap.transpose() * Ap, Ap.transpose() * b
    cp = AtA.lu_solve(Atb)
    res = Ap * cp - b
    c = [0] * len(B)
    for jj, j in enumerate(piv):
        c[j] = cp[jj, 0].element
    resmax = max(abs(res[i, 0].element) for i in range(ns))
    print('exact residual: max |A c - e4| =', resmax, flush=True)
    return B, c, resmax


if __name__ == '__main__':
    a = sys.argv[1:]
    d, m, ns = (int(a[0]), int(a[1]), int(a[2])) if len(a) >= 3 else (2, 2, 40)
    B, c, res = main(d, m, ns)
    for s, ci in zip(B, c):
        print('  %12s  %s' % (ci, name(s)))

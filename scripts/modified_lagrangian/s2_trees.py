"""Candidate invariants for e4 in the graph frame (M = I, q = 0, tangent = first d coordinates).

Building blocks: the ambient derivatives V_k (k = 1..4, symmetric n^k tensors; g = V_1,
H = V_2, ...), the graph coefficients F_k (k = 2, 3, 4: f_k(x1..xk) in N, symmetric in the
tangent slots; F_2 = the second fundamental form) and the tangent velocity v.  The exact and the
scheme's h-expansions are sums of elementary differentials, so e4 is a linear combination of
*connected tree* contractions (no traces, no products of scalars).  Each V slot is tangent (T)
or normal (N), F_k has k T slots and one N slot, v is a T leaf.  Time scaling
(V -> c V, v -> sqrt(c) v) forces (#v leaves) + 2 (#V nodes) = 6 ("tw" = 6); the length
dimension is then automatic for trees.

Rooted tree: (kind, k, out, children) with kind 'v' | 'V' | 'F', out in 'T','N' (the type of
the free slot), children a sorted tuple of rooted trees.  Scalar: ('S', kind, k, children)
with every slot of the root node filled.
"""
import itertools
import numpy as np

TW_MAX = 6
FS_MAX = 4


def tw(t):
    return t[4]


def fs(t):
    return t[5]


def mk(kind, k, out, ch):
    ch = tuple(sorted(ch, key=repr))
    if kind == 'v':
        w, f = 1, 0
    elif kind == 'V':
        w, f = 2, 0
    else:
        w, f = 0, k - 1
    w += sum(c[4] for c in ch)
    f += sum(c[5] for c in ch)
    return (kind, k, out, ch, w, f)


def multisets(pool, r, budget_tw, budget_fs):
    """multisets of r trees from pool (list sorted by repr) with total tw <= budget, fs <= budget."""
    def rec(start, r, btw, bfs):
        if r == 0:
            yield ()
            return
        for i in range(start, len(pool)):
            t = pool[i]
            if t[4] * r > btw + 0 and t[4] > btw:
                continue
            if t[4] > btw or t[5] > bfs:
                continue
            for rest in rec(i, r - 1, btw - t[4], bfs - t[5]):
                yield (t,) + rest
    yield from rec(0, r, budget_tw, budget_fs)


def rooted_trees():
    leaves = [mk('v', 0, 'T', ()), mk('V', 1, 'T', ()), mk('V', 1, 'N', ())]
    trees = set(leaves)
    changed = True
    while changed:
        changed = False
        pool = sorted(trees, key=repr)
        new = set()
        for kind, k in [('V', 2), ('V', 3), ('V', 4), ('F', 2), ('F', 3), ('F', 4)]:
            base_tw = 2 if kind == 'V' else 0
            base_fs = 0 if kind == 'V' else k - 1
            if base_fs > FS_MAX:
                continue
            for out in 'TN':
                if kind == 'V':
                    for ch in multisets(pool, k - 1, TW_MAX - base_tw, FS_MAX - base_fs):
                        new.add(mk(kind, k, out, ch))
                else:
                    Tpool = [t for t in pool if t[2] == 'T']
                    Npool = [t for t in pool if t[2] == 'N']
                    if out == 'N':
                        for ch in multisets(Tpool, k, TW_MAX - base_tw, FS_MAX - base_fs):
                            new.add(mk(kind, k, out, ch))
                    else:
                        for nc in Npool:
                            for ch in multisets(Tpool, k - 1, TW_MAX - base_tw - nc[4], FS_MAX - base_fs - nc[5]):
                                new.add(mk(kind, k, out, ch + (nc,)))
        new = {t for t in new if t[4] <= TW_MAX and t[5] <= FS_MAX}
        if not new <= trees:
            trees |= new
            changed = True
    return sorted(trees, key=repr)


def scalars(trees):
    """all roots with every slot filled, total tw == 6."""
    out = []
    pool = trees
    Tpool = [t for t in pool if t[2] == 'T']
    Npool = [t for t in pool if t[2] == 'N']
    for kind, k in [('V', 1), ('V', 2), ('V', 3), ('V', 4), ('F', 2), ('F', 3), ('F', 4)]:
        base_tw = 2 if kind == 'V' else 0
        base_fs = 0 if kind == 'V' else k - 1
        if kind == 'V':
            for ch in multisets(pool, k, TW_MAX - base_tw, FS_MAX - base_fs):
                s = mk(kind, k, 'S', ch)
                if s[4] == TW_MAX:
                    out.append(s)
        else:
            for nc in Npool:
                for ch in multisets(Tpool, k, TW_MAX - base_tw - nc[4], FS_MAX - base_fs - nc[5]):
                    s = mk(kind, k, 'S', ch + (nc,))
                    if s[4] == TW_MAX:
                        out.append(s)
    return out


# ---------------------------------------------------------------- evaluation
class Data:
    """V[k]: ndarray n^k (k = 1..4), F[k]: ndarray m x d^k (k = 2..4), w: ndarray d."""
    def __init__(self, d, m, V, F, w):
        self.d, self.m, self.n = d, m, d + m
        self.V, self.F, self.w = V, F, w


def contract(T, vecs):
    """contract the leading len(vecs) axes of T with vecs (in order)."""
    for x in vecs:
        T = np.tensordot(x, T, axes=([0], [0]))
    return T


def embed(D, x, typ):
    z = np.zeros(D.n, dtype=x.dtype)
    if typ == 'T':
        z[:D.d] = x
    else:
        z[D.d:] = x
    return z


def ev(D, t, memo):
    key = id(t)
    if key in memo:
        return memo[key]
    kind, k, out, ch = t[:4]
    if kind == 'v':
        r = D.w
    elif kind == 'V':
        vecs = [embed(D, ev(D, c, memo), c[2]) for c in ch]
        full = contract(D.V[k], vecs)
        if out == 'S':
            r = full
        else:
            r = full[:D.d] if out == 'T' else full[D.d:]
    else:
        Tch = [c for c in ch if c[2] == 'T']
        Nch = [c for c in ch if c[2] == 'N']
        Fk = D.F[k]  # m x d^k
        Tv = [ev(D, c, memo) for c in Tch]
        if out == 'N':
            r = contract(np.moveaxis(Fk, 0, -1), Tv)
        else:
            nv = ev(D, Nch[0], memo)
            A = np.tensordot(nv, Fk, axes=([0], [0]))  # d^k
            r = contract(A, Tv)
    memo[key] = r
    return r


def evaluate(D, s):
    r = ev(D, s, {})
    return r.item() if isinstance(r, np.ndarray) else r


def name(t):
    kind, k, out, ch = t[:4]
    if kind == 'v':
        return 'v'
    if kind == 'V':
        base = {1: 'g', 2: 'H', 3: 'V3', 4: 'V4'}[k]
    else:
        base = 'f%d' % k
    o = '' if out == 'S' else '_' + out
    if not ch:
        return base + o
    return base + o + '(' + ','.join(name(c) for c in ch) + ')'


def random_data(d, m, rng, dtype=float):
    n = d + m

    def sym(shape_n, k):
        A = rng.standard_normal((shape_n,) * k)
        S = np.zeros_like(A)
        perms = list(itertools.permutations(range(k)))
        for p in perms:
            S += np.transpose(A, p)
        return S / len(perms)

    V = {k: sym(n, k) for k in (1, 2, 3, 4)}
    F = {k: np.stack([sym(d, k) for _ in range(m)]) for k in (2, 3, 4)}
    return Data(d, m, V, F, rng.standard_normal(d))


if __name__ == '__main__':
    import time
    t0 = time.time()
    T = rooted_trees()
    S = scalars(T)
    print('rooted trees', len(T), 'scalar roots', len(S), '%.1fs' % (time.time() - t0))
    rng = np.random.default_rng(0)
    for d, m in ((2, 2), (3, 3)):
        Ds = [random_data(d, m, rng) for _ in range(3 * len(S) // 2 + 20)]
        A = np.array([[evaluate(D, s) for s in S] for D in Ds])
        print(d, m, 'rank', np.linalg.matrix_rank(A, tol=1e-8 * np.abs(A).max()))

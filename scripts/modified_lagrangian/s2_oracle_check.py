import sys, time, itertools, random
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fractions import Fraction as Fr
from s2_oracle import Oracle, full_sym
random.seed(1)
def rsym(k, n):
    cache = {}
    def f(idx):
        if idx not in cache: cache[idx] = Fr(random.randint(-5, 5), random.randint(1, 3))
        return cache[idx]
    return full_sym(f, k, n)
# unconstrained, d = 2
d, m = 2, 0
O = Oracle(d, m)
Vt = {k: rsym(k, 2) for k in (1, 2, 3, 4)}
F = {2: [], 3: [], 4: []}
w = [Fr(1, 2), Fr(-2, 3)]
t = time.time()
e, info = O.e4(F, Vt, w)
print('oracle', e, float(e), time.time() - t)
g = [Vt[1][(i,)] for i in range(2)]
H = [[Vt[2][(i, j)] for j in range(2)] for i in range(2)]
gHg = sum(g[i] * H[i][j] * g[j] for i in range(2) for j in range(2))
D3 = sum(Vt[3][(i, j, k)] * g[i] * w[j] * w[k] for i in range(2) for j in range(2) for k in range(2))
Hv = [sum(H[i][j] * w[j] for j in range(2)) for i in range(2)]
D4 = sum(Vt[4][idx] * w[idx[0]] * w[idx[1]] * w[idx[2]] * w[idx[3]] for idx in itertools.product(range(2), repeat=4))
form = -gHg / 1440 + D3 / 720 - (Hv[0]**2 + Hv[1]**2) / 1440 - D4 / 4320
print('formula', form, 'diff', e - form)
# circle, pendulum family at angle th with sin = 3/5, cos = 4/5, g = 7
sn, cs, gg = Fr(3, 5), Fr(4, 5), Fr(7)
O = Oracle(1, 1)
F = {2: [{(0, 0): Fr(1)}], 3: [{(0, 0, 0): Fr(0)}], 4: [{(0, 0, 0, 0): Fr(3)}]}
Vt = {1: {(0,): gg * sn, (1,): gg * cs}, 2: full_sym(lambda i: Fr(0), 2, 2), 3: full_sym(lambda i: Fr(0), 3, 2), 4: full_sym(lambda i: Fr(0), 4, 2)}
for wv in (Fr(1), Fr(3, 2)):
    t = time.time()
    e, info = O.e4(F, Vt, [wv])
    ref = (3 * gg**3 * sn**2 * cs + 23 * gg**2 * wv**2 * sn**2 - 2 * gg**2 * wv**2 - gg * wv**4 * cs + wv**6) / 2880
    print('circle w', wv, 'oracle', e, 'pendulum formula', ref, 'diff', e - ref, time.time() - t)

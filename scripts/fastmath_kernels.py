#!/usr/bin/env python3
"""The polynomial kernels of crates/vehsim-core/src/tyre/fastmath.rs: Chebyshev interpolants, computed in 60-digit
decimal arithmetic and printed in monomial form (lowest degree first) with their largest error.

    python3 scripts/fastmath_kernels.py [ATAN_DEGREE [SIN_DEGREE]]     (defaults 8 and 7)

Q(s) = (atan(sqrt s)/sqrt s - 1)/s on [0, tan^2(pi/12)], R(s) = (sin(sqrt s)/sqrt s - 1)/s on
[0, pi^2/4], G(r) = (e^r - 1 - r)/r^2 on [-ln2/2, ln2/2] (degree 9). Standard library only.
"""
from decimal import Decimal as D, getcontext
getcontext().prec = 60
PI = D('3.14159265358979323846264338327950288419716939937510582097494')
def dcos(x):
    x = x % (2*PI)
    s, t, k = D(1), D(1), 0
    while True:
        k += 2
        t = -t * x * x / (k * (k - 1))
        if abs(t) < D(10) ** -58: break
        s += t
    return s
def dsqrt(x): return x.sqrt()
def atan_small(u):  # |u| < 0.3
    s, t, k = u, u, 0
    while True:
        k += 1
        t = -t * u * u
        term = t / (2 * k + 1)
        if abs(term) < D(10) ** -58: break
        s += term
    return s
def sin_series(x):
    s, t, k = x, x, 1
    while True:
        t = -t * x * x / ((k + 1) * (k + 2)); k += 2
        if abs(t) < D(10) ** -58: break
        s += t
    return s
def cheb_fit(f, lo, hi, n):
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    N = n + 1
    ys = [dcos(PI * (j + D('0.5')) / N) for j in range(N)]
    fs = [f(mid + half * y) for y in ys]
    c = []
    for k in range(N):
        acc = sum(fs[j] * dcos(PI * k * (j + D('0.5')) / N) for j in range(N))
        c.append(2 * acc / N)
    c[0] /= 2
    # Chebyshev T_k(y) as monomials in y
    T = [[D(1)], [D(0), D(1)]]
    for k in range(2, N):
        a = [D(0)] + [2 * v for v in T[k - 1]]
        b = T[k - 2] + [D(0)] * (len(a) - len(T[k - 2]))
        T.append([x - y for x, y in zip(a, b)])
    py = [D(0)] * N
    for k in range(N):
        for i, v in enumerate(T[k]): py[i] += c[k] * v
    # y = (s - mid)/half -> monomials in s
    from math import comb
    ps = [D(0)] * N
    for i in range(N):
        for j in range(i + 1):
            ps[j] += py[i] * comb(i, j) * (D(1) if i == j else (-mid) ** (i - j)) / half ** i
    return ps
def check(f, ps, lo, hi, m=2000):
    e = D(0)
    for j in range(m + 1):
        s = lo + (hi - lo) * j / m
        p = D(0)
        for v in reversed(ps): p = p * s + v
        e = max(e, abs(p - f(s)))
    return e
tan_pi12 = 2 - dsqrt(D(3))
smax = tan_pi12 ** 2
def q_atan(s):
    if s == 0: return D(-1) / 3
    u = dsqrt(s)
    return (atan_small(u) / u - 1) / s
import sys
n = int(sys.argv[1]) if len(sys.argv) > 1 else 8
m = int(sys.argv[2]) if len(sys.argv) > 2 else 7
pa = cheb_fit(q_atan, D(0), smax * D('1.0001'), n)
print("atan Q deg", n, "max abs err", check(q_atan, pa, D(0), smax), "times s_max*u:", check(q_atan, pa, D(0), smax) * smax)
for v in pa: print("    %s," % format(float(v), '.17e'))
def r_sin(s):
    if s == 0: return D(-1) / 6
    x = dsqrt(s)
    return (sin_series(x) / x - 1) / s
smax2 = (PI / 2) ** 2
ps = cheb_fit(r_sin, D(0), smax2 * D('1.0001'), m)
print("sin R deg", m, "max abs err", check(r_sin, ps, D(0), smax2), "times s_max:", check(r_sin, ps, D(0), smax2) * smax2)
for v in ps: print("    %s," % format(float(v), '.17e'))
def dexp(x):
    s, t, k = D(1), D(1), 0
    while True:
        k += 1
        t = t * x / k
        if abs(t) < D(10) ** -58: break
        s += t
    return s
def g_exp(r):  # (e^r - 1 - r) / r^2 = sum r^k / (k + 2)!
    s, t, k = D(0), D(1) / 2, 0
    while abs(t) > D(10) ** -58:
        s += t
        k += 1
        t = t * r / (k + 2)
    return s
LN2 = D('0.693147180559945309417232121458176568075500134360255254120680')
half = LN2 / 2
for deg in (9,):
    pe = cheb_fit(g_exp, -half * D('1.0001'), half * D('1.0001'), deg)
    print("exp G deg", deg, "max abs err", check(g_exp, pe, -half, half) , "times r^2:", check(g_exp, pe, -half, half) * half * half)
    if True:
        for v in pe: print("    %s," % format(float(v), '.17e'))

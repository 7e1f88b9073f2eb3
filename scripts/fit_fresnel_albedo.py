#!/usr/bin/env python3
"""Fit the constants of the runtime's Fresnel curve (issue 19, step 4) and
check the bounds that rest on them. Prints every figure the comments in
runtime_shaders/substrate_bsdf.h and substrate_constants.h quote; writes
nothing. Pure Python 3 (no numpy), deterministic, about 30 s on 2 cores.

1. The curve. Every interface follows F = F0 + (F90 - F0) chi(c), chi the
   exact Fresnel of IOR 1.5 normalized, (F(c) - 0.04) / 0.96. The runtime's
   chi is t + D(t), t = (1 - c)^5 (Schlick's weight), D(t) = (1 - t) s (A + B s),
   s = sqrt(t): A and B by least squares on 4,001 cosines (SUBSTRATE_FRESNEL_CURVE_*).
2. G_k = 2 int mu (1 - chi(mu))^(1 + k) dmu (SUBSTRATE_COAT_G_*).
3. The albedo bound (substrate_fresnel_b): for a GGX lobe (the tables' lobe:
   height-correlated Smith, alpha = max(r^2, 1e-3)) integrated by visible
   normals at 41 roughnesses and 33 cosines, the share `pull` of a negative
   D(mean t) that e (t + D(t) - pull min(D, 0)) must give up to stay above the
   lobe's mean chi (SUBSTRATE_FRESNEL_ROUGH_K, _END), and how far above it the
   bound and Schlick's curve are.
4. Karis' fit of the interface albedo (substrate_interface_albedo_fit), its B
   part refitted to the chi-weighted albedo (cosine-weighted squared error,
   seeded random search from Karis' constants), and the quartic of its mean X
   (substrate_interface_albedo_means).
"""

import math
import multiprocessing
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gen_energy_lut as lut  # noqa: E402  (the tables' GGX lobe and sampling)


def fresnel_exact(c, eta=1.5):
    c = min(max(c, 0.0), 1.0)
    st2 = (1.0 - c * c) / (eta * eta)
    if st2 >= 1.0:
        return 1.0
    ct = math.sqrt(1.0 - st2)
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (ct - eta * c) / (ct + eta * c)
    return 0.5 * (rs * rs + rp * rp)


def chi_exact(c):
    return (fresnel_exact(c) - 0.04) / 0.96


def solve(a, b):
    n = len(b)
    m = [row[:] + [bb] for row, bb in zip(a, b)]
    for i in range(n):
        p = max(range(i, n), key=lambda k: abs(m[k][i]))
        m[i], m[p] = m[p], m[i]
        for k in range(n):
            if k != i:
                f = m[k][i] / m[i][i]
                for j in range(i, n + 1):
                    m[k][j] -= f * m[i][j]
    return [m[i][n] / m[i][i] for i in range(n)]


def least_squares(xs, ys, basis):
    a = [[sum(bi(x) * bj(x) for x in xs) for bj in basis] for bi in basis]
    b = [sum(y * bi(x) for x, y in zip(xs, ys)) for bi in basis]
    return solve(a, b)


# 1. The curve.
XS = [i / 4000 for i in range(4001)]
TS = [x ** 5 for x in XS]
DS = [chi_exact(1 - x) - t for x, t in zip(XS, TS)]
CURVE = least_squares(TS, DS, [lambda t: (1 - t) * math.sqrt(t), lambda t: (1 - t) * t])
CURVE = [round(c, 5) for c in CURVE]


def delta(t):
    s = math.sqrt(max(t, 0.0))
    return (1 - t) * s * (CURVE[0] + CURVE[1] * s)


def chi(c):
    x = 1 - min(max(c, 0.0), 1.0)
    t = x ** 5
    return t + delta(t)


# 3. The lobe's albedo weighted by chi.
MUS = [1.0, 0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6, 0.55, 0.5, 0.45, 0.4, 0.35, 0.3, 0.25, 0.2, 0.17,
       0.14, 0.12, 0.1, 0.08, 0.06, 0.05, 0.04, 0.03, 0.02, 0.015, 0.01, 0.005, 0.002, 0.001, 0.0001]
ROUGHNESSES = [i / 40 for i in range(41)]
PTS = lut.hammersley(2048)


def lobe_samples(mu, r):
    """(weight, VoH) of each of the tables' GGX lobe's visible-normal samples at
    (mu, r) that reflect above the horizon; a lobe's mean of f(VoH) is the sum
    of weight * f(VoH) over len(PTS)."""
    a = max(r * r, lut.GGX_MIN_ALPHA)
    a2 = a * a
    vx, vz = math.sqrt(max(0.0, 1 - mu * mu)), mu
    lam_v = lut.ggx_lambda(vz, a2)
    hx, hz = a * vx, vz
    hl = math.hypot(hx, hz)
    hx, hz = hx / hl, hz / hl
    s = 0.5 * (1 + hz)
    for u1, u2 in PTS:
        rr, phi = math.sqrt(u1), 2 * math.pi * u2
        t1, t2 = rr * math.cos(phi), rr * math.sin(phi)
        t2 = (1 - s) * math.sqrt(max(0.0, 1 - t1 * t1)) + s * t2
        tn = math.sqrt(max(0.0, 1 - t1 * t1 - t2 * t2))
        nx, ny, nz = -t2 * hz + tn * hx, t1, t2 * hx + tn * hz
        mx, my, mz = a * nx, a * ny, max(0.0, nz)
        ml = math.sqrt(mx * mx + my * my + mz * mz)
        if ml <= 0:
            continue
        mx, my, mz = mx / ml, my / ml, mz / ml
        voh = vx * mx + vz * mz
        if voh <= 0:
            continue
        lz = 2 * voh * mz - vz
        if lz <= 0:
            continue
        yield (1 + lam_v) / (1 + lam_v + lut.ggx_lambda(min(lz, 1.0), a2)), voh


def lobe(args):
    """(E, B, X) of the lobe: albedo with F = 1, its (1 - VoH)^5 and chi parts."""
    e = b = x = 0.0
    for w, voh in lobe_samples(*args):
        e += w
        b += w * (1 - voh) ** 5
        x += w * chi(voh)
    n = len(PTS)
    return e / n, b / n, x / n


def main():
    worst = max(abs(chi(1 - x) - chi_exact(1 - x)) for x in XS)
    print("1. curve: A %.5f B %.5f; within %.2e of exact Fresnel of IOR 1.5; at c 0.6: F %.4f, exact %.4f, "
          "Schlick %.4f" % (CURVE[0], CURVE[1], worst, 0.04 + 0.96 * chi(0.6), fresnel_exact(0.6),
                            0.04 + 0.96 * 0.4 ** 5))
    n = 200000
    gk = [sum(2 * ((i + 0.5) / n) * (1 - chi((i + 0.5) / n)) ** (1 + k) / n for i in range(n)) for k in range(4)]
    print("2. G_k: " + " / ".join("%.5f" % g for g in gk))

    grid = [(mu, r) for r in ROUGHNESSES for mu in MUS]
    with multiprocessing.Pool(2) as pool:
        lobes = dict(zip(grid, pool.map(lobe, grid)))
    need = {}
    for (mu, r), (e, b, x) in lobes.items():
        t, truth = b / e, x / e
        d = delta(t)
        if t + d < truth:
            need[r] = max(need.get(r, 0.0), (truth - t - d) / -d if d < 0 else float("inf"))
    k_max = max(need.values())
    r_worst = max(need, key=need.get)
    zero_from = min(r for r in ROUGHNESSES if all(need.get(q, 0.0) == 0.0 for q in ROUGHNESSES if q >= r))
    print("3. pull needed: at most %.3f (r %.3f), 0 from r %.3f" % (k_max, r_worst, zero_from))
    k, end = 0.43, 0.45
    over = schlick = 0.0
    for (mu, r), (e, b, x) in lobes.items():
        t = b / e
        d = delta(t)
        pull = k if r < end else 0.0
        bound = e * (t + d - pull * min(d, 0.0))
        assert bound >= x - 1e-12, (mu, r)
        over = max(over, 0.96 * (bound - x))
        schlick = max(schlick, 0.96 * abs(b - x))
    print("   with pull %.2f below r %.2f: the bound holds at all %d points, at most %.4f above in the albedo of "
          "F0 0.04 (Schlick's curve: %.4f either way)" % (k, end, len(lobes), over, schlick))

    # 4. Karis' fit, B refitted to the chi part.
    pts = [(mu, r, lobes[(mu, r)][2]) for (mu, r) in grid if mu >= 0.005]

    def b_fit(p, mu, r):
        kk, s, c0y, c1y = p
        cx = 1 - r
        a = min(cx * cx, 2 ** (-kk * mu)) * cx + c0y + r * c1y
        return s * a - 0.04 + 0.022 * r

    def loss(p):
        return sum(mu * (b_fit(p, mu, r) - x) ** 2 for mu, r, x in pts) / len(pts)

    best = [9.28, 1.04, 0.0425, -0.0275]
    start, best_loss = loss(best), loss(best)
    step = [0.5, 0.05, 0.01, 0.01]
    rng = random.Random(1)
    for it in range(3000):
        cand = [v + rng.gauss(0, s) for v, s in zip(best, step)]
        lc = loss(cand)
        if lc < best_loss:
            best, best_loss = cand, lc
        if it % 500 == 499:
            step = [s * 0.6 for s in step]
    best = [round(best[0], 3), round(best[1], 4), round(best[2], 5), round(best[3], 5)]
    print("4. Karis' B: exponent %.3f, scale %.4f, c.y %.5f %+.5f r; squared error %.1e -> %.1e"
          % (best[0], best[1], best[2], best[3], start, loss(best)))

    def a_part(mu, r):
        kk, s, c0y, c1y = best
        cx = 1 - r
        a = min(cx * cx, 2 ** (-kk * mu)) * cx + c0y + r * c1y
        return -s * a + 1.04 - 0.572 * r

    m = 4096
    rs = [i / 256 for i in range(257)]
    xs = [sum(2 * ((i + 0.5) / m) * a_part((i + 0.5) / m, r) / m for i in range(m)) for r in rs]
    quartic = least_squares(rs, xs, [lambda r, p=p: r ** p for p in range(5)])
    resid = max(abs(sum(c * r ** p for p, c in enumerate(quartic)) - x) for r, x in zip(rs, xs))
    print("   its mean X: quartic " + " ".join("%.9f" % c for c in quartic) + "; within %.1e of the midpoint rule"
          % resid)


if __name__ == "__main__":
    main()

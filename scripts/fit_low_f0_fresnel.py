#!/usr/bin/env python3
"""Fit the runtime's Fresnel curve of a low-F0 dielectric (issue 19, step 24)
and check the lobe albedo bound that reads it. Prints the figures that
runtime_shaders/substrate_bsdf.h and substrate_constants.h quote; writes
nothing. Pure Python 3, deterministic, about a minute on 2 cores.

1. The curve. The ground truth reads a dielectric's IOR from its F0, eta =
   (1 + sqrt F0) / (1 - sqrt F0), and walks its exact Fresnel. The runtime's
   dielectric curve is chi = t + (1 - t) s (A + B s), s = sqrt(t), t = (1 - c)^5,
   IOR 1.5's (F0 0.04) normalized (scripts/fit_fresnel_albedo.py). A lower
   IOR's normalized Fresnel rises later toward grazing; the same form follows
   it with coefficients in x = sqrt(max(F0, MIN_F0)):

       a = A + (x - 0.2) (p0 + p1 x + p2 x^2),  b = B + (x - 0.2) (q0 + q1 x + q2 x^2),

   exactly chi at F0 0.04 (x 0.2); from 0.04 on the runtime keeps chi, which is
   within 0.008 of the exact curve up to F0 0.1. The six coefficients are
   least squares on the reflectance F (the curve's error times 1 - F0) over F0
   MIN_F0 ... 0.04 and 801 cosines (SUBSTRATE_DIELECTRIC_CURVE_P*, _Q*). Step
   17 (reverted for its cost) followed the same curves as chi^p: a power per
   channel and light, where this is two multiply-adds.
2. The albedo bound. substrate_fresnel_b bounds a lobe's mean of w by
   e (t + D(t) - pull min(D(t), 0)) at the lobe's mean t = B / e, per channel;
   pull is 0.43 below roughness 0.45 and 0 from there for chi (fitted by
   fit_fresnel_albedo.py). A low-F0 curve is more convex in t than chi, and
   with pull 0 a rough lobe's mean of it lies above the bound (by 0.057 in the
   albedo at F0 0.001, r 0.45). Its pull is at least
   min(LOW_PULL_MAX, LOW_PULL_SLOPE (0.2 - x)) (SUBSTRATE_DIELECTRIC_CURVE_PULL_*:
   0 at chi's F0, so chi's bound is unchanged). Checked here at the tables' GGX
   lobe (fit_fresnel_albedo.py's) for 41 roughnesses x 33 cosines and the
   curves of 13 F0 from MIN_F0 to 0.04: the largest amount by which the lobe's
   mean exceeds the bound, in the albedo, with the pull and without it.
"""

import math
import multiprocessing
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_fresnel_albedo as fa  # noqa: E402  (the curve chi, the tables' lobe, solve)

A, B = fa.CURVE  # SUBSTRATE_FRESNEL_CURVE_A, _B
X_CHI = 0.2  # sqrt(0.04): chi's own F0
MIN_F0 = 0.001  # SUBSTRATE_DIELECTRIC_CURVE_MIN_F0
DEGREE = 3  # per coefficient: chi's constant plus (x - 0.2) times a quadratic
PULL_K, PULL_END = 0.43, 0.45  # SUBSTRATE_FRESNEL_ROUGH_K, _END
SLACK = 2e-4  # the energy tables' own margin (gen_energy_lut.py)
COSINES = [(i + 0.5) / 801 for i in range(801)]
FIT_F0S = [MIN_F0 + (0.04 - MIN_F0) * (i / 59) ** 2 for i in range(60)]  # denser at low F0
CHECK_F0S = [MIN_F0, 0.0015, 0.002, 0.003, 0.005, 0.0075, 0.01, 0.015, 0.02, 0.025, 0.03, 0.035, 0.04]
LOW_PULL_MAX, LOW_PULL_SLOPE = 0.32, 6.5  # SUBSTRATE_DIELECTRIC_CURVE_PULL_MAX, _SLOPE


def exact(f0, c):
    r = math.sqrt(f0)
    return fa.fresnel_exact(c, (1 + r) / (1 - r)) if r > 0 else 0.0


def variable(f0):
    return math.sqrt(min(max(f0, MIN_F0), X_CHI * X_CHI))


def coefficients(coef, f0):
    x = variable(f0)
    n = DEGREE
    pa = sum(coef[i] * x ** i for i in range(n))
    pb = sum(coef[n + i] * x ** i for i in range(n))
    return A + (x - X_CHI) * pa, B + (x - X_CHI) * pb


def curve(t, a, b):
    s = math.sqrt(t)
    return t + (1 - t) * s * (a + b * s)


def fit():
    n = 2 * DEGREE
    ata = [[0.0] * n for _ in range(n)]
    atb = [0.0] * n
    for f0 in FIT_F0S:
        weight = 1 - f0
        x = variable(f0)
        for c in COSINES:
            t = (1 - c) ** 5
            s = math.sqrt(t)
            u, v = (1 - t) * s, (1 - t) * t
            y = (exact(f0, c) - f0) - weight * curve(t, A, B)
            row = [weight * u * (x - X_CHI) * x ** i for i in range(DEGREE)] + \
                  [weight * v * (x - X_CHI) * x ** i for i in range(DEGREE)]
            for i in range(n):
                atb[i] += row[i] * y
                for j in range(n):
                    ata[i][j] += row[i] * row[j]
    return fa.solve(ata, atb)


def report_curve(coef):
    print("1. coefficients p0 p1 p2, q0 q1 q2:", " ".join("%.5f" % c for c in coef))
    print("   largest |F - exact| over 4,001 cosines (the fit / chi), lowest w, largest w - chi:")
    for f0 in [0.0, 5e-4] + CHECK_F0S + [0.07, 0.1]:
        a, b = coefficients(coef, f0)
        e_fit = e_chi = 0.0
        low, above = 1.0, -1.0
        prev = -1.0
        monotone = True
        for i in range(4001):
            c = 1 - i / 4000
            t = (1 - c) ** 5
            w = curve(t, a, b)
            chi = curve(t, A, B)
            ex = exact(f0, c)
            e_fit = max(e_fit, abs(f0 + (1 - f0) * w - ex))
            e_chi = max(e_chi, abs(f0 + (1 - f0) * chi - ex))
            low = min(low, w)
            above = max(above, w - chi)
            monotone = monotone and w >= prev - 1e-12
            prev = w
        print("   F0 %.4f: a %.4f b %.4f: %.4f / %.4f; lowest w %.2e; w - chi at most %.2e; %s"
              % (f0, a, b, e_fit, e_chi, low, above, "rises with t" if monotone else "NOT MONOTONE"))


def lobe(args):
    mu, r, curves = args
    e = b = 0.0
    xs = [0.0] * len(curves)
    for w, voh in fa.lobe_samples(mu, r):
        e += w
        t = (1 - voh) ** 5
        b += w * t
        for i, (ca, cb) in enumerate(curves):
            xs[i] += w * curve(t, ca, cb)
    n = len(fa.PTS)
    return e / n, b / n, [x / n for x in xs]


def low_pull(f0):
    return min(LOW_PULL_MAX, LOW_PULL_SLOPE * (X_CHI - variable(f0)))


def bound(e, b, r, ca, cb, low):
    t = min(b / e, 1.0)
    s = math.sqrt(t)
    d = (1 - t) * s * (ca + cb * s)
    pull = max(PULL_K if r < PULL_END else 0.0, low)
    return e * (t + d - pull * min(d, 0.0))


def main():
    coef = fit()
    report_curve(coef)
    curves = [coefficients(coef, f0) for f0 in CHECK_F0S]
    grid = [(mu, r, curves) for r in fa.ROUGHNESSES for mu in fa.MUS]
    with multiprocessing.Pool(2) as pool:
        lobes = pool.map(lobe, grid)
    worst, without, above = {}, {}, {}
    for (mu, r, _), (e, b, xs) in zip(grid, lobes):
        for f0, (ca, cb), x in zip(CHECK_F0S, curves, xs):
            under = (1 - f0) * (x - bound(e, b, r, ca, cb, low_pull(f0)))
            if under > worst.get(f0, (-1.0,))[0]:
                worst[f0] = (under, mu, r)
            without[f0] = max(without.get(f0, -1.0), (1 - f0) * (x - bound(e, b, r, ca, cb, 0.0)))
            if mu >= 0.2:
                above[f0] = max(above.get(f0, -1.0), -under)
    print("2. the albedo bound at %d lobes: the largest (lobe - bound) in the albedo, per F0 (where), without "
          "the low curve's pull, and the bound's largest excess for NoV >= 0.2:" % len(grid))
    fails = 0
    for f0 in CHECK_F0S:
        u, mu, r = worst[f0]
        fails += u > SLACK
        print("   F0 %.4f (pull %.3f): %+.5f at NoV %.4f, r %.3f%s; without: %+.5f; excess %.4f"
              % (f0, low_pull(f0), u, mu, r, "" if u <= SLACK else "  (ABOVE THE SLACK)", without[f0], above[f0]))
    print("   the bound holds at every lobe and F0" if not fails else "   THE BOUND FAILS at %d F0" % fails)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Fit the exponent of a low-F0 interface's Fresnel curve (issue 19, step 17)
and the share of it that a lobe's albedo bound may take. Step 17 was tried and
reverted for its cost (docs/accuracy.md, "17. A low-F0 interface follows the
Fresnel of its own IOR (tried, reverted)"; commit 80ca3cc holds the runtime
that used these constants; the SUBSTRATE_* and substrate_* names below are
its); the script keeps the fit for the next attempt.
Writes nothing. Pure Python 3, deterministic, about a minute on 2 cores.

1. The curve. The ground truth reads a dielectric's IOR from its F0, eta =
   (1 + sqrt F0) / (1 - sqrt F0), and walks its exact Fresnel; the runtime's
   curve is chi, IOR 1.5's (F0 0.04) normalized (scripts/fit_fresnel_albedo.py).
   A lower IOR's normalized Fresnel, (F_eta(c) - F0) / (1 - F0), is close to
   chi(c)^p: the best p per F0 (least largest error over 2,001 cosines), and
   the largest error of p = 1 + max(0.04 / sqrt(F0) - 0.2, 0)
   (SUBSTRATE_FRESNEL_IOR_K, _F0_SQRT), against chi's own.
2. The albedo. The tables bound the mean of chi over a lobe by u = t + x
   (substrate_fresnel_b's bound; substrate_fresnel_parts in 80ca3cc); the mean of chi^p exceeds u^p where the lobe
   spreads its half vectors (Jensen's inequality, x^p convex). The bound takes
   u^q, q = 1 + kappa (min(p, P_MAX) - 1) (w^p <= w^P_MAX where p > P_MAX,
   so the cap keeps it a bound; without it the steep curves of F0 near 0
   would take kappa down to 0.13): for the GGX lobe of the tables (as
   fit_fresnel_albedo.py integrates it) at 41 roughnesses, 33 cosines and the
   curves of 10 F0 from 0 to 0.03, the largest kappa(r) that keeps
   e u^q at or above the lobe's mean of chi^p (u from the exact e and B, with
   the runtime's pull; within 2e-4 of the lobe in the albedo, the tables' own
   margin), and the line kappa = max(K0 - S r, KMIN) under it
   (SUBSTRATE_FRESNEL_IOR_SPREAD_0, _SLOPE, _MIN). Even a smooth lobe needs
   kappa < 1: at grazing views its half vectors spread as much as the angle.
"""

import math
import multiprocessing
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_fresnel_albedo as fa  # noqa: E402  (the curve chi and the tables' lobe)

K, F0_SQRT = 0.04, 0.2  # SUBSTRATE_FRESNEL_IOR_K, SUBSTRATE_FRESNEL_IOR_F0_SQRT
P_MAX = 3.0  # SUBSTRATE_FRESNEL_IOR_BOUND_P_MAX: the albedo bound's exponent at most (F0 3.3e-4)
PULL_K, PULL_END = 0.43, 0.45  # SUBSTRATE_FRESNEL_ROUGH_K, _END
F0S = [0.0, 1e-4, 5e-4, 0.001, 0.002, 0.005, 0.01, 0.015, 0.02, 0.03]
SLACK = 2e-4  # the energy tables' own margin (gen_energy_lut.py)


def exponent(f0):
    return 1 + max(K / math.sqrt(max(f0, 1e-6)) - K / F0_SQRT, 0.0)


def bound_exponent(f0):
    """The exponent the albedo bound reads: a steeper curve's mean is below this one's."""
    return min(exponent(f0), P_MAX)


def chi_of_ior(c, f0):
    r = math.sqrt(f0)
    eta = (1 + r) / (1 - r)
    return (fa.fresnel_exact(c, eta) - f0) / (1 - f0)


def curve_fit():
    cs = [i / 2000 for i in range(2001)]
    chis = [fa.chi(c) for c in cs]
    print("1. curve chi^p against the exact Fresnel of the IOR of F0 (largest error over %d cosines):" % len(cs))
    for f0 in F0S + [0.04]:
        target = [chi_of_ior(c, f0) for c in cs]

        def err(p):
            return max(abs(x ** p - y) for x, y in zip(chis, target))

        best = min((err(1 + i / 200), 1 + i / 200) for i in range(0, 600))
        p = exponent(f0)
        print("   F0 %.4f: best p %.3f (error %.4f); p = %.3f: error %.4f; chi itself: %.4f"
              % (f0, best[1], best[0], p, err(p), err(1.0)))


def lobe(args):
    """(e, B, [mean chi^p for p of each F0]) of the tables' GGX lobe at (mu, r)."""
    ps = [exponent(f0) for f0 in F0S]
    e = b = 0.0
    xs = [0.0] * len(ps)
    for w, voh in fa.lobe_samples(*args):
        e += w
        b += w * (1 - voh) ** 5
        c = fa.chi(voh)
        for i, p in enumerate(ps):
            xs[i] += w * c ** p
    n = len(fa.PTS)
    return e / n, b / n, [x / n for x in xs]


def main():
    curve_fit()
    grid = [(mu, r) for r in fa.ROUGHNESSES for mu in fa.MUS]
    with multiprocessing.Pool(2) as pool:
        lobes = dict(zip(grid, pool.map(lobe, grid)))
    def bound(e, b, r, kappa, f0):
        t = b / e
        d = fa.delta(t)
        u = min(t + d - (PULL_K if r < PULL_END else 0.0) * min(d, 0.0), 1.0)
        return e * u ** (1 + kappa * (bound_exponent(f0) - 1))

    def holds(r, kappa):
        return all((1 - f0) * (bound(e, b, r, kappa, f0) - x) >= -SLACK
                   for mu in fa.MUS for (e, b, xs) in [lobes[(mu, r)]] for f0, x in zip(F0S, xs))

    need = {}  # r -> the largest kappa that holds at every mu and F0
    for r in fa.ROUGHNESSES:
        lo, hi = 0.0, 1.0
        if holds(r, 1.0):
            lo = 1.0
        for _ in range(30):
            if lo == 1.0:
                break
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if holds(r, mid) else (lo, mid)
        need[r] = lo
    print("2. the largest kappa per roughness (within %.0e of the lobe in the albedo):" % SLACK)
    print("   " + " ".join("%.3f:%.3f" % (r, need[r]) for r in fa.ROUGHNESSES))
    start = math.floor(need[0.0] * 100) / 100
    floor = math.floor(min(need.values()) * 100) / 100
    slope = math.ceil(100 * max((start - need[r]) / r for r in fa.ROUGHNESSES if r > 0 and need[r] > floor)) / 100
    print("   kappa = max(%.2f - %.2f r, %.2f) is at or under it at every roughness "
          "(SUBSTRATE_FRESNEL_IOR_SPREAD_0, _SLOPE, _MIN)" % (start, slope, floor))
    worst, before = {}, {}
    for (mu, r), (e, b, xs) in lobes.items():
        kappa = max(start - slope * r, floor)
        band = "NoV >= 0.2" if mu >= 0.2 else "NoV < 0.2"
        for f0, x in zip(F0S, xs):
            over = (1 - f0) * (bound(e, b, r, kappa, f0) - x)
            assert over >= -SLACK - 1e-12, (mu, r, f0)
            worst[band] = max(worst.get(band, 0.0), over)
            before[band] = max(before.get(band, 0.0), (1 - f0) * (bound(e, b, r, 0.0, f0) - x))
    print("   the bound holds at all %d points x %d F0; at most above the lobe in the albedo: %s"
          % (len(lobes), len(F0S), "; ".join("%s %.4f (chi's own bound: %.4f)" % (k, worst[k], before[k])
                                             for k in sorted(worst))))


if __name__ == "__main__":
    main()

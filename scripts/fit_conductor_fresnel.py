#!/usr/bin/env python3
"""Fit the runtime's conductor Fresnel curve (issue 19, step 23) and print the
figures that runtime_shaders/substrate_bsdf.h and substrate_constants.h quote.
Writes nothing. Pure Python 3 (no numpy), deterministic, a few seconds.

The ground truth walks a conductor of normal reflectance F0 as Gulbrandsen
2014's complex IOR (n, k) with the edge tint g = 1 - (1 - F0)^2.75
(compiler/tools/reference: conductorIor, edgeTint, fresnelConductor; F90 1).
Its normalized curve w(c) = (F(c) - F0) / (1 - F0) depends on F0: at F0 0.14
it lies up to 0.04 above Schlick's t = (1 - c)^5, at 0.9 on it. The runtime's
dielectric curve (step 4) is t + (1 - t) s (A + B s), s = sqrt(t); the same
form with coefficients in F0,

    a(F0) = a0 + a1 x + a2 x^2 + a3 x^3,  x = sqrt(max(F0, 0.02)),  b(F0) likewise,

follows the conductor's, per channel. The eight coefficients are fitted by
least squares on the reflectance F itself (the curve's error times 1 - F0)
over F0 0.02 ... 1 (99 values) and 801 cosines: SUBSTRATE_CONDUCTOR_CURVE_A*,
_B*. Below F0 0.02 (SUBSTRATE_CONDUCTOR_CURVE_MIN_F0) a channel takes the
curve of 0.02: the form's t term cannot follow a curve that stays near 0 up
to grazing (docs/accuracy.md, step 17), and the cubic's a0 < 0 would take the
curve below 0 near F0 0.
"""

import cmath
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fit_fresnel_albedo import solve  # noqa: E402  (Gauss-Jordan, partial pivoting)

CURVE_A, CURVE_B = 0.18317, -0.39315  # SUBSTRATE_FRESNEL_CURVE_A, _B (chi)
DEGREE = 3
MIN_F0 = 0.02  # SUBSTRATE_CONDUCTOR_CURVE_MIN_F0


def conductor_ior(r, g):
    r = min(max(r, 0.0), 0.9999)
    g = min(max(g, 0.0), 0.9999)
    sr = math.sqrt(r)
    n = g * (1 - r) / (1 + r) + (1 - g) * (1 + sr) / (1 - sr)
    k = math.sqrt(max(0.0, (r * (n + 1) ** 2 - (n - 1) ** 2) / (1 - r)))
    return n, k


def fresnel_conductor(c, n, k):
    c = min(max(c, 0.0), 1.0)
    eta = complex(n, k)
    ct = cmath.sqrt(1 - (1 - c * c) / (eta * eta))
    if eta * c + ct == 0 or c + eta * ct == 0:
        return 1.0  # as the reference's fresnelConductor
    rpa = abs((eta * c - ct) / (eta * c + ct)) ** 2
    rpe = abs((c - eta * ct) / (c + eta * ct)) ** 2
    return min(max(0.5 * (rpa + rpe), 0.0), 1.0)


def truth(f0, c):
    """The ground truth's conductor of F0 f0 and F90 1 at cosine c."""
    n, k = conductor_ior(f0, 1 - (1 - f0) ** 2.75)
    return fresnel_conductor(c, n, k)


def basis(t):
    s = math.sqrt(t)
    return (1 - t) * s, (1 - t) * s * s


def variable(f0):
    return math.sqrt(max(f0, MIN_F0))


def coefficients(coef, f0):
    p = [variable(f0) ** i for i in range(DEGREE + 1)]
    n = DEGREE + 1
    # a >= 0 (the runtime's max): with a < 0 (F0 above 0.7) D is convex in t
    # near 0, its mean over a lobe above D(mean t), and substrate_fresnel_b
    # would no longer bound the lobe's albedo from above.
    return max(sum(c * q for c, q in zip(coef[:n], p)), 0.0), sum(c * q for c, q in zip(coef[n:], p))


def curve(t, a, b):
    u, v = basis(t)
    return t + a * u + b * v


F0S = [MIN_F0 + (1 - MIN_F0) * i / 98 for i in range(99)]
COSINES = [(i + 0.5) / 801 for i in range(801)]


def fit():
    n = 2 * (DEGREE + 1)
    ata = [[0.0] * n for _ in range(n)]
    atb = [0.0] * n
    for f0 in F0S:
        weight = 1 - f0
        for c in COSINES:
            t = (1 - c) ** 5
            y = (truth(f0, c) - f0) - weight * t
            u, v = basis(t)
            x = variable(f0)
            row = [weight * u * x ** i for i in range(DEGREE + 1)] + [weight * v * x ** i for i in range(DEGREE + 1)]
            for i in range(n):
                atb[i] += row[i] * y
                for j in range(n):
                    ata[i][j] += row[i] * row[j]
    return solve(ata, atb)


def report(coef):
    print("coefficients a0..a3, b0..b3:", " ".join(f"{c:.5f}" for c in coef))
    print("largest |F - truth| over the cosines, per F0 (the fit / chi / Schlick's):")
    worst = [0.0, 0.0, 0.0]
    for f0 in [0.005, 0.01, 0.02, 0.04, 0.07, 0.1, 0.12, 0.14, 0.17, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0]:
        a, b = coefficients(coef, f0)
        e = [0.0, 0.0, 0.0]
        low = [0.0, 0.0, 0.0]
        for i in range(4001):
            c = i / 4000
            t = (1 - c) ** 5
            f = truth(f0, c)
            for j, w in enumerate((curve(t, a, b), curve(t, CURVE_A, CURVE_B), t)):
                assert 0 <= f0 + (1 - f0) * w <= 1, (f0, c, w)
                low[j] = min(low[j], w)
                e[j] = max(e[j], abs(f0 + (1 - f0) * w - f))
        if f0 >= MIN_F0:
            worst = [max(x, y) for x, y in zip(worst, e)]
        print(f"  F0 {f0:.3f}: a {a:+.4f} b {b:+.4f}  {e[0]:.4f} / {e[1]:.4f} / {e[2]:.4f}, lowest w {low[0]:.1e}")
    print(f"  from F0 {MIN_F0}: {worst[0]:.4f} / {worst[1]:.4f} / {worst[2]:.4f}")
    lowest, highest = 1.0, 0.0
    for i in range(1001):
        a, b = coefficients(coef, i / 1000)
        for j in range(2001):
            w = curve(((2000 - j) / 2000) ** 5, a, b)
            lowest, highest = min(lowest, w), max(highest, w)
    print(f"the fitted curve over F0 0 ... 1 (1,001) and 2,001 cosines: w in [{lowest:.2e}, {highest:.6f}]")
    print("relative error at cosines 0.8 / 0.6 / 0.4 / 0.2 / 0.1 (%), the fit | Schlick's:")
    for f0 in [0.14, 0.2, 0.3, 0.5]:
        a, b = coefficients(coef, f0)
        fit_e, sch_e = [], []
        for c in [0.8, 0.6, 0.4, 0.2, 0.1]:
            t = (1 - c) ** 5
            f = truth(f0, c)
            fit_e.append(100 * ((f0 + (1 - f0) * curve(t, a, b)) / f - 1))
            sch_e.append(100 * ((f0 + (1 - f0) * t) / f - 1))
        print(f"  F0 {f0:.2f}: " + " ".join(f"{x:+.1f}" for x in fit_e) + " | " + " ".join(f"{x:+.1f}" for x in sch_e))


if __name__ == "__main__":
    report(fit())

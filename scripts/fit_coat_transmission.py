#!/usr/bin/env python3
"""Fit and check the constants of the layers' interface term under a rough top
(issue 19, step 9; substrate_coat_floor in runtime_shaders/substrate_closure.h,
substrate_coat_transmission and substrate_coat_mean_share in substrate_bsdf.h,
SUBSTRATE_COAT_ROUGH_* and SUBSTRATE_COAT_MEAN_* in substrate_constants.h).
Prints the fitted constants, checks the shipped ones and exits 1 if they break
a bound; writes nothing. Pure Python 3 (no numpy), deterministic, about 20 s.

The layers above a closure are read as one interface of IOR 1.5 whose angular
transmission is 1 - chi(mu) (chi: the runtime's Fresnel curve,
substrate_fresnel_weight). A rough top reflects less at grazing angles: what an
interface of F0 0 and F90 1 of roughness r does not reflect is 1 - b(mu, r),
b the chi-weighted part of the tables' albedo as the runtime computes it
(substrate_energy_dfg, substrate_fresnel_b at share 1), and no top of F0 0 ..
0.04 lets through less per unit of its T_N. The term shipped is

    g(mu) = max(1 - chi(mu), 1 - (1 - f) (1 - mu)^2),
    f(r)  = SCALE x / (x + HALF),  x = max(r - START, 0),

and the bound it must keep, at every mu and r, is g <= max(1 - chi, 1 - b).
For each r the largest f of that form is found; (START, HALF, SCALE) are then
the rational curve under those values that loses the least (a scan; the
shipped 0.1, 0.175, 1.094 came from a finer one and are checked here).

The diffuse under the layers is normalized by the cosine-weighted mean of
g^(1 + k) (k = extra interfaces, 0..3): G_k(f) = G_k + (1 - G_k) h(f) must bound
it from above, h(f) = sat(f (A + f (B + C f))): a least-squares quadratic in f
of the largest of the four shares, raised (its f term) until it bounds them.
"""

import math
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
RUNTIME = os.path.join(ROOT, "runtime_shaders")


def define(name):
    text = open(os.path.join(RUNTIME, "substrate_constants.h")).read()
    return float(re.search(r"#define %s ([-0-9.eE+]+)" % name, text).group(1))


CURVE_A = define("SUBSTRATE_FRESNEL_CURVE_A")
CURVE_B = define("SUBSTRATE_FRESNEL_CURVE_B")
ROUGH_K = define("SUBSTRATE_FRESNEL_ROUGH_K")
ROUGH_END = define("SUBSTRATE_FRESNEL_ROUGH_END")
G_K = [define("SUBSTRATE_COAT_G_%d" % k) for k in range(4)]


def lut_tables():
    text = open(os.path.join(RUNTIME, "substrate_energy_lut_data.h")).read()
    body = text[text.index("SUBSTRATE_LUT_TABLES[3072]"):]
    body = body[body.index("(float, 3072)") + len("(float, 3072)"):]
    body = re.sub(r"//[^\n]*", "", body)
    values = [float(x) for x in re.findall(r"[-+]?\d+\.\d+e[-+]\d+", body)[:2048]]
    return values[:1024], values[1024:2048]


E_TABLE, B_TABLE = lut_tables()


def lut(table, x, y):
    """substrate_lut_coords + substrate_lut_blend."""
    px = min(max(x, 0.0), 1.0) * 32 - 0.5
    py = min(max(y, 0.0), 1.0) * 32 - 0.5
    x0 = int(min(max(math.floor(px), 0), 30))
    y0 = int(min(max(math.floor(py), 0), 30))
    fx, fy = px - x0, py - y0
    i = y0 * 32 + x0
    a = table[i] + (table[i + 1] - table[i]) * fx
    b = table[i + 32] + (table[i + 33] - table[i + 32]) * fx
    return a + (b - a) * fy


def delta(t):
    s = math.sqrt(t)
    return (1 - t) * s * (CURVE_A + CURVE_B * s)


def chi(c):
    t = (1 - min(max(c, 0.0), 1.0)) ** 5
    return t + delta(t)


def b_part(mu, r):
    """substrate_fresnel_b(substrate_energy_dfg(mu, r), e, pull(r), 1).y."""
    e_raw = lut(E_TABLE, mu, r)
    b = min(max(lut(B_TABLE, mu, r), 0.0), 1.0)
    e = min(max(min(max(e_raw - b, 0.0), 1.0) + b, 1e-3), 1.0)
    pull = ROUGH_K if r < ROUGH_END else 0.0
    t = min(b / e, 1.0)
    d = delta(t)
    return e * (t + d - pull * min(d, 0.0))


MUS = [1e-4 + (0.05 - 1e-4) * i / 399 for i in range(400)] + [0.05 + 0.95 * i / 1599 for i in range(1, 1600)]
WEIGHTS = [2 * MUS[i] * ((MUS[min(i + 1, len(MUS) - 1)] - MUS[max(i - 1, 0)]) / 2) for i in range(len(MUS))]
SMOOTH = [1 - chi(m) for m in MUS]
ROUGHNESSES = [i / 100 for i in range(101)]


def bound(r):
    return [max(s, min(max(1 - b_part(m, r), 0.0), 1.0)) for s, m in zip(SMOOTH, MUS)]


def largest_floor(bnd):
    """The largest f with 1 - (1 - f)(1 - mu)^2 <= bnd at every mu."""
    return max(0.0, min(1 - (1 - g) / max((1 - m) ** 2, 1e-12) for g, m in zip(bnd, MUS)))


def floor_of(r, start, half, scale):
    x = max(r - start, 0.0)
    return scale * x / (x + half)


def term(mu_index, f):
    m = 1 - MUS[mu_index]
    return max(SMOOTH[mu_index], 1 - (1 - f) * m * m)


def shares(f):
    """(mean g^(1+k) - G_k) / (1 - G_k) for k = 0..3, the means on the grid."""
    out = []
    for k in range(4):
        mean = sum(w * term(i, f) ** (1 + k) for i, w in enumerate(WEIGHTS))
        smooth = sum(w * s ** (1 + k) for s, w in zip(SMOOTH, WEIGHTS))
        out.append((mean - smooth) / (1 - G_K[k]))  # the difference on one grid: its quadrature error cancels
    return max(out)


def main():
    bounds = {r: bound(r) for r in ROUGHNESSES}
    fmax = {r: largest_floor(bounds[r]) for r in ROUGHNESSES}
    best = None
    for start in [i / 200 for i in range(0, 31)]:
        for half in [0.05 + i / 200 for i in range(0, 111)]:
            scale = min(fmax[r] / (max(r - start, 0) / (max(r - start, 0) + half))
                        for r in ROUGHNESSES if r > start)
            loss = sum(fmax[r] - floor_of(r, start, half, scale) for r in ROUGHNESSES)
            if best is None or loss < best[0]:
                best = (loss, start, half, scale)
    _, start, half, scale = best
    print("floor f(r) = SCALE x / (x + HALF), x = max(r - START, 0): START %.3f HALF %.3f SCALE %.5f" %
          (start, half, scale))
    ok = True
    s_start, s_half, s_scale = (define("SUBSTRATE_COAT_ROUGH_START"), define("SUBSTRATE_COAT_ROUGH_HALF"),
                                define("SUBSTRATE_COAT_ROUGH_SCALE"))
    worst = max(term(i, floor_of(r, s_start, s_half, s_scale)) - bounds[r][i]
                for r in ROUGHNESSES for i in range(len(MUS)))
    print("shipped (%.3f, %.3f, %.4f): largest excess over max(1 - chi, 1 - b): %.2e" %
          (s_start, s_half, s_scale, worst))
    ok = ok and worst <= 1e-6
    for r in (0.2, 0.4, 0.6, 0.8, 1.0):
        f = floor_of(r, s_start, s_half, s_scale)
        gain = sum(w * (b - s) for w, b, s in zip(WEIGHTS, bounds[r], SMOOTH))
        got = sum(w * (term(i, f) - s) for i, (w, s) in enumerate(zip(WEIGHTS, SMOOTH)))
        print("  r %.1f: f %.4f (largest %.4f), takes %.0f %% of what 1 - b adds" %
              (r, f, fmax[r], 100 * got / max(gain, 1e-12)))

    # h(f): least squares in (f, f^2, f^3) over the shipped floors, then the f term raised.
    fs = [floor_of(r, s_start, s_half, s_scale) for r in ROUGHNESSES]
    hs = [shares(f) for f in fs]
    pts = [(f, h) for f, h in zip(fs, hs) if f > 0]
    cols = [[f ** (1 + j) for j in range(3)] for f, _ in pts]
    ata = [[sum(c[a] * c[b] for c in cols) for b in range(3)] for a in range(3)]
    aty = [sum(c[a] * h for c, (_, h) in zip(cols, pts)) for a in range(3)]
    coef = solve3(ata, aty)
    coef[0] += max(0.0, max((h - sum(coef[j] * f ** (1 + j) for j in range(3))) / f for f, h in pts))
    print("mean share h(f) = sat(f (A + f (B + C f))): A %.5f B %.5f C %.5f" % tuple(coef))
    a, b, c = define("SUBSTRATE_COAT_MEAN_A"), define("SUBSTRATE_COAT_MEAN_B"), define("SUBSTRATE_COAT_MEAN_C")
    gaps = [min(max(f * (a + f * (b + c * f)), 0.0), 1.0) - h for f, h in zip(fs, hs)]
    print("shipped (%.4f, %.4f, %.4f): below the share by at most %.2e, above it by at most %.4f" %
          (a, b, c, max(0.0, -min(gaps)), max(gaps)))
    ok = ok and min(gaps) >= -1e-6
    print("bounds hold" if ok else "A BOUND IS BROKEN")
    return 0 if ok else 1


def solve3(m, y):
    """Gaussian elimination for a 3 x 3 system."""
    m = [row[:] + [v] for row, v in zip(m, y)]
    for i in range(3):
        p = max(range(i, 3), key=lambda k: abs(m[k][i]))
        m[i], m[p] = m[p], m[i]
        for k in range(i + 1, 3):
            q = m[k][i] / m[i][i]
            m[k] = [a - q * b for a, b in zip(m[k], m[i])]
    x = [0.0] * 3
    for i in reversed(range(3)):
        x[i] = (m[i][3] - sum(m[i][j] * x[j] for j in range(i + 1, 3))) / m[i][i]
    return x


if __name__ == "__main__":
    sys.exit(main())

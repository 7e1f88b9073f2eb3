#!/usr/bin/env python3
"""Fit the constants of the trapped share of a conductor's lobe under a coat
(issue 19, step 6; substrate_closure_coat_specular in
runtime_shaders/substrate_bsdf.h, SUBSTRATE_COAT_TIR_* in substrate_constants.h).
Prints the constants and the fit's error; writes nothing. Pure Python 3 (no
numpy), deterministic, about 10 s on 2 cores.

Light that reaches a closure under a coat (read as a dielectric of IOR 1.5)
travels inside the coat at mu_i = sqrt(1 - (1 - NoV^2) / 2.25), never below
the critical cosine mu_c = sqrt(1 - 1 / 2.25) = 0.74536. A smooth lobe sends
it back at mu_i, inside the cone that leaves through the top; a rough GGX lobe
spreads it, and what it sends below mu_c is reflected back down by the coat's
top (total internal reflection) and meets the closure again. The share

    R(alpha, mu_i) = (lobe albedo toward mu_o < mu_c) / (lobe albedo)

(the tables' lobe: height-correlated Smith, visible-normal sampling, F = 1)
is fitted, by least squares over 33 view cosines and 21 roughnesses, as

    R ~ P1 a^2 / (a^2 + P2 d^2) + P3 a^2,   a = GGX alpha, d = mu_i - mu_c,

P1 and P3 linear for each P2 of a scan (then a finer one around the best).
"""

import math
import multiprocessing
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gen_energy_lut as lut  # noqa: E402  (the tables' GGX lobe and sampling)

ETA = 1.5
MU_C = math.sqrt(1.0 - 1.0 / (ETA * ETA))
SAMPLES = 8192
PTS = lut.hammersley(SAMPLES)
NOVS = [i / 32.0 for i in range(33)]
ROUGHNESSES = [j / 20.0 for j in range(21)]


def inner_cosine(nov):
    """The view's cosine once refracted into the coat."""
    return math.sqrt(1.0 - (1.0 - nov * nov) / (ETA * ETA))


def trapped(args):
    """R(alpha, mu): the lobe's albedo share sent below the critical cosine."""
    mu, r = args
    a = max(r * r, lut.GGX_MIN_ALPHA)
    a2 = a * a
    vx, vz = math.sqrt(max(0.0, 1 - mu * mu)), mu
    lam_v = lut.ggx_lambda(vz, a2)
    hx, hz = a * vx, vz
    hl = math.hypot(hx, hz)
    hx, hz = hx / hl, hz / hl
    s = 0.5 * (1 + hz)
    e = t = 0.0
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
        w = (1 + lam_v) / (1 + lam_v + lut.ggx_lambda(min(lz, 1.0), a2))
        e += w
        if lz < MU_C:
            t += w
    return t / e if e > 0 else 0.0


def model(p, a, d):
    p1, p2, p3 = p
    a2 = a * a
    return p1 * a2 / max(a2 + p2 * d * d, 1e-12) + p3 * a2


def fit_linear(p2, rows):
    """P1, P3 by least squares for a given P2; returns (sse, (p1, p2, p3))."""
    s11 = s13 = s33 = b1 = b3 = 0.0
    for a, d, y in rows:
        a2 = a * a
        x1 = a2 / max(a2 + p2 * d * d, 1e-12)
        x3 = a2
        s11 += x1 * x1
        s13 += x1 * x3
        s33 += x3 * x3
        b1 += x1 * y
        b3 += x3 * y
    det = s11 * s33 - s13 * s13
    p1 = (b1 * s33 - b3 * s13) / det
    p3 = (s11 * b3 - s13 * b1) / det
    p = (p1, p2, p3)
    sse = sum((model(p, a, d) - y) ** 2 for a, d, y in rows)
    return sse, p


def main():
    cells = [(inner_cosine(max(nov, 1e-4)), r) for nov in NOVS for r in ROUGHNESSES]
    with multiprocessing.Pool() as pool:
        values = pool.map(trapped, cells)
    rows = [(max(r * r, lut.GGX_MIN_ALPHA), mu - MU_C, y) for (mu, r), y in zip(cells, values)]
    best = min(fit_linear(0.05 * k, rows) for k in range(1, 200))
    lo = best[1][1]
    best = min(fit_linear(lo - 0.05 + 0.0005 * k, rows) for k in range(201))
    sse, p = best
    errs = [abs(model(p, a, d) - y) for a, d, y in rows]
    worst = max(range(len(rows)), key=lambda i: errs[i])
    print(f"critical cosine mu_c = {MU_C:.5f}")
    print(f"P1 = {p[0]:.4f}  P2 = {p[1]:.4f}  P3 = {p[2]:.4f}")
    print(f"rms error {math.sqrt(sse / len(rows)):.4f}, largest {errs[worst]:.4f} "
          f"(r {cells[worst][1]:.2f}, mu_i {cells[worst][0]:.4f}: {values[worst]:.4f})")
    for r in (0.25, 0.5, 0.75, 1.0):
        line = []
        for nov in (1.0, 0.6, 0.2, 0.0):
            mu = inner_cosine(max(nov, 1e-4))
            line.append(f"NoV {nov:.1f}: {trapped((mu, r)):.3f} / {model(p, max(r * r, lut.GGX_MIN_ALPHA), mu - MU_C):.3f}")
        print(f"r {r:.2f} (integral / fit)  " + "  ".join(line))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Fit the constants of the energy Chan 2024's diffuse lobe loses (issue 19,
step 7; substrate_diffuse_chan2024 in runtime_shaders/substrate_bsdf.h,
SUBSTRATE_CHAN24_MS_* in substrate_constants.h). Prints the constants and the
white directional albedo before and after; writes nothing. Pure Python 3 (no
numpy), deterministic, a few seconds.

Chan 2024 as UE ships it (r the roughness, a = r^2):

    f = 1/pi (1 - r + r FRough + 0.38 a),
    FRough = s(r) (NoH + b(r)) / (NoH + 0.025) VoH^2,
    s = max(0.55 - 0.2 r, 1.25 - 1.6 r),  b = sat(4 a).

With albedo 1 it returns less than 1: its directional albedo E(mu, r) falls
to 0.94. E splits into two integrals of the view cosine mu alone, because
(NoH + b) / (NoH + 0.025) = 1 + (b - 0.025) / (NoH + 0.025):

    K0(mu) = int VoH^2 cos / pi = 1/2 + mu/3          (VoH^2 = (1 + VoL) / 2)
    K1(mu) = int VoH^2 / (NoH + 0.025) cos / pi       (no closed form)
    1 - E(mu, r) = r h(mu, r),
    h = 1 - 0.38 r - s (K0(mu) + (b - 0.025) K1(mu)).

K1 is fitted as (P0 + P1 mu + P2 mu^2 + P3 mu^3) / (mu + C) over 81 cosines
dense at grazing, minimax for each C of a scan (Lawson's reweighted least
squares), then shifted up by its largest error so that it never lies below K1. The lost
energy is returned as a reciprocal multiple-scattering lobe (Kulla & Conty
2017's form, which EON uses too):

    f_ms = albedo / pi r max(h(mu_o), 0) max(h(mu_i), 0) / H(r),
    H = int h 2 mu dmu = 1 - 0.38 r - s (13/18 + (b - 0.025) M),
    M = int K1 2 mu dmu (of the fit),

whose directional albedo is exactly r h(mu_o) = 1 - E(mu_o) where h >= 0
(h < 0 only below NoV 0.04 at r > 0.42, where E already exceeds 1 and the
runtime divides it by a bound of that excess).

Then the lobe factors SUBSTRATE_COAT_LOBE_* of substrate_closure_coat_diffuse:
under layers the diffuse is normalized with G_k = 2 int mu g_k dmu, the
cosine-weighted mean of the light-side interface term g_k = (1 - chi)^(1 + k)
(chi the runtime's Fresnel curve, SUBSTRATE_FRESNEL_CURVE_*). A lobe f that
favours light near the normal takes more of it; the factor is the largest
over 11 roughnesses and 7 views of g_k(NoV) int f g_k cos / (G_k int f cos),
for Chan 2024 with its lobe (the constants just fitted) and for EON (its
roughness 0.4 r, albedo 1), rounded up.
"""

import math

QUAD = 200  # points per axis of the quadrature over the light hemisphere


def k_integrals(mu, n=QUAD):
    """(K0, K1) at view cosine mu: midpoint rule in mu_i^2 and the azimuth
    (the integrand is even in it), so each is a plain mean."""
    so = math.sqrt(max(0.0, 1.0 - mu * mu))
    k0 = k1 = 0.0
    for i in range(n):
        u = (i + 0.5) / n
        mi, si = math.sqrt(u), math.sqrt(1.0 - u)
        for j in range(n):
            phi = (j + 0.5) / n * math.pi
            hx, hy, hz = so + si * math.cos(phi), si * math.sin(phi), mu + mi
            inv = 1.0 / math.sqrt(hx * hx + hy * hy + hz * hz)
            noh, voh = hz * inv, (so * hx + mu * hz) * inv
            k0 += voh * voh
            k1 += voh * voh / (noh + 0.025)
    return k0 / (n * n), k1 / (n * n)


def solve(a, b):
    """Gauss-Jordan with partial pivoting."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                for k in range(c, n + 1):
                    m[r][k] -= f * m[c][k]
    return [m[i][n] / m[i][i] for i in range(n)]


def fit_rational(mus, ys, c, weights):
    """Weighted least-squares P0..P3 of (P0 + P1 mu + P2 mu^2 + P3 mu^3) / (mu + c)
    and the residuals (fit - data)."""
    basis = [[mu**k / (mu + c) for k in range(4)] for mu in mus]
    a = [[sum(w * row[i] * row[j] for w, row in zip(weights, basis)) for j in range(4)] for i in range(4)]
    b = [sum(w * row[i] * y for w, row, y in zip(weights, basis, ys)) for i in range(4)]
    p = solve(a, b)
    return p, [sum(pk * bk for pk, bk in zip(p, row)) - y for row, y in zip(basis, ys)]


def fit_minimax(mus, ys, c, iterations=60):
    """Lawson's algorithm: least squares reweighted by the residuals, which
    converges to the fit of smallest largest error."""
    weights = [1.0] * len(mus)
    for _ in range(iterations):
        p, res = fit_rational(mus, ys, c, weights)
        total = sum(w * abs(r) for w, r in zip(weights, res))
        weights = [max(w * abs(r) / total, 1e-12) for w, r in zip(weights, res)]
    return p, res


def k1_fit(mu, p, c):
    return (p[0] + mu * (p[1] + mu * (p[2] + mu * p[3]))) / (mu + c)


def scale_bias(r):
    return max(0.55 - 0.2 * r, 1.25 - 1.6 * r), min(1.0, 4.0 * r * r)


def h_of(mu, r, p, c):
    s, b = scale_bias(r)
    return 1.0 - 0.38 * r - s * (0.5 + mu / 3.0 + (b - 0.025) * k1_fit(mu, p, c))


def big_h(r, m):
    s, b = scale_bias(r)
    return 1.0 - 0.38 * r - s * (13.0 / 18.0 + (b - 0.025) * m)


def excess_bound(mu, r):
    """The runtime's divisor for the grazing excess, 1 + 0.026 sat(1 - 25 mu) sat(10 (r - 0.42))."""
    return 1.0 + 0.026 * min(1.0, max(0.0, 1.0 - 25.0 * mu)) * min(1.0, max(0.0, 10.0 * (r - 0.42)))


def chan_albedo(mu, r, k0, k1):
    """E(mu, r) from the two integrals, divided by the runtime's bound of the
    excess (1 + 0.026 sat(1 - 25 mu) sat(10 (r - 0.42)))."""
    s, b = scale_bias(r)
    e = 1.0 - r + r * s * (k0 + (b - 0.025) * k1) + 0.38 * r * r
    return e / excess_bound(mu, r)


def main():
    mus = [(i / 80.0) ** 2 for i in range(81)]
    ks = [k_integrals(mu) for mu in mus]
    k0_err = max(abs(k0 - (0.5 + mu / 3.0)) for mu, (k0, _) in zip(mus, ks))
    print(f"K0 = 1/2 + mu/3: largest quadrature difference {k0_err:.1e}")
    k1s = [k1 for _, k1 in ks]

    best = None
    for ci in range(150, 300, 2):
        c = ci / 1000.0
        p, res = fit_minimax(mus, k1s, c)
        err = max(abs(r) for r in res)
        if best is None or err < best[2]:
            best = (c, p, err, res)
    c, p, err, res = best
    # Shifted up by its largest shortfall, the fit never lies below K1: the
    # lobe then returns at most what Chan 2024 loses (h is decreasing in K1).
    shift = max(0.0, -min(res))
    p = [p[0] + shift * c, p[1] + shift, p[2], p[3]]
    print(f"K1 ~ (P0 + P1 mu + P2 mu^2 + P3 mu^3) / (mu + C): minimax error {err:.5f}, shifted up by {shift:.5f}")
    print(f"  C = {c:.3f}, P = " + ", ".join(f"{v:.6f}" for v in p))

    n = 20000
    m = sum(k1_fit((i + 0.5) / n, p, c) * 2 * (i + 0.5) / n for i in range(n)) / n
    print(f"  M = int K1 2 mu dmu = {m:.6f}")

    # The white directional albedo before and after, on a grid of views and
    # roughnesses (h is clamped at 0 on both sides, as in the runtime).
    views = [1.0, 0.8, 0.6, 0.4, 0.3, 0.2, 0.1, 0.05, 0.02, 0.005, 1e-4]
    table = {mu: k_integrals(mu, 120) for mu in views}
    lo_before, lo_after, hi_after, lo_view = (2.0, None), (2.0, None), (0.0, None), (2.0, None)
    for j in range(21):
        r = j / 20.0
        hh = big_h(r, m)
        pos = sum(max(h_of((i + 0.5) / n, r, p, c), 0.0) * 2 * (i + 0.5) / n for i in range(n)) / n
        for mu in views:
            e = chan_albedo(mu, r, *table[mu])
            after = e + (r * max(h_of(mu, r, p, c), 0.0) * pos / max(hh, 1e-4) if r > 0 else 0.0)
            lo_before = min(lo_before, (e, (mu, r)))
            lo_after = min(lo_after, (after, (mu, r)))
            hi_after = max(hi_after, (after, (mu, r)))
            if mu >= 0.05:
                lo_view = min(lo_view, (after, (mu, r)))
    print(f"white directional albedo, NoV {views[0]}..{views[-1]} x r 0..1 (21):")
    print(f"  before: lowest {lo_before[0]:.4f} at (NoV, r) = {lo_before[1]}")
    print(f"  after:  lowest {lo_after[0]:.4f} at {lo_after[1]}, highest {hi_after[0]:.4f} at {hi_after[1]}")
    print(f"  after, NoV >= 0.05: lowest {lo_view[0]:.4f} at {lo_view[1]} (below, the bound of the excess divides)")
    print(f"  H(r) lowest {min(big_h(j / 100.0, m) for j in range(101)):.4f}")
    print_lobe_factors(p, c, m)


CURVE_A, CURVE_B = 0.18317, -0.39315  # SUBSTRATE_FRESNEL_CURVE_A, _B


def interface_term(mu, k):
    """g_k = (1 - chi(mu))^(1 + k), chi the runtime's Fresnel curve."""
    t = (1.0 - mu) ** 5
    s = math.sqrt(t)
    return (1.0 - (t + (1.0 - t) * s * (CURVE_A + CURVE_B * s))) ** (1 + k)


def chan_lobe(r, mo, mi, phi, p, c, m):
    """Chan 2024 (times pi, albedo 1), the bound of its excess and its lobe."""
    so, si = math.sqrt(max(0.0, 1 - mo * mo)), math.sqrt(max(0.0, 1 - mi * mi))
    hx, hy, hz = so + si * math.cos(phi), si * math.sin(phi), mo + mi
    inv = 1.0 / math.sqrt(hx * hx + hy * hy + hz * hz)
    noh, voh = hz * inv, (so * hx + mo * hz) * inv
    s, b = scale_bias(r)
    f = 1.0 - r + r * s * (noh + b) / (noh + 0.025) * voh * voh + 0.38 * r * r
    f /= excess_bound(mo, r)
    if r > 0:
        f += r * max(h_of(mo, r, p, c), 0.0) * max(h_of(mi, r, p, c), 0.0) / max(big_h(r, m), 1e-4)
    return f


def eon_albedo(mu, r):
    x = 1.0 - mu
    return (1 + r * x * (0.0571085289 + x * (0.491881867 + x * (-0.332181442 + x * 0.0714429953)))) / (
        1 + 0.287793409 * r)


def eon_lobe(r, mo, mi, phi):
    """EON (times pi) at albedo 1 with the runtime's roughness 0.4 r."""
    r *= 0.4
    so, si = math.sqrt(max(0.0, 1 - mo * mo)), math.sqrt(max(0.0, 1 - mi * mi))
    s = so * si * math.cos(phi)
    s_over_t = s / max(mo, mi, 1e-6) if s > 0 else s
    af = 1.0 / (1.0 + 0.287793409 * r)
    e_avg = af * (1.0 + 0.0724882125 * r)
    ms = max(1e-7, 1 - eon_albedo(mo, r)) * max(1e-7, 1 - eon_albedo(mi, r)) / max(1e-7, 1 - e_avg)
    return af * (1.0 + r * s_over_t) + ms  # rho = 1, rho_ms = 1


def lobe_factor(lobe, k, n=64):
    """The largest g_k(NoV) int f g_k cos / (G_k int f cos) over the grid."""
    g_mean = sum(2 * ((i + 0.5) / 4000) * interface_term((i + 0.5) / 4000, k) for i in range(4000)) / 4000
    worst = 0.0
    for j in range(11):
        r = j / 10.0
        for mo in (1.0, 0.95, 0.9, 0.8, 0.6, 0.4, 0.2):
            num = den = 0.0
            for i in range(n):
                mi = math.sqrt((i + 0.5) / n)
                g = interface_term(mi, k)
                for q in range(n):
                    f = lobe(r, mo, mi, (q + 0.5) / n * math.pi)
                    num += f * g
                    den += f
            worst = max(worst, interface_term(mo, k) * num / (den * g_mean))
    return worst


def print_lobe_factors(p, c, m):
    for name, lobe in (("CHAN2024", lambda r, mo, mi, phi: chan_lobe(r, mo, mi, phi, p, c, m)), ("EON", eon_lobe)):
        factors = [lobe_factor(lobe, k) for k in range(4)]
        print(f"SUBSTRATE_COAT_LOBE_{name}_0..3: " + ", ".join(f"{math.ceil(v * 1e4) / 1e4:.4f} ({v:.5f})"
                                                          for v in factors))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Generate runtime_shaders/substrate_energy_lut_data.h: the directional-albedo
tables the runtime shaders use for energy compensation and split-sum lighting.

Tables (32 x 32 each, row-major: index = j * 32 + i, i = NoV cell, j = roughness
cell; NoV = (i + 0.5) / 32 and perceptual roughness r = (j + 0.5) / 32 at cell
centres):

  SUBSTRATE_LUT_E              E(mu, r): directional albedo of the single-scattering
                               GGX lobe with F = 1 (F0 = F90 = 1), height-correlated
                               Smith G2, alpha = max(r^2, 1e-3) (the runtime clamp).
  SUBSTRATE_LUT_B              B(mu, r): the part of E weighted by (1 - VoH)^5, so
                               that with Schlick's Fresnel the albedo of the lobe is
                               E_ss(F0, F90) = F0 * (E - B) + F90 * B
                               (the split-sum "DFG" pair is (E - B, B)).
  SUBSTRATE_LUT_FUZZ           E_fuzz(mu, r): directional albedo of the Charlie sheen
                               lobe (Estevez & Kulla 2017) with its fitted Lambda
                               shadowing, alpha = max(r^2, SHEEN_MIN_ALPHA). Not
                               clamped: it exceeds 1 at grazing view for smooth
                               fuzz (the runtime normalizes the lobe there).

  SUBSTRATE_LUT_ANISO          E_max(mu, r, |A|) and B_max(mu, r, |A|): the largest
                               directional albedo and the largest B, over the view's
                               azimuth, of the anisotropic GGX lobe with F = 1
                               (alphas r^2 (1 +- |A|), clamped as the runtime does),
                               on 16 x 16 nodes in (sqrt(mu), r) at |A| = 1/3, 2/3
                               and 1, as 1/960ths rounded up, three of 10 bits
                               per word (pack_aniso: one uint4 per two nodes
                               neighbouring in mu); the runtime compensates an
                               anisotropic lobe with W = 1 / E_max (issue 19), which
                               gains energy at no azimuth, and bounds its B by
                               B_max. Raised to an envelope of its lookup as the
                               tables above are (aniso_table).

Integration is deterministic: GGX by visible-normal importance sampling
(Heitz 2018) and the sheen by sampling its NDF, both over a Hammersley set.

The tables are conservative (docs/stability.md, "Energy: the white furnace"):
every value the runtime's lookup returns (bilinear between cell centres, the
outer half cells extrapolated linearly, NoV >= 1e-4 as the BSDF clamps it) is
at least the true albedo. The centre values are integrated first; then, on a
grid of ENVELOPE_STEPS points per cell and axis over the whole lookup domain,
the true values are integrated again and any node the lookup leaves below a
point is raised (by that point's bilinear weights) until none is. E - B and B
are bounded separately (E = (E - B) + B), so F0 (E - B) + F90 B is an upper
bound for any F0, F90 in [0, 1]: compensation never adds energy and the
diffuse below never receives more than 1 - E_spec of the true lobe.

Pure Python 3 (no numpy). Writes the header (default path, or argv[1]) and prints
the largest anisotropic nodes (10 bits of 1/960 hold up to 1.066); two runs give
identical files (about 5 minutes on 2 cores).
"""

import math
import multiprocessing
import os
import sys

N = 32                 # table resolution per axis
GGX_SAMPLES = 4096     # Hammersley points per GGX cell
FUZZ_SAMPLES = 8192    # Hammersley points per sheen cell
GGX_MIN_ALPHA = 1e-3   # must match SUBSTRATE_MIN_ALPHA in substrate_bsdf.h
SHEEN_MIN_ALPHA = 1e-3 # must match SUBSTRATE_FUZZ_MIN_ALPHA in substrate_bsdf.h
MIN_NOV = 1e-4         # SUBSTRATE_MIN_COS: the BSDF never looks up a smaller NoV
ENVELOPE_STEPS = 4     # envelope check points per cell and axis
ENVELOPE_GGX_SAMPLES = 2048
ENVELOPE_FUZZ_SAMPLES = 4096
ENVELOPE_MARGIN = 2e-4  # absolute slack over the integrated value (integration noise)
# More check points in NoV below the first cell centre, where E dips near
# NoV ~ alpha and a sharp sheen's albedo peaks (6.1 at NoV 6e-4, r 0.03).
ENVELOPE_EXTRA_NOV = (2e-4, 4e-4, 6e-4, 1e-3, 1.5e-3, 2e-3, 3e-3, 4e-3, 5.5e-3)
# The sheen's albedo at grazing views integrates to ~0.5 % (1 % where it
# exceeds 1, sharp fuzz) with ENVELOPE_FUZZ_SAMPLES points: its margin is
# relative, 1 % of the value.
ENVELOPE_FUZZ_RELATIVE_MARGIN = 0.01


def radical_inverse2(i):
    i = ((i << 16) | (i >> 16)) & 0xFFFFFFFF
    i = ((i & 0x55555555) << 1) | ((i & 0xAAAAAAAA) >> 1)
    i = ((i & 0x33333333) << 2) | ((i & 0xCCCCCCCC) >> 2)
    i = ((i & 0x0F0F0F0F) << 4) | ((i & 0xF0F0F0F0) >> 4)
    i = ((i & 0x00FF00FF) << 8) | ((i & 0xFF00FF00) >> 8)
    return i * (1.0 / 4294967296.0)


def hammersley(n):
    # (i + 0.5) / n in the first coordinate keeps the points off the poles.
    return [((i + 0.5) / n, radical_inverse2(i)) for i in range(n)]


def ggx_lambda(mu, a2):
    # Smith Lambda for GGX: (-1 + sqrt(1 + a^2 tan^2)) / 2.
    mu2 = mu * mu
    return 0.5 * (-1.0 + math.sqrt(1.0 + a2 * (1.0 - mu2) / mu2))


def ggx_cell(mu, r, pts):
    """E and B for view cosine mu and perceptual roughness r."""
    a = max(r * r, GGX_MIN_ALPHA)
    a2 = a * a
    vx = math.sqrt(max(0.0, 1.0 - mu * mu))
    vz = mu
    lam_v = ggx_lambda(vz, a2)
    # Heitz 2018 VNDF sampling; V lies in the xz plane (vy = 0).
    hx, hz = a * vx, vz
    hl = math.sqrt(hx * hx + hz * hz)
    hx /= hl
    hz /= hl
    # T1 = (-Vh.y, Vh.x, 0) / |.| = (0, 1, 0) since Vh.y = 0 and Vh.x >= 0
    # (for Vh.x = 0 the fallback (1, 0, 0) gives the same distribution).
    # T2 = cross(Vh, T1) = (-hz, 0, hx).
    s = 0.5 * (1.0 + hz)
    e_sum = 0.0
    b_sum = 0.0
    two_pi = 2.0 * math.pi
    for u1, u2 in pts:
        rr = math.sqrt(u1)
        phi = two_pi * u2
        t1 = rr * math.cos(phi)
        t2 = rr * math.sin(phi)
        t2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - t1 * t1)) + s * t2
        tn = math.sqrt(max(0.0, 1.0 - t1 * t1 - t2 * t2))
        # Nh = t1 * T1 + t2 * T2 + tn * Vh
        nx = -t2 * hz + tn * hx
        ny = t1
        nz = t2 * hx + tn * hz
        # back to the ellipsoid configuration
        mx, my, mz = a * nx, a * ny, max(0.0, nz)
        ml = math.sqrt(mx * mx + my * my + mz * mz)
        if ml <= 0.0:
            continue
        mx /= ml
        my /= ml
        mz /= ml
        voh = vx * mx + vz * mz
        if voh <= 0.0:
            continue
        lz = 2.0 * voh * mz - vz
        if lz <= 0.0:
            continue
        lam_l = ggx_lambda(min(lz, 1.0), a2)
        w = (1.0 + lam_v) / (1.0 + lam_v + lam_l)  # G2 / G1(V)
        fc = 1.0 - voh
        fc2 = fc * fc
        e_sum += w
        b_sum += w * fc2 * fc2 * fc
    n = float(len(pts))
    return e_sum / n, b_sum / n


def sheen_l(x, a):
    t = (1.0 - a) * (1.0 - a)
    pa = 21.5473 + (25.3245 - 21.5473) * t
    pb = 3.82987 + (3.32435 - 3.82987) * t
    pc = 0.19823 + (0.16801 - 0.19823) * t
    pd = -1.97760 + (-1.27393 + 1.97760) * t
    pe = -4.32054 + (-4.85967 + 4.32054) * t
    return pa / (1.0 + pb * (x ** pc if x > 0.0 else 0.0)) + pd * x + pe


def sheen_lambda(mu, a):
    if mu < 0.5:
        return math.exp(sheen_l(mu, a))
    return math.exp(2.0 * sheen_l(0.5, a) - sheen_l(1.0 - mu, a))


def fuzz_cell(mu, r, pts):
    """Directional albedo of the Charlie sheen lobe: f = D G / (4 NoV NoL),
    D = (2 + 1/a) sin^(1/a)(theta_h) / (2 pi), G = 1 / (1 + Lv + Ll).
    H is sampled with pdf D(h) NoH: sin(theta_h) = u^(1 / (2 + 1/a))."""
    a = max(r * r, SHEEN_MIN_ALPHA)
    vx = math.sqrt(max(0.0, 1.0 - mu * mu))
    vz = mu
    lam_v = sheen_lambda(vz, a)
    k = 1.0 / (2.0 + 1.0 / a)
    total = 0.0
    two_pi = 2.0 * math.pi
    for u1, u2 in pts:
        st = u1 ** k
        ct = math.sqrt(max(0.0, 1.0 - st * st))
        phi = two_pi * u2
        hx = st * math.cos(phi)
        hz = ct
        voh = vx * hx + vz * hz
        if voh <= 0.0 or hz <= 0.0:
            continue
        lz = 2.0 * voh * hz - vz
        if lz <= 0.0:
            continue
        g = 1.0 / (1.0 + lam_v + sheen_lambda(min(lz, 1.0), a))
        # f NoL / pdf_L with pdf_L = D NoH / (4 VoH): G VoH / (NoV NoH)
        total += g * voh / (vz * hz)
    return total / float(len(pts))


# --- The anisotropic table (issue 19): E_max(NoV, r, |A|) ---------------------

ANISO_N = 16            # nodes per axis in (sqrt(NoV), r), at i / 15 and j / 15
ANISO_SLICES = 3        # |A| = 1/3, 2/3, 1 (|A| = 0 is the E and B tables)
ANISO_SCALE = 960.0     # a packed value is a count of 1/960ths (10 bits: up to 1.066; raised nodes exceed 1)
ANISO_PHIS = 9          # view azimuths from the tangent to the bitangent, 0 .. pi/2
ANISO_SAMPLES = 1024    # Hammersley points per azimuth at a node
ANISO_CHECK_SAMPLES = 2048  # and at an envelope check point (512 read up to 2.5e-3 low)
ANISO_MARGIN = 1e-3     # absolute slack over the integrated value (2048 points read up to 7e-4 low)
ANISO_CHECK_A = [1 / 24.0, 1 / 12.0, 1 / 8.0] + [k / 12.0 for k in range(2, 13)]  # |A| of the checks


def ggx_alpha(r, a_abs):
    """substrate_ggx_alpha: (ax, ay) = r^2 (1 + |A|, 1 - |A|), clamped to [1e-3, 1]."""
    a = r * r
    return (min(max(a * (1.0 + a_abs), GGX_MIN_ALPHA), 1.0), min(max(a * (1.0 - a_abs), GGX_MIN_ALPHA), 1.0))


def aniso_albedo(mu, phi, ax, ay, pts):
    """(E, B) of the anisotropic GGX lobe with F = 1 seen from azimuth phi (from
    the axis of roughness ax): Heitz 2018's visible-normal sampling, weight
    G2 / G1(V); B is the part weighted by (1 - VoH)^5."""
    sv = math.sqrt(max(0.0, 1.0 - mu * mu))
    vx, vy, vz = sv * math.cos(phi), sv * math.sin(phi), mu
    lam_v = 0.5 * (-1.0 + math.sqrt(1.0 + (ax * ax * vx * vx + ay * ay * vy * vy) / (vz * vz)))
    hx, hy, hz = ax * vx, ay * vy, vz
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    hx, hy, hz = hx / hl, hy / hl, hz / hl
    lensq = hx * hx + hy * hy
    if lensq > 0.0:
        il = 1.0 / math.sqrt(lensq)
        t1x, t1y = -hy * il, hx * il
    else:
        t1x, t1y = 1.0, 0.0
    # T2 = cross(Vh, T1), T1 = (t1x, t1y, 0)
    t2x, t2y, t2z = -hz * t1y, hz * t1x, hx * t1y - hy * t1x
    s = 0.5 * (1.0 + hz)
    two_pi = 2.0 * math.pi
    total = 0.0
    total_b = 0.0
    for u1, u2 in pts:
        rr = math.sqrt(u1)
        ph = two_pi * u2
        a1 = rr * math.cos(ph)
        a2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - a1 * a1)) + s * rr * math.sin(ph)
        an = math.sqrt(max(0.0, 1.0 - a1 * a1 - a2 * a2))
        mx = ax * (a1 * t1x + a2 * t2x + an * hx)
        my = ay * (a1 * t1y + a2 * t2y + an * hy)
        mz = max(0.0, a2 * t2z + an * hz)
        ml = math.sqrt(mx * mx + my * my + mz * mz)
        if ml <= 0.0:
            continue
        mx, my, mz = mx / ml, my / ml, mz / ml
        voh = vx * mx + vy * my + vz * mz
        lx, ly, lz = 2.0 * voh * mx - vx, 2.0 * voh * my - vy, 2.0 * voh * mz - vz
        if lz <= 0.0:
            continue
        lam_l = 0.5 * (-1.0 + math.sqrt(1.0 + (ax * ax * lx * lx + ay * ay * ly * ly) / (lz * lz)))
        w = (1.0 + lam_v) / (1.0 + lam_v + lam_l)
        fc = 1.0 - min(max(voh, 0.0), 1.0)
        fc2 = fc * fc
        total += w
        total_b += w * fc2 * fc2 * fc
    return total / float(len(pts)), total_b / float(len(pts))


def aniso_max(args):
    """(E_max, B_max): the largest E and the largest B over ANISO_PHIS view
    azimuths of the lobe at (NoV, r, |A|) (each bounded separately)."""
    mu, r, a_abs, n = args
    ax, ay = ggx_alpha(r, a_abs)
    pts = hammersley(n)
    mu = max(mu, MIN_NOV)
    eb = [aniso_albedo(mu, k * 0.5 * math.pi / (ANISO_PHIS - 1), ax, ay, pts) for k in range(ANISO_PHIS)]
    return max(e for e, _ in eb), max(b for _, b in eb)


def aniso_weights(mu, r, a_abs):
    """substrate_energy_aniso's lookup: the (node index, weight) pairs over the
    nodes (index = (j * 16 + i) * ANISO_SLICES + slice) and the weight of the
    isotropic tables."""
    x = math.sqrt(min(max(mu, 0.0), 1.0)) * (ANISO_N - 1)
    y = min(max(r, 0.0), 1.0) * (ANISO_N - 1)
    i0 = min(int(math.floor(x)), ANISO_N - 2)
    j0 = min(int(math.floor(y)), ANISO_N - 2)
    fx, fy = x - i0, y - j0
    a = min(max(a_abs, 0.0), 1.0) * ANISO_SLICES
    out = []
    for dj, wy in ((0, 1.0 - fy), (1, fy)):
        for di, wx in ((0, 1.0 - fx), (1, fx)):
            for sl in range(ANISO_SLICES):
                w = max(0.0, 1.0 - abs(a - (sl + 1))) * wx * wy
                if w > 0.0:
                    out.append((((j0 + dj) * ANISO_N + i0 + di) * ANISO_SLICES + sl, w))
    return out, max(0.0, 1.0 - a)


def iso_lookup(tab, mu, r, lo):
    """A bilinear lookup of a generated 32 x 32 table (lookup_weights), clamped
    to [lo, 1] (substrate_energy_dfg: E to [1e-3, 1], B to [0, 1])."""
    px = min(max(mu, 0.0), 1.0) * N - 0.5
    py = min(max(r, 0.0), 1.0) * N - 0.5
    return min(max(sum(tab[i] * w for i, w in lookup_weights(px, py)), lo), 1.0)


def units_up(v):
    """The smallest count q of 1 / ANISO_SCALE with q / ANISO_SCALE >= v (v >= 0), 10 bits."""
    q = max(int(math.ceil(v * ANISO_SCALE)), 0)
    if q / ANISO_SCALE < v:
        q += 1
    if q > 1023:
        raise RuntimeError("anisotropic node %g does not fit 10 bits of 1/960ths" % v)
    return q


def pack_aniso(e_nodes, b_nodes):
    """One uint4 per pair of nodes neighbouring in NoV, (i, j) and (i + 1, j),
    i < 15, at [(j * 15 + i) * 4]: (E(i), B(i), E(i + 1), B(i + 1)), each word
    the values at |A| 1/3 | 2/3 << 10 | 1 << 20 as 1/960ths rounded up (a
    bound stays a bound). The lookup reads one word group per roughness row.
    A host passes the words through a float buffer, so no word may read as a
    denormal float (some paths flush those to zero): where bits 23-30 would
    all be 0 (the value at |A| 1 below 0.008), bit 30 is set; the lookup
    masks each value to its 10 bits."""
    def word(nodes, i, j):
        n = (j * ANISO_N + i) * ANISO_SLICES
        w = units_up(nodes[n]) | units_up(nodes[n + 1]) << 10 | units_up(nodes[n + 2]) << 20
        return w | (1 << 30) if (w >> 23) == 0 else w
    out = []
    for j in range(ANISO_N):
        for i in range(ANISO_N - 1):
            out += [word(e_nodes, i, j), word(b_nodes, i, j), word(e_nodes, i + 1, j), word(b_nodes, i + 1, j)]
    return out


def aniso_lookup_at(check, nodes, iso_tab, lo):
    """What substrate_energy_aniso returns at one check (mu, r, |A|, _): the
    isotropic table `iso_tab`'s share (its weight at |A| = 0) plus the
    weighted `nodes`; with the (node index, weight) pairs it used."""
    mu, r, a_abs, _n = check
    ws, w_iso = aniso_weights(mu, r, a_abs)
    return w_iso * iso_lookup(iso_tab, mu, r, lo) + sum(nodes[k] * w for k, w in ws), ws


def raise_aniso(nodes, checks, values, iso_tab, lo):
    """Raises `nodes` until the lookup (aniso_lookup_at) is at least value +
    ANISO_MARGIN at every check."""
    for _ in range(200):
        worst = 0.0
        for check, value in zip(checks, values):
            have, ws = aniso_lookup_at(check, nodes, iso_tab, lo)
            d = value + ANISO_MARGIN - have
            if d > 1e-9:
                worst = max(worst, d)
                s2 = sum(w * w for _, w in ws)
                for k, w in ws:
                    nodes[k] += d * w / s2
        if worst <= 1e-9:
            return
    raise RuntimeError("anisotropic envelope did not converge")


def lower_aniso(nodes, checks, values, iso_tab, lo):
    """Lowers each node of `nodes` (raised by raise_aniso) as far as every
    check it takes part in allows (the lookup stays at least value +
    ANISO_MARGIN), one node at a time, until no node moves by more than 1e-7
    (at most 100 passes; every step keeps every check): raise_aniso lifts every
    node of a short check together, so a node may be left higher than any
    check needs (the largest albedo bends across |A| and r), and every point of
    a node's cells loses what it is too high."""
    have, need, uses = [], [], [[] for _ in nodes]
    for c, (check, value) in enumerate(zip(checks, values)):
        at, ws = aniso_lookup_at(check, nodes, iso_tab, lo)
        have.append(at)
        need.append(value + ANISO_MARGIN)
        for k, w in ws:
            if w > 0.0:
                uses[k].append((c, w))
    for _ in range(100):
        moved = 0.0
        for k, used in enumerate(uses):
            if not used:
                continue
            slack = min((have[c] - need[c]) / w for c, w in used)
            step = min(slack, nodes[k])
            if step > 1e-7:
                nodes[k] -= step
                for c, w in used:
                    have[c] -= step * w
                moved = max(moved, step)
        if moved <= 1e-7:
            return


def aniso_table(e_tab, b_tab, pool):
    """The E_max and B_max nodes, each raised until the lookup bounds it (plus
    ANISO_MARGIN) at every check point: the nodes themselves, the midpoints
    between nodes in sqrt(NoV) and r, at |A| = 1/24, 1/12, 1/8 and 1/6 .. 1 in
    steps of 1/12 (ANISO_CHECK_A; finer where the isotropic tables take part),
    NoV >= 1e-4; then
    lowered where no check needs them (lower_aniso) and packed as 1/960ths
    rounded up (pack_aniso)."""
    nodes_args = []
    for j in range(ANISO_N):
        for i in range(ANISO_N):
            for sl in range(ANISO_SLICES):
                nodes_args.append(((i / (ANISO_N - 1.0)) ** 2, j / (ANISO_N - 1.0), (sl + 1.0) / ANISO_SLICES,
                                   ANISO_SAMPLES))
    nodes = pool.map(aniso_max, nodes_args, chunksize=16)
    e_nodes = [e for e, _ in nodes]
    b_nodes = [b for _, b in nodes]
    us = [k / (2.0 * (ANISO_N - 1)) for k in range(2 * ANISO_N - 1)]
    checks = []
    for y in us:
        for x in us:
            for a_abs in ANISO_CHECK_A:
                checks.append((max(x * x, MIN_NOV), y, a_abs, ANISO_CHECK_SAMPLES))
    values = pool.map(aniso_max, checks, chunksize=32)
    for nodes, tab, lo, k in ((e_nodes, e_tab, 1e-3, 0), (b_nodes, b_tab, 0.0, 1)):
        raise_aniso(nodes, checks, [v[k] for v in values], tab, lo)
        lower_aniso(nodes, checks, [v[k] for v in values], tab, lo)
    print("anisotropic nodes: E up to %.4f, B up to %.4f" % (max(e_nodes), max(b_nodes)))
    return pack_aniso(e_nodes, b_nodes)


def fmt(v):
    return "%.5e" % v


def emit_table(out, name, index, values, comment):
    out.append("  // [%d * 1024 + j * 32 + i] %s: %s" % (index, name, comment))
    for j in range(N):
        row = values[j * N:(j + 1) * N]
        line = ", ".join(fmt(v) for v in row)
        last = index == 2 and j + 1 == N
        out.append("  " + line + ("" if last else ",") + "  // r = %.5f" % ((j + 0.5) / N))


def emit_aniso_table(out, values):
    out.append(ANISO_TOP)
    out.append("  // [(j * 15 + i) * 4 + c]: nodes (sqrt(NoV) = i / 15 and (i + 1) / 15, r = j / 15); c = 0, 1:")
    out.append("  // E_max, B_max at node i, c = 2, 3 at node i + 1; each word: |A| 1/3 | 2/3 << 10 | 1 << 20")
    out.append("  // (10 bits each, counts of 1/960)")
    row = (ANISO_N - 1) * 4
    for j in range(ANISO_N):
        line = ", ".join("0x%08xu" % v for v in values[j * row:(j + 1) * row])
        out.append("  " + line + ("" if j + 1 == ANISO_N else ",") + "  // r = %.5f" % (j / (ANISO_N - 1.0)))
    out.append(ANISO_BOTTOM)


HEADER_TOP = """\
// substratec runtime shaders: the directional-albedo tables (GENERATED by
// scripts/gen_energy_lut.py -- do not edit; rerun the script instead).
//
// One array of 3 x 32 x 32 floats, SUBSTRATE_LUT_TABLES[t * 1024 + j * 32 + i]:
// t the table (SUBSTRATE_LUT_E, SUBSTRATE_LUT_B, SUBSTRATE_LUT_FUZZ), i the NoV
// cell and j the perceptual-roughness cell; NoV = (i + 0.5) / 32 and
// r = (j + 0.5) / 32 at cell centres. Then, for shaders with anisotropy and for
// hosts (SUBSTRATE_USE_ANISOTROPY undefined or 1), SUBSTRATE_LUT_ANISO_TABLE:
// 15 x 16 uint4 of three 10-bit counts of 1/960 per uint (low bits first),
// one per pair of nodes neighbouring in NoV, [(j * 15 + i) * 4 + c]: nodes at
// NoV = (i / 15)^2 and ((i + 1) / 15)^2, r = j / 15. The host uploads the two
// arrays' bits in that order (SUBSTRATE_LUT_FLOATS 32-bit words in all).
//
//   SUBSTRATE_LUT_E     E(NoV, r): albedo of the single-scattering GGX lobe with
//                       F = 1 (height-correlated Smith G2, alpha = max(r^2, 1e-3)).
//                       Turquin 2019 uses it for W = 1 + F0 (1 - E) / E.
//                       Stored as (E - B) + B of the two upper bounds (below),
//                       so it may exceed 1 by their slack.
//   SUBSTRATE_LUT_B     B(NoV, r): the part of E weighted by (1 - VoH)^5; with
//                       Schlick's Fresnel the lobe's albedo is F0 (E - B) + F90 B
//                       (the split-sum DFG pair).
//   SUBSTRATE_LUT_FUZZ  E_fuzz(NoV, r): albedo of the Charlie sheen lobe (Estevez &
//                       Kulla 2017, fitted Lambda shadowing, alpha = max(r^2, 1e-3)).
//                       Not clamped: the model exceeds 1 at grazing view for small
//                       roughness (up to ~3.2 at NoV = 1/64, r = 1/64); the BSDF
//                       divides the lobe by max(1, E_fuzz).
//   SUBSTRATE_LUT_ANISO E_max(NoV, r, |A|) and B_max(NoV, r, |A|): the largest
//                       albedo and the largest B, over the view's azimuth, of
//                       the anisotropic GGX lobe with F = 1 (alphas
//                       r^2 (1 +- |A|) clamped to [1e-3, 1]), for the energy
//                       terms of anisotropic lobes (substrate_energy_aniso):
//                       bounds at every azimuth. Components 0, 1: E_max and B_max
//                       at node i, 2, 3 at node i + 1; each word holds |A| = 1/3,
//                       2/3 and 1 in bits 0-9, 10-19 and 20-29 (1/960ths;
//                       bit 30 set where the word would read as a denormal float).
//                       %d azimuths per point, %d points per azimuth at the nodes;
//                       raised until the lookup (bilinear in sqrt(NoV) and r, by
//                       hat weights over |A| with the E and B tables at |A| = 0)
//                       is at least the value + %g at the nodes, the midpoints
//                       between them and %d values of |A| (%d points per
//                       azimuth), each node then lowered as far as those checks
//                       allow, then rounded up to 1/960ths.
//
// Integration: %d (GGX, visible-normal sampling, Heitz 2018) and %d (sheen, NDF
// sampling) Hammersley points per cell.
//
// Conservative: every value the runtime's lookup returns (substrate_lut_coords:
// bilinear between cell centres, linear extrapolation in the outer half cells,
// NoV >= 1e-4) is at least the true value (E - B, B and E_fuzz each), checked
// on %d x %d points over the lookup domain (%d more NoV below the first cell
// centre) with a margin of %g (E_fuzz: %g of the value more); nodes
// the lookup left short were raised (docs/stability.md, "Energy: the white furnace").
//
// Shaders read these values from a uniform buffer by default (see
// substrate_energy_lut.h); this file is what the host uploads, and what a shader
// compiles in as a constant array with SUBSTRATE_LUT_INLINE. It needs
// SUBSTRATE_CONST and SUBSTRATE_ARRAY_BEGIN/END: the shader preludes define them,
// and C or C++ hosts may too, e.g. `static const` / `{` / `}`.
#ifndef SUBSTRATE_ENERGY_LUT_DATA_H
#define SUBSTRATE_ENERGY_LUT_DATA_H 1

#define SUBSTRATE_LUT_SIZE 32
#define SUBSTRATE_LUT_E 0
#define SUBSTRATE_LUT_B 1
#define SUBSTRATE_LUT_FUZZ 2
#define SUBSTRATE_LUT_ANISO 3
#define SUBSTRATE_LUT_ANISO_SIZE 16
#define SUBSTRATE_LUT_FLOATS 4032

SUBSTRATE_CONST float SUBSTRATE_LUT_TABLES[3072] = SUBSTRATE_ARRAY_BEGIN(float, 3072)"""

HEADER_BOTTOM = """\
#endif
"""

ANISO_TOP = """\
SUBSTRATE_ARRAY_END;

#if !defined(SUBSTRATE_USE_ANISOTROPY) || SUBSTRATE_USE_ANISOTROPY
SUBSTRATE_CONST uint SUBSTRATE_LUT_ANISO_TABLE[960] = SUBSTRATE_ARRAY_BEGIN(uint, 960)"""

ANISO_BOTTOM = """\
SUBSTRATE_ARRAY_END;
#endif
"""


def lookup_weights(px, py):
    """substrate_lut_coords: the four (index, weight) pairs of the bilinear
    lookup at table coordinates p = value * 32 - 0.5 (weights in [-0.5, 1.5]
    in the outer half cells)."""
    x0 = min(max(math.floor(px), 0), N - 2)
    y0 = min(max(math.floor(py), 0), N - 2)
    fx = px - x0
    fy = py - y0
    i = y0 * N + x0
    return ((i, (1.0 - fx) * (1.0 - fy)), (i + 1, fx * (1.0 - fy)),
            (i + N, (1.0 - fx) * fy), (i + N + 1, fx * fy))


def raise_to_envelope(nodes, points, relative=0.0):
    """Raises `nodes` until the lookup at every (px, py, value) of `points`
    is at least value + ENVELOPE_MARGIN + relative * value. A
    point short by d raises its positive-weight nodes by d w / sum(w^2), which
    lifts it by exactly d."""
    for _ in range(200):
        worst = 0.0
        for px, py, value in points:
            ws = lookup_weights(px, py)
            have = sum(nodes[i] * w for i, w in ws)
            d = value + ENVELOPE_MARGIN + relative * value - have
            if d > 1e-9:
                worst = max(worst, d)
                s2 = sum(w * w for _, w in ws if w > 0.0)
                for i, w in ws:
                    if w > 0.0:
                        nodes[i] += d * w / s2
        if worst <= 1e-9:
            return
    raise RuntimeError("envelope did not converge")


def envelope_points():
    """(px, py, NoV, r) over the lookup domain: ENVELOPE_STEPS points per cell
    and axis from p = -0.5 (NoV = 1e-4, r = 0) to 31.5 (NoV = r = 1), and the
    ENVELOPE_EXTRA_NOV columns."""
    ps = [-0.5 + k / float(ENVELOPE_STEPS) for k in range(N * ENVELOPE_STEPS + 1)]
    mus = [min(max((px + 0.5) / N, MIN_NOV), 1.0) for px in ps] + list(ENVELOPE_EXTRA_NOV)
    out = []
    for py in ps:
        r = min(max((py + 0.5) / N, 0.0), 1.0)
        for mu in mus:
            out.append((mu * N - 0.5, py, mu, r))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        here, "..", "runtime_shaders", "substrate_energy_lut_data.h")
    pts_ggx = hammersley(GGX_SAMPLES)
    pts_fuzz = hammersley(FUZZ_SAMPLES)
    x_tab, b_tab, f_tab = [], [], []  # E - B, B, E_fuzz at the cell centres
    for j in range(N):
        r = (j + 0.5) / N
        for i in range(N):
            mu = (i + 0.5) / N
            e, b = ggx_cell(mu, r, pts_ggx)
            b = min(b, e)
            x_tab.append(e - b)
            b_tab.append(b)
            f_tab.append(fuzz_cell(mu, r, pts_fuzz))  # may exceed 1 (see header)
    # The conservative envelope (see the module docstring).
    pts_env_ggx = hammersley(ENVELOPE_GGX_SAMPLES)
    pts_env_fuzz = hammersley(ENVELOPE_FUZZ_SAMPLES)
    x_pts, b_pts, f_pts = [], [], []
    for px, py, mu, r in envelope_points():
        e, b = ggx_cell(mu, r, pts_env_ggx)
        b = min(b, e)
        x_pts.append((px, py, e - b))
        b_pts.append((px, py, b))
        f_pts.append((px, py, fuzz_cell(mu, r, pts_env_fuzz)))
    raise_to_envelope(x_tab, x_pts)
    raise_to_envelope(b_tab, b_pts)
    raise_to_envelope(f_tab, f_pts, ENVELOPE_FUZZ_RELATIVE_MARGIN)
    # E is stored as the sum of the two bounds, not clamped to 1: the lookup
    # takes E - B back from it (substrate_energy_dfg).
    e_tab = [x + b for x, b in zip(x_tab, b_tab)]
    with multiprocessing.Pool() as pool:
        a_tab = aniso_table(e_tab, b_tab, pool)
    steps = N * ENVELOPE_STEPS + 1
    out = [HEADER_TOP % (ANISO_PHIS, ANISO_SAMPLES, ANISO_MARGIN, len(ANISO_CHECK_A), ANISO_CHECK_SAMPLES,
                         GGX_SAMPLES, FUZZ_SAMPLES, steps, steps, len(ENVELOPE_EXTRA_NOV), ENVELOPE_MARGIN,
                         ENVELOPE_FUZZ_RELATIVE_MARGIN)]
    emit_table(out, "SUBSTRATE_LUT_E", 0, e_tab, "E(NoV, r), F = 1")
    emit_table(out, "SUBSTRATE_LUT_B", 1, b_tab, "B(NoV, r), the (1 - VoH)^5 part of E")
    emit_table(out, "SUBSTRATE_LUT_FUZZ", 2, f_tab, "E_fuzz(NoV, r), Charlie sheen")
    emit_aniso_table(out, a_tab)
    out.append(HEADER_BOTTOM)
    text = "\n".join(out)
    with open(path, "w", newline="\n") as fh:
        fh.write(text)


if __name__ == "__main__":
    main()

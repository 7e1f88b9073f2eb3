#!/usr/bin/env python3
"""Fit the constants of a slab's medium weight (issue 19, step 12;
runtime_shaders/substrate_bsdf.h, "A slab's medium"; SUBSTRATE_MEDIUM_* in
substrate_constants.h) and print the figures the comments quote. Pure Python 3,
deterministic, a few seconds; writes nothing.

WALK holds what the ground truth's random walk (compiler/tools/reference/
random_walk.h, layeredAlbedo with albedoSeenThroughInterface, 65,536 walks per
figure, seed 1) returned for one slab of F0 0.04 over a semi-infinite medium
of albedo A (diffuse_albedo A, MFP 1) and over a Lambertian of the same albedo
(MFP 0), at roughness 0.05, 0.45 and 0.8, for A in ALBEDOS and NoV in NOVS:
the diffuse part, the slab's albedo minus that of the same slab over a black
medium. The ratio medium / Lambertian is the medium's angular factor, which
the weight models on top of the Lambertian's.

1. INVERSE: s = (1 - A) / (1 + c A) against the exact inverse of van de
   Hulst's albedo, c by minimax of the weight (1 + 2 s m) / (1 + 2 s) at m 0.645.
2. The light side's mean: for mu' = p + (1 - p) mu, the cosine- and
   transmission-weighted mean of 1 / (1 + 2 s mu') over the hemisphere against
   1 / (1 + 2 s m'), m' = p + (1 - p) MEAN_COS.
3. SPREAD: the rms of the model's factor against WALK over SPREAD (A >= 0.1),
   and the residuals at the chosen value.
"""

import math

ALBEDOS = [0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9]
NOVS = [1.0, 0.8, 0.6, 0.4, 0.2, 0.1]
MEAN_COS = 0.645
INVERSE = 1.376
SPREAD = 0.35
F0 = 0.04

WALK = {
    # roughness 0.05: (medium, Lambertian)
    0.05: (
    [
        [0.0321, 0.0364, 0.0366, 0.0360, 0.0275, 0.0174],
        [0.0718, 0.0745, 0.0759, 0.0745, 0.0587, 0.0344],
        [0.1548, 0.1607, 0.1607, 0.1563, 0.1220, 0.0782],
        [0.2963, 0.3034, 0.3037, 0.2850, 0.2225, 0.1430],
        [0.4512, 0.4537, 0.4504, 0.4234, 0.3229, 0.2111],
        [0.6551, 0.6588, 0.6482, 0.6069, 0.4636, 0.3012],
        [0.8341, 0.8310, 0.8160, 0.7583, 0.5813, 0.3789],
    ],
    [
        [0.0485, 0.0486, 0.0475, 0.0424, 0.0346, 0.0211],
        [0.0961, 0.0960, 0.0943, 0.0866, 0.0679, 0.0440],
        [0.1913, 0.1910, 0.1864, 0.1739, 0.1322, 0.0825],
        [0.3346, 0.3340, 0.3258, 0.3021, 0.2318, 0.1485],
        [0.4774, 0.4760, 0.4656, 0.4306, 0.3292, 0.2128],
        [0.6714, 0.6693, 0.6547, 0.6070, 0.4637, 0.2999],
        [0.8639, 0.8610, 0.8426, 0.7807, 0.5962, 0.3856],
    ]),
    # roughness 0.45: (medium, Lambertian)
    0.45: (
    [
        [0.0357, 0.0393, 0.0393, 0.0410, 0.0392, 0.0393],
        [0.0758, 0.0783, 0.0800, 0.0832, 0.0796, 0.0805],
        [0.1599, 0.1664, 0.1681, 0.1681, 0.1605, 0.1576],
        [0.2973, 0.3089, 0.3109, 0.3054, 0.2892, 0.2778],
        [0.4519, 0.4560, 0.4530, 0.4449, 0.4204, 0.4039],
        [0.6556, 0.6604, 0.6533, 0.6339, 0.5895, 0.5621],
        [0.8358, 0.8359, 0.8239, 0.7932, 0.7343, 0.6969],
    ],
    [
        [0.0492, 0.0489, 0.0475, 0.0459, 0.0414, 0.0395],
        [0.0961, 0.0957, 0.0940, 0.0907, 0.0824, 0.0773],
        [0.1926, 0.1917, 0.1882, 0.1801, 0.1654, 0.1572],
        [0.3367, 0.3348, 0.3288, 0.3168, 0.2907, 0.2741],
        [0.4828, 0.4801, 0.4714, 0.4514, 0.4163, 0.3916],
        [0.6747, 0.6703, 0.6583, 0.6314, 0.5821, 0.5504],
        [0.8666, 0.8615, 0.8458, 0.8116, 0.7487, 0.7081],
    ]),
    # roughness 0.8: (medium, Lambertian)
    0.8: (
    [
        [0.0387, 0.0402, 0.0431, 0.0467, 0.0458, 0.0452],
        [0.0782, 0.0828, 0.0885, 0.0936, 0.0908, 0.0897],
        [0.1673, 0.1751, 0.1812, 0.1880, 0.1857, 0.1796],
        [0.3076, 0.3180, 0.3284, 0.3327, 0.3312, 0.3217],
        [0.4582, 0.4664, 0.4776, 0.4822, 0.4751, 0.4589],
        [0.6635, 0.6716, 0.6733, 0.6757, 0.6615, 0.6466],
        [0.8474, 0.8497, 0.8468, 0.8425, 0.8205, 0.8022],
    ],
    [
        [0.0485, 0.0481, 0.0477, 0.0475, 0.0444, 0.0468],
        [0.0966, 0.0961, 0.0965, 0.0945, 0.0912, 0.0918],
        [0.1947, 0.1935, 0.1930, 0.1909, 0.1862, 0.1817],
        [0.3413, 0.3395, 0.3381, 0.3330, 0.3233, 0.3190],
        [0.4872, 0.4857, 0.4836, 0.4770, 0.4622, 0.4542],
        [0.6818, 0.6791, 0.6748, 0.6662, 0.6471, 0.6374],
        [0.8774, 0.8741, 0.8683, 0.8572, 0.8343, 0.8197],
    ]),
}


def exact_slope(a):
    """Kulla & Conty's exact inverse of van de Hulst's spherical albedo."""
    b = 1.139 + 1.17 * a
    return 2 * (1 - a) / (b + math.sqrt(max(b * b - 0.556 * (1 - a), 0.0)))


def fresnel(mu, eta):
    st = math.sqrt(max(1 - mu * mu, 0.0)) / eta
    ct = math.sqrt(max(1 - st * st, 0.0))
    rs = (mu - eta * ct) / (mu + eta * ct)
    rp = (eta * mu - ct) / (eta * mu + ct)
    return 0.5 * (rs * rs + rp * rp)


def interface(f0, roughness, spread):
    sq = math.sqrt(f0)
    ie2 = ((1 - sq) / (1 + sq)) ** 2
    return ie2, math.sqrt(1 - ie2) * (1 - spread * roughness)


def slope(a, f0, ie2):
    t = max((1 - f0) * (20 / 21) * ie2, 1e-4)
    return t * (1 - a) / (t + (1 + INVERSE - t) * a)


def view_factor(a, mu, roughness, spread, f0=F0):
    ie2, p = interface(f0, roughness, spread)
    s = slope(a, f0, ie2)
    return (1 + 2 * s * MEAN_COS) / (1 + 2 * s * (p + (1 - p) * mu))


def fit_inverse():
    grid = [i / 2000 for i in range(2001)]
    exact = [exact_slope(a) for a in grid]

    def weight(s):
        return (1 + 2 * s * MEAN_COS) / (1 + 2 * s)

    def worst(c):
        return max(abs(weight((1 - a) / (1 + c * a)) / weight(e) - 1) for a, e in zip(grid, exact))

    best = min((worst(1 + i / 1000), 1 + i / 1000) for i in range(1001))
    ds = max(abs((1 - a) / (1 + INVERSE * a) - e) for a, e in zip(grid, exact))
    print(f"1. INVERSE: minimax c = {best[1]:.3f} (weight within {best[0]:.2e}); at c = {INVERSE}: "
          f"weight within {worst(INVERSE):.2e}, s within {ds:.4f}")


def light_mean():
    n = 4000
    worst = 0.0
    for eta in (1.0, 1.2, 1.33, 1.4, 1.5, 1.7, 2.0):
        f0 = ((eta - 1) / (eta + 1)) ** 2
        for r in (0.0, 0.5, 1.0):
            ie2, p = interface(f0, r, SPREAD)
            for s in (0.05, 0.25, 0.5, 1.0):
                num = den = 0.0
                for i in range(n):
                    mu = (i + 0.5) / n
                    w = (1 - (fresnel(mu, eta) if eta > 1 else 0.0)) * mu
                    num += w / (1 + 2 * s * (p + (1 - p) * mu))
                    den += w
                model = 1 / (1 + 2 * s * (p + (1 - p) * MEAN_COS))
                worst = max(worst, abs(model / (num / den) - 1))
    print(f"2. light side: 1 / (1 + 2 s m') within {worst:.4f} of the weighted mean "
          "(eta 1 .. 2, r 0 .. 1, s 0.05 .. 1)")


def residuals(spread):
    out = []
    for r, (medium, lambertian) in WALK.items():
        for i, a in enumerate(ALBEDOS):
            row = [view_factor(a, mu, r, spread) / (m / l) - 1 for mu, m, l in zip(NOVS, medium[i], lambertian[i])]
            out.append((r, a, row))
    return out


def rms(spread):
    e = [x for r, a, row in residuals(spread) if a >= 0.1 for x in row]
    return math.sqrt(sum(x * x for x in e) / len(e))


def fit_spread():
    scan = [(rms(i / 100), i / 100) for i in range(0, 101, 5)]
    print("3. SPREAD: rms against the walk " + ", ".join(f"{v:.2f}: {e:.4f}" for e, v in scan))
    print(f"   at SPREAD = {SPREAD} (rms {rms(SPREAD):.4f}), model / walk - 1 (NoV " +
          " / ".join(f"{m:g}" for m in NOVS) + "):")
    for r, a, row in residuals(SPREAD):
        print(f"   r {r:<4} A {a:<4} " + " ".join(f"{x:+.3f}" for x in row))


if __name__ == "__main__":
    fit_inverse()
    light_mean()
    fit_spread()

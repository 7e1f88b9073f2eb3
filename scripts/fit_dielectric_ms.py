#!/usr/bin/env python3
"""Fit the dielectric multiple-scattering factor (issue 19, step 20;
SUBSTRATE_DIELECTRIC_MS in runtime_shaders/substrate_constants.h,
substrate_specular_energy in substrate_bsdf.h; docs/accuracy.md, step 20).

For slabs of diffuse albedo 0 (a black base: the albedo is the interface's
alone), F0 0.04 and 0.08 and roughness 0.2 ... 1, `substratec accuracy --json`
gives the model's and the truth's directional albedo at NoV 1 / 0.8 / 0.6 /
0.4 / 0.2 / 0.1. The model's lobe carries 1 + MS r (the build's MS, read from
substrate_constants.h), which the script divides out; what the truth needs on
top of the single-scattering lobe, truth / model_ss - 1, is fitted by weighted
least squares (weights: the truth's standard error) as c r^p for p = 1, 1.5, 2,
as r (a + b (1 - NoV)), and as a r + b r^2; then it prints the model's error
with the shipped MS at every point, and F0 0.02 (left out of the fit: the
low-F0 curve of step 17 lies above the truth there). Pure Python 3 (no
numpy), deterministic; writes nothing but a temporary directory; about 10 s on
two cores at the default 65,536 walks.

usage: scripts/fit_dielectric_ms.py [--bin BIN] [--samples N] [--jobs J]
"""

import argparse
import itertools
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
ROUGHNESS = (0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
F0S = (0.02, 0.04, 0.08)


def shipped_ms():
    with open(os.path.join(ROOT, "runtime_shaders", "substrate_constants.h")) as f:
        return float(re.search(r"#define SUBSTRATE_DIELECTRIC_MS ([0-9.eE+-]+)", f.read()).group(1))


def measure(binary, tmp, samples, r, f0):
    """[(NoV, model, truth, truth's standard error)] of a black slab (green channel: grey)."""
    name = ("black_%g_%g" % (r, f0)).replace(".", "p")
    doc = {"format": "substrate-material/1", "name": name,
           "nodes": {"s": {"kind": "slab", "diffuse_albedo": 0, "f0": f0, "roughness": r}}, "output": "s"}
    path = os.path.join(tmp, name + ".json")
    with open(path, "w") as out:
        json.dump(doc, out)
    run = subprocess.run([binary, "accuracy", path, "--json", "--samples", str(samples), "--eval-samples", "16",
                          "-j", "1", "--diffuse", "lambert"], capture_output=True, text=True, check=True)
    return [(row["nov"], row["analytic"][1], row["truth"][1], row["truth_stderr"][1])
            for row in json.loads(run.stdout)["rows"]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "bin", "substratec"))
    parser.add_argument("--samples", type=int, default=65536)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    ms = shipped_ms()
    grid = list(itertools.product(ROUGHNESS, F0S))
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.jobs) as pool:
        rows = list(pool.map(lambda rf: measure(args.bin, tmp, args.samples, *rf), grid))
    points = []  # (r, NoV, needed factor - 1, weight)
    for (r, f0), measured in zip(grid, rows):
        if f0 == 0.02:
            continue
        for nov, model, truth, err in measured:
            single = model / (1 + ms * r)  # the build's factor divided out
            points.append((r, nov, truth / single - 1, 1 / ((err / single) ** 2 + 1e-4)))
    total = sum(p[3] for p in points)

    def rms(model):
        return math.sqrt(sum(w * (y - model(r, nov)) ** 2 for r, nov, y, w in points) / total)

    def fit2(f, g):
        """Weighted least squares of y on a f + b g: the 2 x 2 normal equations."""
        sff = sum(w * f(r, n) ** 2 for r, n, _, w in points)
        sgg = sum(w * g(r, n) ** 2 for r, n, _, w in points)
        sfg = sum(w * f(r, n) * g(r, n) for r, n, _, w in points)
        sfy = sum(w * f(r, n) * y for r, n, y, w in points)
        sgy = sum(w * g(r, n) * y for r, n, y, w in points)
        det = sff * sgg - sfg * sfg
        return (sfy * sgg - sgy * sfg) / det, (sgy * sff - sfy * sfg) / det

    print("what the truth needs on the single-scattering lobe, %d points (F0 0.04, 0.08):" % len(points))
    for p in (1.0, 1.5, 2.0):
        c = sum(w * r ** p * y for r, _, y, w in points) / sum(w * r ** (2 * p) for r, _, _, w in points)
        largest = max(abs(y - c * r ** p) for r, _, y, _ in points)
        print("  c r^%.1f:              c = %.4f, rms %.4f, largest %.4f"
              % (p, c, rms(lambda r, n: c * r ** p), largest))
    for label, f, g in (("r (a + b (1 - NoV))", lambda r, n: r, lambda r, n: r * (1 - n)),
                        ("a r + b r^2", lambda r, n: r, lambda r, n: r * r)):
        a, b = fit2(f, g)
        print("  %-21s a = %.4f, b = %.4f, rms %.4f" % (label + ":", a, b,
                                                          rms(lambda r, n: a * f(r, n) + b * g(r, n))))
    print("\nthe build (MS %.4f): model / truth - 1 %% at NoV 1 / 0.8 / 0.6 / 0.4 / 0.2 / 0.1 (truth's stderr %%)" % ms)
    for (r, f0), measured in zip(grid, rows):
        print("  r %.1f F0 %.2f  %s" % (r, f0, " ".join("%+5.1f (%.1f)" % (100 * (m / t - 1), 100 * e / t)
                                                        for _, m, t, e in measured)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""A conductor under a tinted coat, against the Monte Carlo truth (issue 19,
step 14: SUBSTRATE_COAT_TOP_SPREAD and SUBSTRATE_COAT_ROUGH_PATH in
runtime_shaders/substrate_constants.h, substrate_closure_coat_specular).

The grid: a white conductor (F0 1) of roughness 0.05 / 0.2 / 0.4 / 0.7 under a
coat slab (F0 0.04) of roughness 0.1 / 0.2 / 0.3 / 0.4 / 0.6 / 0.8 / 1 whose
medium lets 0.7 or 0.4 through head-on (transmittance_to_mfp over 1e-4 mm,
as MaterialX's coat_color does). For each case `substratec accuracy --json`
gives the shipping model's directional albedo and the truth's at NoV 1 / 0.8 /
0.6 / 0.4 / 0.2 / 0.1; the script prints the relative errors, then per top
roughness their rms and the largest at NoV >= 0.2. With --before BIN it runs a
second build on the same truth samples and prints both side by side.

The constants were chosen by a scan over (TOP_SPREAD, ROUGH_PATH, the power of
f) with this grid as the objective (docs/accuracy.md, step 14); this script
checks the shipped build. Writes nothing but a temporary directory; about 12 s
per build on two cores at the default 16,384 walks per albedo.

usage: scripts/scan_tinted_coat.py [--bin BIN] [--before BIN] [--samples N] [--jobs J]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
TOPS = [0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0]
BASES = [0.05, 0.2, 0.4, 0.7]
TRANSMITTANCES = [0.7, 0.4]


def material(top, base, transmittance):
    return {
        "format": "substrate-material/1",
        "name": "tinted_coat",
        "nodes": {
            "medium": {"kind": "transmittance_to_mfp", "transmittance": transmittance, "thickness": 0.0001},
            "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": top, "sss_mfp": "medium.mfp"},
            "base": {"kind": "slab", "diffuse_albedo": 0, "f0": 1, "roughness": base},
            "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": 0.0001},
        },
        "output": "root",
    }


def errors(binary, path, samples):
    out = subprocess.run([binary, "accuracy", path, "--json", "--samples", str(samples), "--eval-samples", "4",
                          "-j", "1"], capture_output=True, text=True, check=True).stdout
    return [row["analytic"][0] / row["truth"][0] - 1 for row in json.loads(out)["rows"]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "bin", "substratec"))
    parser.add_argument("--before", help="a second substratec to compare (e.g. the previous commit's)")
    parser.add_argument("--samples", type=int, default=16384)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    builds = [("after", args.bin)] + ([("before", args.before)] if args.before else [])
    cases = [(t, b, tr) for t in TOPS for b in BASES for tr in TRANSMITTANCES]
    with tempfile.TemporaryDirectory() as tmp:
        paths = {}
        for case in cases:
            paths[case] = os.path.join(tmp, "coat_%s_%s_%s.json" % case)
            with open(paths[case], "w") as f:
                json.dump(material(*case), f)
        jobs = [(name, binary, case) for name, binary in builds for case in cases]
        with ThreadPoolExecutor(args.jobs) as pool:
            results = list(pool.map(lambda j: errors(j[1], paths[j[2]], args.samples), jobs))
    table = {(name, case): errs for (name, _, case), errs in zip(jobs, results)}

    def row(errs):
        return " ".join("%+6.1f" % (100 * e) for e in errs)

    print("top  base  T    | albedo error % at NoV 1 / 0.8 / 0.6 / 0.4 / 0.2 / 0.1")
    for case in cases:
        line = "%.2f %.2f  %.1f | " % case
        line += " | ".join("%s %s" % (name, row(table[(name, case)])) for name, _ in reversed(builds))
        print(line)
    print()
    print("top  | rms %, largest % at NoV >= 0.2")
    for top in TOPS:
        parts = []
        for name, _ in reversed(builds):
            errs = [table[(name, c)] for c in cases if c[0] == top]
            flat = [e for es in errs for e in es]
            rms = (sum(e * e for e in flat) / len(flat)) ** 0.5
            worst = max(abs(e) for es in errs for e in es[:5])
            parts.append("%s %.1f / %.1f" % (name, 100 * rms, 100 * worst))
        print("%.1f  | %s" % (top, " | ".join(parts)))
    print("cases: %d per build" % len(cases))
    return 0 if cases else 1


if __name__ == "__main__":
    sys.exit(main())

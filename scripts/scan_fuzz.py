#!/usr/bin/env python3
"""Every material with a fuzz, against the Monte Carlo truth (issue 19, step 16:
the diffuse under a fuzz, substrate_eval_closure in runtime_shaders/substrate_bsdf.h).

The materials: every example and control (bench/materials/, with --diffuse
lambert as bench/accuracy.sh runs them) whose file sets a `fuzz_amount`, and
every material of the MaterialX and glTF corpora (tests/import/corpus/) whose
`substratec import` sets one. For each, `substratec accuracy --json` gives the
shipping model's directional albedo against the truth's at NoV 1 / 0.8 / 0.6 /
0.4 / 0.2 / 0.1 and the white furnace; the script prints the relative errors
(luminance) and the lowest furnace, then how many materials meet issue 19's
goals (albedo within 5 % at NoV >= 0.2 and 8 % at 0.1; a white furnace of at
least 0.97), in all and per set (examples, controls, the MaterialX corpus, the
glTF corpus). With --before BIN it runs a second build on the same truth samples
and prints both. The corpora's textures read 0.5 (no image is bound). With
--all it takes every material of those sets, with a fuzz or not (issue 19,
step 17 measured the Fresnel curve of low-F0 interfaces on all of them).

Writes nothing but a temporary directory; about 45 s per build on two cores at
the default 32,768 walks per albedo (the truth is cached between builds), about
7 minutes per build with --all (565 materials).

usage: scripts/scan_fuzz.py [--bin BIN] [--before BIN] [--samples N] [--jobs J] [--all]
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SETS = ("examples", "controls", "MaterialX corpus", "glTF corpus")


def sets_fuzz(path):
    with open(path) as f:
        return '"fuzz_amount"' in f.read()


def cases(binary, tmp, every):
    """(label, file, extra accuracy arguments, set) for every material with a fuzz (every one with `every`);
    set is one of SETS."""
    out = []
    selected = (lambda path: True) if every else sets_fuzz
    for path in sorted(glob.glob(os.path.join(ROOT, "examples", "*.json"))):
        if selected(path):
            out.append((os.path.basename(path)[:-5], path, [], "examples"))
    for path in sorted(glob.glob(os.path.join(ROOT, "bench", "materials", "*.json"))):
        if selected(path):
            out.append((os.path.basename(path)[:-5], path, ["--diffuse", "lambert"], "controls"))
    corpus = sorted(glob.glob(os.path.join(ROOT, "tests", "import", "corpus", "materialx", "**", "*.mtlx"),
                              recursive=True))
    corpus += sorted(glob.glob(os.path.join(ROOT, "tests", "import", "corpus", "gltf", "*.materials.json")))
    for i, path in enumerate(corpus):
        target = os.path.join(tmp, "import%d" % i)
        if subprocess.run([binary, "import", path, "-o", target], capture_output=True).returncode != 0:
            continue
        stem = os.path.basename(path).split(".")[0]
        kind = "MaterialX corpus" if path.endswith(".mtlx") else "glTF corpus"
        for imported in sorted(glob.glob(os.path.join(target, "*.json"))):
            if selected(imported):
                with open(imported) as f:
                    name = json.load(f)["name"]
                out.append(("%s / %s" % (stem, name), path, ["--material", name], kind))
    return out


def measure(binary, case, samples):
    _, path, extra, _ = case
    run = subprocess.run([binary, "accuracy", path, "--json", "--samples", str(samples), "--eval-samples", "256",
                          "-j", "1"] + extra, capture_output=True, text=True)
    if run.returncode != 0:
        return None
    report = json.loads(run.stdout)
    if report.get("domain") == "volume":  # a fog's march has no albedo to compare (issue 22)
        return "volume"
    rows = report["rows"]

    def luminance(v):
        return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]

    return [r["rel_error"] for r in rows], min(luminance(r["furnace_analytic"]) for r in rows)


def meets_goal(result):
    errs, furnace = result
    return all(abs(e) <= 0.05 for e in errs[:-1]) and abs(errs[-1]) <= 0.08, furnace >= 0.97


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "bin", "substratec"))
    parser.add_argument("--before", help="a second substratec to compare (e.g. the previous commit's)")
    parser.add_argument("--samples", type=int, default=32768)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--all", action="store_true", help="every material, not only those with a fuzz")
    args = parser.parse_args()
    builds = ([("before", args.before)] if args.before else []) + [("after", args.bin)]
    with tempfile.TemporaryDirectory() as tmp:
        found = cases(args.bin, tmp, args.all)
        jobs = [(name, binary, case) for name, binary in builds for case in found]
        with ThreadPoolExecutor(args.jobs) as pool:
            results = list(pool.map(lambda j: measure(j[1], j[2], args.samples), jobs))
    table = {(name, case[0]): result for (name, _, case), result in zip(jobs, results)}
    volumes = sorted({case[0] for (_, _, case), result in zip(jobs, results) if result == "volume"})
    found = [case for case in found if case[0] not in volumes]

    print("material | %s: albedo error %% at NoV 1 / 0.8 / 0.6 / 0.4 / 0.2 / 0.1, lowest furnace"
          % " | ".join(name for name, _ in builds))
    for case in found:
        parts = []
        for name, _ in builds:
            result = table[(name, case[0])]
            parts.append("error" if result is None else
                         "%s  %.3f" % (" ".join("%+5.1f" % (100 * e) for e in result[0]), result[1]))
        print("%s | %s" % (case[0], " | ".join(parts)))
    print()
    if volumes:
        print("left out, volume materials (a march, no albedo): %s" % ", ".join(volumes))
    for name, _ in builds:
        measured = [table[(name, c[0])] for c in found if table[(name, c[0])] is not None]
        goals = [meets_goal(r) for r in measured]
        print("%s: %d materials measured; albedo within the goal %d, furnace >= 0.97 %d" %
              (name, len(measured), sum(g[0] for g in goals), sum(g[1] for g in goals)))
        for kind in SETS:  # the goal names each set
            of_set = [c for c in found if c[3] == kind]
            got = [table[(name, c[0])] for c in of_set if table[(name, c[0])] is not None]
            if of_set:
                print("  %s: %d of %d measured, albedo within the goal %d" %
                      (kind, len(got), len(of_set), sum(meets_goal(r)[0] for r in got)))
    return 0 if found and all(table[(name, c[0])] is not None for name, _ in builds for c in found) else 1


if __name__ == "__main__":
    sys.exit(main())

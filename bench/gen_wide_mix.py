#!/usr/bin/env python3
"""Writes the widest material the limits allow (bench/wide_mix.sh; issue 16, severe 6).

Usage: gen_wide_mix.py OUT_FILE [SLABS] [SEED] [--constant | --mix-inputs]   (default 512 slabs, seed 16)

SLABS slabs (a power of two) mixed in pairs: a balanced tree of `horizontal`
nodes, SLABS - 1 of them, so 512 slabs make 1023 tree nodes, one under the
tree-size limit of 1024. Every slab has its own diffuse albedo, F0 and
roughness; by default every mix weight and every slab's diffuse albedo is an
input (1023 inputs for 512 slabs, one under the input-count limit of 1024):
runtime parameters keep the simplifier from folding the blends into
constants, so the generated code grows with the tree. --constant writes
every value as a literal (the blends fold); --mix-inputs makes only the mix
weights and every tenth slab's roughness inputs (563 for 512 slabs).
Deterministic for a seed.
"""
import json
import random
import sys


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    constant = "--constant" in argv
    mixInputs = "--mix-inputs" in argv
    out = args[0]
    slabs = int(args[1]) if len(args) > 1 else 512
    rng = random.Random(int(args[2]) if len(args) > 2 else 16)
    if slabs < 2 or slabs & (slabs - 1):
        sys.exit("SLABS must be a power of two >= 2")
    inputs, nodes = {}, {}

    def value(name, kind, v):
        if constant or (mixInputs and not name.startswith(("w_", "rough"))):
            return v
        inputs[name] = {"type": kind, "default": v, "min": 0, "max": 1}
        return "$" + name

    level = []
    for i in range(slabs):
        albedo = [round(rng.uniform(0.05, 0.95), 3) for _ in range(3)]
        nodes["s%d" % i] = {
            "kind": "slab",
            "diffuse_albedo": value("albedo%d" % i, "color", albedo),
            "f0": round(rng.uniform(0.02, 0.08), 3),
            "roughness": round(rng.uniform(0.1, 0.9), 3),
        }
        if mixInputs and i % 10 == 0:
            nodes["s%d" % i]["roughness"] = value("rough%d" % i, "float", nodes["s%d" % i]["roughness"])
        level.append("s%d" % i)
    depth = 0
    while len(level) > 1:
        nxt = []
        for j in range(0, len(level), 2):
            key = "m%d_%d" % (depth, j // 2)
            nodes[key] = {"kind": "horizontal", "background": level[j], "foreground": level[j + 1],
                          "mix": value("w_" + key, "float", round(rng.uniform(0.2, 0.8), 3))}
            nxt.append(key)
        level = nxt
        depth += 1
    doc = {"format": "substrate-material/1", "name": "wide_mix_%d" % slabs,
           "description": "%d slabs mixed in pairs (bench/gen_wide_mix.py)" % slabs,
           "inputs": inputs, "nodes": nodes, "output": level[0]}
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main(sys.argv)

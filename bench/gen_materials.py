#!/usr/bin/env python3
"""Writes N generated substrate-material/1 files into OUT_DIR (bench/compile_throughput.sh).

Usage: gen_materials.py OUT_DIR [N] [SEED]   (default 1000 materials, seed 9)

Deterministic for a seed. Each material is one of five shapes, in turn: a
slab; a horizontal mix of two slabs; a coat over a slab; a coat over a mix of
two slabs; a weighted coat over a slab with a select of two more below it. Slab
parameters are constants or inputs (drawn in their legal ranges), and each slab
uses each opt-in feature (F90, anisotropy, SSS, haze, fuzz, glint) with a small
probability, so the set spans every layout class and budget like the examples.
"""
import json
import random
import sys
from pathlib import Path


def main(argv):
    out = Path(argv[1])
    count = int(argv[2]) if len(argv) > 2 else 1000
    rng = random.Random(int(argv[3]) if len(argv) > 3 else 9)
    out.mkdir(parents=True, exist_ok=True)
    for i in range(count):
        name = "gen_%05d" % i
        inputs = {}

        def value(kind, lo=0.0, hi=1.0):
            """A constant, or (one time in three) an input with that default."""
            if kind == "color":
                v = [round(rng.uniform(lo, hi), 3) for _ in range(3)]
            else:
                v = round(rng.uniform(lo, hi), 3)
            if rng.random() < 1 / 3:
                key = "p%d" % len(inputs)
                inputs[key] = {"type": kind, "default": v, "min": lo, "max": hi}
                return "$" + key
            return v

        def slab():
            s = {"kind": "slab", "diffuse_albedo": value("color"), "f0": value("color", 0.02, 0.1),
                 "roughness": value("float", 0.05, 1.0)}
            if rng.random() < 0.2:
                s["f90"] = value("color", 0.5, 1.0)
            if rng.random() < 0.15:
                s["anisotropy"] = value("float", -0.9, 0.9)
            if rng.random() < 0.15:
                s["sss_mfp"] = [round(rng.uniform(0.0005, 0.01), 4) for _ in range(3)]
            if rng.random() < 0.2:
                s["second_roughness"] = value("float", 0.3, 1.0)
                s["second_roughness_weight"] = value("float", 0.1, 0.9)
            if rng.random() < 0.15:
                s["fuzz_amount"] = value("float", 0.1, 1.0)
                s["fuzz_color"] = value("color")
            if rng.random() < 0.05:
                s["glint_value"] = value("float", 0.2, 0.9)
            return s

        def coat():
            return {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": value("float", 0.02, 0.3),
                    "sss_mfp": 10}

        shape = i % 5
        nodes = {}
        if shape == 0:
            nodes["root"] = slab()
        elif shape == 1:
            nodes.update(a=slab(), b=slab())
            nodes["root"] = {"kind": "horizontal", "background": "a", "foreground": "b", "mix": value("float", 0.1, 0.9)}
        elif shape == 2:
            nodes.update(top=coat(), base=slab())
            nodes["root"] = {"kind": "vertical", "top": "top", "base": "base", "thickness": 0.0001}
        elif shape == 3:
            nodes.update(top=coat(), a=slab(), b=slab())
            nodes["mix"] = {"kind": "horizontal", "background": "a", "foreground": "b", "mix": value("float", 0.1, 0.9)}
            nodes["root"] = {"kind": "vertical", "top": "top", "base": "mix", "thickness": 0.0002}
        else:
            nodes.update(top=coat(), a=slab(), b=slab())
            nodes["worn"] = {"kind": "coverage_weight", "a": "top", "weight": value("float", 0.2, 0.9)}
            nodes["pick"] = {"kind": "select", "a": "a", "b": "b", "value": value("float"), "threshold": 0.5}
            nodes["root"] = {"kind": "vertical", "top": "worn", "base": "pick", "thickness": 0.0001}
        doc = {"format": "substrate-material/1", "name": name, "inputs": inputs, "nodes": nodes, "output": "root"}
        (out / (name + ".json")).write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

#!/usr/bin/env python3
"""Checks schema/substrate-material.schema.json and every examples/*.json (and tests/blocks/*.json) against it.

Usage: check_schema.py [REPO_ROOT]   (default: two directories above this script)

1. The schema itself is a valid JSON Schema draft 2020-12 document.
2. Every examples/*.json (globbed at run time) is strict JSON (no NaN/Infinity),
   validates, and has "name" equal to its file stem.
3. A valid in-script document validates, and each negative variant of it is
   rejected, with an error at the expected JSON pointer.

Prints one line per check and a final line "N passed, M failed"; exits 0 only if
nothing failed. Needs only the standard library and jsonschema (Debian 12 ships
4.10: only Draft202012Validator and in-file "#/$defs/..." refs are used).
"""
import copy
import json
import sys
from pathlib import Path

import jsonschema
from jsonschema.exceptions import best_match

SCHEMA_REL = Path("schema") / "substrate-material.schema.json"


def pointer(path):
    """JSON pointer of an error path (a deque of keys and indices)."""
    return "/" + "/".join(str(p).replace("~", "~0").replace("/", "~1") for p in path)


def reject_constant(name):
    raise ValueError("%s is not a JSON number" % name)


def load_strict(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f, parse_constant=reject_constant)


# A small valid document; the negatives below are mutations of it.
BASE = {
    "format": "substrate-material/1",
    "name": "negative_base",
    "inputs": {
        "mask": {"type": "float", "default": 0.5, "min": 0, "max": 1},
        "tint": {"type": "color", "default": 0.5},
        "albedo": {"type": "texture2d", "colorspace": "srgb"},
    },
    "nodes": {
        "albedo_tex": {"kind": "texture", "texture": "$albedo"},
        "root": {
            "kind": "slab",
            "diffuse_albedo": "albedo_tex.rgb",
            "roughness": 0.5,
            "f0": {"kind": "ior_to_f0", "ior": 1.5},
        },
    },
    "output": "root",
}


def mutate(fn):
    doc = copy.deepcopy(BASE)
    fn(doc)
    return doc


def _set(path, value):
    def fn(doc):
        d = doc
        for key in path[:-1]:
            d = d[key]
        d[path[-1]] = value
    return fn


def _del(path):
    def fn(doc):
        d = doc
        for key in path[:-1]:
            d = d[key]
        del d[path[-1]]
    return fn


# (description, mutation, JSON pointer the best error must be at or under)
NEGATIVES = [
    ("unknown top-level key", _set(["colour"], "red"), "/"),
    ("wrong format string", _set(["format"], "substrate-material/2"), "/format"),
    ("missing output", _del(["output"]), "/"),
    ("slab with roughness 2", _set(["nodes", "root", "roughness"], 2), "/nodes/root/roughness"),
    ("slab with anisotropy -1.5", _set(["nodes", "root", "anisotropy"], -1.5), "/nodes/root/anisotropy"),
    ("slab with a negative sss_mfp channel",
     _set(["nodes", "root", "sss_mfp"], [0.004, -0.002, 0.001]), "/nodes/root/sss_mfp"),
    ("slab with an unknown pin", _set(["nodes", "root", "glossiness"], 0.5), "/nodes/root"),
    ("float input without default", _del(["inputs", "mask", "default"]), "/inputs/mask"),
    ("color input with a 2-number default", _set(["inputs", "tint", "default"], [1, 2]), "/inputs/tint/default"),
    ("texture2d input with a default", _set(["inputs", "albedo", "default"], 0.5), "/inputs/albedo"),
    ("name that is not a C identifier", _set(["name"], "3-coat"), "/name"),
    ("node id that is not a C identifier",
     _set(["nodes", "bad-id"], {"kind": "saturate", "x": 1}), "/nodes"),
    ("unknown node kind", _set(["nodes", "extra"], {"kind": "blur", "x": 1}), "/nodes/extra/kind"),
    ("binary op missing pin b", _set(["nodes", "extra"], {"kind": "multiply", "a": 1}), "/nodes/extra"),
    ("input reference on a Substrate pin",
     _set(["nodes", "top"], {"kind": "vertical", "top": "$mask", "base": "root"}), "/nodes/top/top"),
    ("horizontal mix literal out of [0,1]",
     _set(["nodes", "h"], {"kind": "horizontal", "background": "root", "foreground": "root", "mix": 1.5}),
     "/nodes/h/mix"),
    ("coated_layer without its base",
     _set(["nodes", "c"], {"kind": "coated_layer", "coat_roughness": 0.1}), "/nodes/c"),
    ("ue4_default_lit with metallic 2",
     _set(["nodes", "u"], {"kind": "ue4_default_lit", "metallic": 2}), "/nodes/u/metallic"),
    ("gltf_pbr with an unknown alpha_mode",
     _set(["nodes", "g"], {"kind": "gltf_pbr", "alpha_mode": "maybe"}), "/nodes/g/alpha_mode"),
    ("unknown settings key", _set(["settings"], {"bytes_per_pixel": 80, "budget": 3}), "/settings"),
    ("bytes_per_pixel out of range", _set(["settings"], {"bytes_per_pixel": 4}), "/settings/bytes_per_pixel"),
]


def main(argv):
    root = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parent.parent.parent
    passed = failed = 0

    def report(ok, what, detail=""):
        nonlocal passed, failed
        if ok:
            passed += 1
        else:
            failed += 1
        print("%s %s%s" % ("PASS" if ok else "FAIL", what, (": " + detail) if detail else ""))

    schema_path = root / SCHEMA_REL
    try:
        schema = load_strict(schema_path)
        jsonschema.Draft202012Validator.check_schema(schema)
    except Exception as e:  # noqa: BLE001 - any failure here is reported, then we stop
        report(False, str(SCHEMA_REL), "%s: %s" % (type(e).__name__, getattr(e, "message", e)))
        print("%d passed, %d failed" % (passed, failed))
        return 1
    report(True, str(SCHEMA_REL), "valid draft 2020-12 schema")
    validator = jsonschema.Draft202012Validator(schema)

    def first_error(doc):
        errors = list(validator.iter_errors(doc))
        return best_match(errors) if errors else None

    examples = sorted((root / "examples").glob("*.json"))
    if not examples:
        report(False, "examples/*.json", "no examples found")
    for path in examples:
        rel = path.relative_to(root)
        try:
            doc = load_strict(path)
        except ValueError as e:
            report(False, str(rel), "not strict JSON: %s" % e)
            continue
        err = first_error(doc)
        if err is not None:
            report(False, str(rel), "%s: %s" % (pointer(err.absolute_path), err.message))
        elif isinstance(doc, dict) and doc.get("name") != path.stem:
            report(False, str(rel), "name %r is not the file stem %r" % (doc.get("name"), path.stem))
        else:
            report(True, str(rel))

    # The building blocks' expansion inputs (tests/blocks: one per block kind).
    blocks = sorted((root / "tests" / "blocks").glob("*.json"))
    if not blocks:
        report(False, "tests/blocks/*.json", "no building-block inputs found")
    for path in blocks:
        rel = path.relative_to(root)
        err = first_error(load_strict(path))
        report(err is None, str(rel), "" if err is None else "%s: %s" % (pointer(err.absolute_path), err.message))

    err = first_error(BASE)
    report(err is None, "negative: base document is valid",
           "" if err is None else "%s: %s" % (pointer(err.absolute_path), err.message))

    for what, fn, where in NEGATIVES:
        err = first_error(mutate(fn))
        if err is None:
            report(False, "negative: " + what, "was accepted")
            continue
        at = pointer(err.absolute_path)
        ok = where == "/" or at == where or at.startswith(where + "/")
        report(ok, "negative: " + what, "rejected at %s: %s" % (at, err.message)
               + ("" if ok else " (expected at %s)" % where))

    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))

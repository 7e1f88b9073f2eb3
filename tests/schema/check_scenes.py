#!/usr/bin/env python3
"""Checks the scene and platform schemas and the files under examples/ that use them.

Usage: check_scenes.py [REPO_ROOT]   (default: two directories above this script)

1. schema/substrate-scene.schema.json and schema/substrate-platforms.schema.json
   are valid JSON Schema draft 2020-12 documents.
2. Every examples/scenes/*.json validates against the scene schema, names only
   material files that exist, and every examples/scenes/materials/*.json
   validates against the material schema with "name" equal to its file stem.
3. Every examples/platforms/*.json validates against the platforms schema.
4. Negative variants of a valid scene and of a valid platform table are
   rejected, each with an error at the expected JSON pointer.

Prints one line per check and "N passed, M failed"; exits 0 only if nothing failed.
"""
import copy
import sys
from pathlib import Path

import jsonschema
from jsonschema.exceptions import best_match

from check_schema import load_strict, pointer

SCENE = {"format": "substrate-scene/1", "name": "negative_scene", "platform": "mobile",
         "materials": ["../row12_simple.json", "materials/plaster.json"]}
PLATFORMS = {"format": "substrate-platforms/1",
             "platforms": {"handheld": {"extends": "mobile", "bytes_per_pixel": 28, "features": ["f90", "fuzz"]}}}

# (what, document, mutation, JSON pointer the best error must be at or under)
NEGATIVES = [
    ("scene: unknown key", SCENE, lambda d: d.update(lights=[]), "/"),
    ("scene: wrong format", SCENE, lambda d: d.update(format="substrate-scene/2"), "/format"),
    ("scene: no materials", SCENE, lambda d: d.update(materials=[]), "/materials"),
    ("scene: a material twice", SCENE, lambda d: d["materials"].append("materials/plaster.json"), "/materials"),
    ("scene: a number for a material", SCENE, lambda d: d["materials"].append(3), "/materials/2"),
    ("scene: name not an identifier", SCENE, lambda d: d.update(name="my scene"), "/name"),
    ("scene: name with __", SCENE, lambda d: d.update(name="a__b"), "/name"),
    ("platforms: unknown feature", PLATFORMS,
     lambda d: d["platforms"]["handheld"].update(features=["sheen"]), "/platforms/handheld/features/0"),
    ("platforms: budget below 8", PLATFORMS,
     lambda d: d["platforms"]["handheld"].update(bytes_per_pixel=4), "/platforms/handheld/bytes_per_pixel"),
    ("platforms: 9 closures", PLATFORMS,
     lambda d: d["platforms"]["handheld"].update(max_closures=9), "/platforms/handheld/max_closures"),
    ("platforms: unknown platform key", PLATFORMS,
     lambda d: d["platforms"]["handheld"].update(budget=3), "/platforms/handheld"),
    ("platforms: bad platform name", PLATFORMS, lambda d: d["platforms"].update({"Big PC": {}}), "/platforms"),
]


def main(argv):
    root = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parent.parent.parent
    passed = failed = 0

    def report(ok, what, detail=""):
        nonlocal passed, failed
        passed += ok
        failed += not ok
        print("%s %s%s" % ("PASS" if ok else "FAIL", what, (": " + detail) if detail else ""))

    validators = {}
    for kind in ("scene", "platforms", "material"):
        rel = Path("schema") / ("substrate-%s.schema.json" % kind)
        schema = load_strict(root / rel)
        jsonschema.Draft202012Validator.check_schema(schema)
        validators[kind] = jsonschema.Draft202012Validator(schema)
        report(True, str(rel), "valid draft 2020-12 schema")

    def first_error(kind, doc):
        errors = list(validators[kind].iter_errors(doc))
        return best_match(errors) if errors else None

    def check_file(kind, path, extra=None):
        rel = path.relative_to(root)
        try:
            doc = load_strict(path)
        except ValueError as e:
            report(False, str(rel), "not strict JSON: %s" % e)
            return
        err = first_error(kind, doc)
        problem = "%s: %s" % (pointer(err.absolute_path), err.message) if err else (extra(doc) if extra else "")
        report(not problem, str(rel), problem)

    def scene_files_exist(path):
        def check(doc):
            missing = [m for m in doc["materials"] if not (path.parent / m).is_file()]
            return "missing material files: %s" % ", ".join(missing) if missing else ""
        return check

    scenes = sorted((root / "examples" / "scenes").glob("*.json"))
    report(bool(scenes), "examples/scenes/*.json", "" if scenes else "no scenes found")
    for path in scenes:
        check_file("scene", path, scene_files_exist(path))
    for path in sorted((root / "examples" / "scenes" / "materials").glob("*.json")):
        check_file("material", path,
                   lambda doc, p=path: "" if doc.get("name") == p.stem else "name is not the file stem")
    platforms = sorted((root / "examples" / "platforms").glob("*.json"))
    report(bool(platforms), "examples/platforms/*.json", "" if platforms else "no platform tables found")
    for path in platforms:
        check_file("platforms", path)

    for kind, base in (("scene", SCENE), ("platforms", PLATFORMS)):
        err = first_error(kind, base)
        report(err is None, "negative: the base %s document is valid" % kind,
               "" if err is None else "%s: %s" % (pointer(err.absolute_path), err.message))
    for what, base, fn, where in NEGATIVES:
        doc = copy.deepcopy(base)
        fn(doc)
        err = first_error("scene" if base is SCENE else "platforms", doc)
        if err is None:
            report(False, "negative: " + what, "was accepted")
            continue
        at = pointer(err.absolute_path)
        ok = where == "/" or at == where or at.startswith(where + "/")
        report(ok, "negative: " + what, "rejected at %s: %s" % (at, err.message) + ("" if ok else " (expected at %s)" % where))

    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))

#!/usr/bin/env python3
"""Validates every tests/golden/*.expected.layout.json against
schema/substrate-layout.schema.json, and checks each file's arithmetic
(offsets contiguous, words = ceil(bits/32), bytes = 4*words + 4 top-layer bytes,
or 4*words for a VOLUME layout's froxel, which has no top layer)."""
import glob, json, os, sys

import jsonschema

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
schema = json.load(open(os.path.join(root, "schema", "substrate-layout.schema.json")))
jsonschema.Draft202012Validator.check_schema(schema)
validator = jsonschema.Draft202012Validator(schema)
passed = failed = 0
files = sorted(glob.glob(os.path.join(root, "tests", "golden", "*.expected.layout.json")))
for path in files:
    doc = json.load(open(path))
    problems = [e.message for e in validator.iter_errors(doc)]
    offset = 0
    for f in doc.get("fields", []):
        if f["offset"] != offset or f["word"] != offset // 32 or f["shift"] != offset % 32:
            problems.append(f"field {f['name']} is not at offset {offset}")
        offset += f["bits"]
    top = 0 if doc.get("layout") == "VOLUME" else 4
    if doc.get("top_layer", {}).get("bits") != 8 * top:
        problems.append("the top-layer word is not what the layout class says")
    if offset != doc.get("bits") or doc.get("words") != (offset + 31) // 32 or doc.get("bytes_per_pixel") != 4 * doc.get("words", 0) + top:
        problems.append("bits/words/bytes do not add up")
    name = os.path.basename(path)
    if problems:
        failed += 1
        print(f"FAIL {name}: {problems[0]}")
    else:
        passed += 1
        print(f"PASS {name}")
if not files:
    failed += 1
    print("FAIL no layout goldens found")
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)

#!/usr/bin/env python3
"""Every imported material (tests/import/golden/**/*.json) validates against
schema/substrate-material.schema.json: the importers write the format, not a
dialect the compiler happens to accept.

Usage: check_golden_schema.py [REPO_ROOT]   (default: two directories above this script)
Exits 0 only when every file validates; prints the first error of each that does not.
"""
import json
import sys
from pathlib import Path

import jsonschema


def main():
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2]
    schema = json.loads((root / "schema" / "substrate-material.schema.json").read_text(encoding="utf-8"))
    validator = jsonschema.Draft202012Validator(schema)
    files = sorted((root / "tests" / "import" / "golden").rglob("*.json"))
    failed = 0
    for f in files:
        doc = json.loads(f.read_text(encoding="utf-8"))
        error = next(iter(validator.iter_errors(doc)), None)
        if error is not None:
            failed += 1
            where = "/" + "/".join(str(p) for p in error.absolute_path)
            print(f"FAIL {f.relative_to(root)}: {where}: {error.message[:200]}")
    print(f"{len(files) - failed} passed, {failed} failed")
    return 0 if files and failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())

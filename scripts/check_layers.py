#!/usr/bin/env python3
"""The layering check (ctest layering_includes): every `#include "x/..."` in
compiler/ names its own floor or one below it, as compiler/floors.txt says.

compiler/floors.txt is the one table of floors (CMake builds one target per
floor from it, linked only downward). A floor may include the floors it names
and, through them, every floor below those. The check fails naming file:line
and the wrong-way edge, on an include that names no floor's folder, on a
source file in no floor, on a table that is not bottom-up (a floor naming one
not defined above it), and when it checked no include at all. It runs its
self-test first: a known-bad include must be caught, a good one let through.

Usage: check_layers.py <repo root>     (the self-test, then the tree)
       check_layers.py --self-test
"""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
SOURCE_SUFFIXES = {".h", ".hpp", ".cc", ".cpp", ".inc"}
INCLUDE_ROOTS = ("core", "tools", "")  # compiler/core, compiler/tools, compiler (CMake's include path)


def parse_floors(text):
    """floors.txt -> ([floor names bottom-up], {floor: [folders]}, {floor: [floors right below]}).
    Raises ValueError on a malformed or not bottom-up table."""
    order, dirs, below = [], {}, {}
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        fields = [f.split() for f in line.split("|")]
        if len(fields) != 3 or len(fields[0]) != 1 or not fields[1]:
            raise ValueError(f"floors.txt:{n}: expected 'floor | folders | lower floors'")
        name = fields[0][0]
        if name in dirs:
            raise ValueError(f"floors.txt:{n}: floor {name} twice")
        for b in fields[2]:
            if b not in dirs:
                raise ValueError(f"floors.txt:{n}: {name} names {b}, which is not a floor defined above it")
        order.append(name)
        dirs[name] = fields[1]
        below[name] = fields[2]
    return order, dirs, below


def allowed_floors(order, below):
    """floor -> every floor it may include (itself and all below, transitively)."""
    allowed = {}
    for f in order:  # bottom-up, so the floors below are done
        allowed[f] = {f}.union(*(allowed[b] for b in below[f]))
    return allowed


def floor_of_folder(dirs):
    return {d: f for f, ds in dirs.items() for d in ds}


def floor_of_path(rel, folders):
    """The floor of a path relative to compiler/ (its folder), or None."""
    parent = str(pathlib.PurePosixPath(rel).parent)
    return folders.get(parent)


def check(floors_text, files):
    """files: {path relative to compiler/: text}. Returns (includes checked, [errors])."""
    order, dirs, below = parse_floors(floors_text)
    allowed = allowed_floors(order, below)
    folders = floor_of_folder(dirs)
    checked, errors = 0, []
    for rel in sorted(files):
        own = floor_of_path(rel, folders)
        if own is None:
            errors.append(f"compiler/{rel}: in no floor of compiler/floors.txt")
            continue
        for n, line in enumerate(files[rel].splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or "/" not in m.group(1):
                continue  # a file of its own folder or of runtime_shaders/
            inc = m.group(1)
            target = None
            for root in INCLUDE_ROOTS:
                folder = str(pathlib.PurePosixPath(root, inc).parent)
                if folder in folders:
                    target = folders[folder]
                    break
            checked += 1
            if target is None:
                errors.append(f"compiler/{rel}:{n}: #include \"{inc}\" names no floor's folder")
            elif target not in allowed[own]:
                errors.append(f"compiler/{rel}:{n}: {own} -> {target} (#include \"{inc}\") points the wrong way: "
                              f"{own} may include {', '.join(f for f in order if f in allowed[own])}")
    return checked, errors


SELF_TEST_FLOORS = """# a three-floor house
low  | core/low            |
mid  | core/mid core/mid2  | low
top  | tools/top           | mid
"""


def self_test():
    """Known-good and known-bad inputs: returns the number of cases, raises on a miss."""
    cases = [
        ({"core/mid/a.cc": '#include "low/x.h"\n#include "mid2/y.h"\n#include "a_local.h"\n'}, 2, []),
        ({"tools/top/t.cc": '#include "low/x.h"\n'}, 1, []),  # two floors down, through mid
        ({"core/low/x.h": '// ok\n#include "mid/a.h"\n'}, 1,
         ["compiler/core/low/x.h:2: low -> mid (#include \"mid/a.h\") points the wrong way: low may include low"]),
        ({"core/mid2/y.cc": '  #  include "top/t.h"\n'}, 1,
         ["compiler/core/mid2/y.cc:1: mid -> top (#include \"top/t.h\") points the wrong way: "
          "mid may include low, mid"]),
        ({"core/mid/a.cc": '#include "nowhere/z.h"\n'}, 1,
         ["compiler/core/mid/a.cc:1: #include \"nowhere/z.h\" names no floor's folder"]),
        ({"core/stray/s.cc": '#include "low/x.h"\n'}, 0, ["compiler/core/stray/s.cc: in no floor of compiler/floors.txt"]),
    ]
    for files, want_checked, want_errors in cases:
        got_checked, got_errors = check(SELF_TEST_FLOORS, files)
        if (got_checked, got_errors) != (want_checked, want_errors):
            raise AssertionError(f"self-test: {files}: got {got_checked} {got_errors}, want {want_checked} {want_errors}")
    for bad in ("a | core/a | b\nb | core/b |\n", "a | core/a |\na | core/b |\n", "a | | \n"):
        try:
            parse_floors(bad)
        except ValueError:
            continue
        raise AssertionError(f"self-test: the table {bad!r} was accepted")
    return len(cases) + 3


def main(argv):
    n = self_test()
    print(f"check_layers: self-test: {n} cases (wrong-way includes, unknown folders, stray files, bad tables) pass")
    if argv[1:] == ["--self-test"]:
        return 0
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    compiler = pathlib.Path(argv[1]) / "compiler"
    floors_text = (compiler / "floors.txt").read_text()
    files = {p.relative_to(compiler).as_posix(): p.read_text(errors="replace")
             for p in sorted(compiler.rglob("*")) if p.suffix in SOURCE_SUFFIXES and p.is_file()}
    checked, errors = check(floors_text, files)
    # The CMake side: every floor of the table is built by substratec_floor().
    cmake = (compiler / "CMakeLists.txt").read_text()
    order, _, _ = parse_floors(floors_text)
    for f in order:
        if not re.search(rf"substratec_floor\({f}\b", cmake):
            errors.append(f"compiler/CMakeLists.txt: floor {f} of compiler/floors.txt has no substratec_floor({f} ...)")
    for e in errors:
        print(e)
    print(f"check_layers: {checked} includes in {len(files)} files over {len(order)} floors checked, "
          f"{len(errors)} wrong")
    if checked == 0:
        print("check_layers: no include checked: is the path right?")
        return 1
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

#!/usr/bin/env python3
"""Functions over 80 lines in compiler/ (ctest long_functions): each carries a
comment with `long:` and the reason in the 3 lines before its definition, or
is listed in tests/long_functions_allowlist.txt (`path:function`, one a line,
the offenders of the day the check came in; to be emptied as they are split).

A heuristic, not a parser: a definition is a line starting in column 0 (the
style does not indent namespace bodies) that is not a declaration, type,
namespace, variable or preprocessor line, whose header has a parameter list
and ends in `{`; its length runs from the header's first line to the matching
`}` (braces in comments, strings and character literals skipped). Member
functions defined inside a class body are not seen.

Prints every function over the limit, the count, and fails on one that has
neither `long:` nor an allowlist entry, or when it found no function at all.
Runs its self-test first. Usage: check_long_functions.py <repo root> | --self-test
"""
import pathlib
import re
import sys

LIMIT = 80
SOURCE_SUFFIXES = {".h", ".cc"}
NOT_FUNCTION = re.compile(r"^(namespace|class|struct|enum|union|using|typedef|extern\s+\"C\"|#|//|/\*|\*|\}|template\s*<[^>]*>\s*$)")
NAME = re.compile(r"((?:[A-Za-z_~][\w]*::)*(?:operator\s*[^\s(]+|~?[A-Za-z_]\w*))\s*\(")


def blank_literals(text):
    """The text with comments, string and character literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(c)  # a digit separator (1'000)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """[(name, first line, lines, has `long:`)] of the column-0 definitions."""
    raw = text.splitlines()
    code = blank_literals(text).splitlines()
    found, i = [], 0
    while i < len(code):
        line = code[i]
        if not line or line[0].isspace() or NOT_FUNCTION.match(line) or not raw[i].strip():
            i += 1
            continue
        # The header: up to the first `{` or `;` at this point.
        start, header, j = i, "", i
        while j < len(code):
            header += code[j] + "\n"
            if "{" in code[j] or ";" in code[j]:
                break
            j += 1
        brace, semi = header.find("{"), header.find(";")
        head = header[:brace] if brace >= 0 else ""
        if brace < 0 or (0 <= semi < brace) or "(" not in head or "=" in head.split("(")[0]:
            i = j + 1
            continue
        # Match the braces from the header's `{`.
        depth, k, col = 0, j, code[j].find("{")
        end = None
        while k < len(code) and end is None:
            segment = code[k][col:] if k == j else code[k]
            for ch in segment:
                if ch == "{":
                    depth += 1
                elif ch == "}":
                    depth -= 1
                    if depth == 0:
                        end = k
                        break
            k += 1
        if end is None:
            break
        lines = end - start + 1
        m = NAME.search(re.sub(r"^template\s*<[^>]*>\s*", "", head.strip()))
        name = m.group(1).replace(" ", "") if m else head.split("(")[0].split()[-1]
        reason = any("long:" in raw[x] for x in range(max(0, start - 3), start))
        found.append((name, start + 1, lines, reason))
        i = end + 1
    return found


def long_functions(text, limit=LIMIT):
    """The functions over `limit` lines."""
    return [f for f in functions(text) if f[2] > limit]


def self_test():
    body = "".join(f"  x += {n};\n" for n in range(LIMIT))
    cases = [
        (f"int f(int x) {{\n{body}  return x;\n}}\n", [("f", 1, LIMIT + 3, False)]),
        (f"// long: one table, read straight down.\nint A::g() const {{\n{body}}}\n", [("A::g", 2, LIMIT + 2, True)]),
        (f"namespace n {{\nstatic void h(\n    int a) {{\n  const char* s = \"}}\";\n  // }}\n{body}}}\n}}\n",
         [("h", 2, LIMIT + 5, False)]),
        ("int short_one() {\n  return 1;\n}\n", []),
        (f"const int kTable[] = {{\n{body}}};\n", []),  # a variable, not a function
        (f"struct S {{\n{body}}};\n", []),
        (f"int d(int);\nint e() {{ return '{{'; }}\n", []),
    ]
    for text, want in cases:
        got = long_functions(text)
        if got != want:
            raise AssertionError(f"self-test: got {got}, want {want} for:\n{text[:200]}")
    return len(cases)


def main(argv):
    n = self_test()
    print(f"check_long_functions: self-test: {n} cases pass")
    if argv[1:] == ["--self-test"]:
        return 0
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    root = pathlib.Path(argv[1])
    allow_file = root / "tests" / "long_functions_allowlist.txt"
    allowed = {l.strip() for l in allow_file.read_text().splitlines() if l.strip() and not l.startswith("#")}
    files = sorted(p for p in (root / "compiler").rglob("*") if p.suffix in SOURCE_SUFFIXES)
    measured, over, bad, seen = 0, 0, [], set()
    for p in files:
        rel = p.relative_to(root).as_posix()
        found = functions(p.read_text(errors="replace"))
        measured += len(found)
        for name, line, lines, reason in (f for f in found if f[2] > LIMIT):
            over += 1
            key = f"{rel}:{name}"
            seen.add(key)
            status = "long: given" if reason else ("allowlisted" if key in allowed else "NO REASON")
            print(f"{rel}:{line}: {name}: {lines} lines ({status})")
            if not reason and key not in allowed:
                bad.append(key)
    stale = sorted(allowed - seen)
    for key in stale:
        print(f"check_long_functions: {key} is in {allow_file.name} but no longer over {LIMIT} lines without long:")
    print(f"check_long_functions: {measured} functions in {len(files)} files measured, {over} functions over {LIMIT} lines, "
          f"{len(bad)} without a `long:` reason or an allowlist entry, {len(stale)} stale allowlist entries")
    for key in bad:
        print(f"  {key}: give the reason as a `long:` comment in the 3 lines above it, or split it")
    if not measured:
        print("check_long_functions: no function found: is the path right?")
        return 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

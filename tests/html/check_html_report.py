#!/usr/bin/env python3
"""The HTML report in a real browser (issue 24; docs/report.md, "HTML").

Writes `substratec report EXAMPLE --html` for every example and for
tests/html/*.json, and the all-examples scene's report.html (`substratec scene
examples/scenes/all_examples.json -o DIR`), then checks each page:

  - as text: no script, no reference to anything outside the page (every src
    and href is a #fragment or a data: URI, no url() or @import in the CSS),
    and HTML Tidy (Debian's `tidy`, an HTML5 checker) reports no error and no
    warning;
  - in headless Chromium (one browser for every page: headless_browser.py):
    no console error, no request but the page itself, a screenshot that is
    not blank, and a DOM whose tree boxes are exactly the compiled tree's
    nodes (`report --json`'s "tree"), each by its id.

Prints what it checked and fails on any problem, or when it checked nothing.

    check_html_report.py --substratec build/bin/substratec --source . --work /tmp/html
"""

import argparse, json, pathlib, re, shutil, subprocess, sys, time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from headless_browser import HeadlessBrowser, png_distinct_colours, png_is_blank  # noqa: E402

# A page renders at least this many colours (text, boxes, bars and badges).
MIN_COLOURS = 16
# The screenshot's height: the header, summary, byte bars and tree of a page
# (a whole long page's screenshot costs seconds), at half scale.
SCREENSHOT_HEIGHT = 2400


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        raise SystemExit(f"failed ({r.returncode}): {' '.join(map(str, cmd))}\n{r.stderr}")
    return r.stdout


def external_references(html):
    """Every src/href that is neither a #fragment nor a data: URI, and any url() or @import."""
    bad = [v for v in re.findall(r'\b(?:src|href|xlink:href)="([^"]*)"', html)
           if not (v.startswith("#") or v.startswith("data:"))]
    bad += re.findall(r"url\([^)]*\)|@import", html)
    if re.search(r"<script\b", html, re.I):
        bad.append("<script>")
    return bad


def tidy_problems(path):
    r = subprocess.run(["tidy", "-errors", "-quiet", str(path)], capture_output=True, text=True, timeout=120)
    return [line for line in (r.stdout + r.stderr).splitlines() if line.strip()] + \
        ([f"tidy exit {r.returncode}"] if r.returncode not in (0,) else [])


def tree_views(dom):
    """{view: [node ids]} of the tree diagrams in a page's DOM, in document order."""
    views = {}
    for m in re.finditer(r'<svg[^>]*class="tree"[^>]*data-view="([a-z]+)"[^>]*>(.*?)</svg>', dom, re.S):
        key = m.group(1)
        while key in views:
            key += "+"
        views[key] = re.findall(r'<g class="node"[^>]*data-node="([^"]*)"', m.group(2))
    return views


def pages(args, work):
    """(page, {material: compiled tree node ids} or None for the scene) for every page written."""
    out = []
    inputs = sorted((args.source / "examples").glob("*.json")) + sorted((args.source / "tests/html").glob("*.json"))
    reports = json.loads(run([args.substratec, "report", "--json"] + [str(f) for f in inputs]))
    if len(reports) != len(inputs):  # one material per file
        raise SystemExit(f"{len(reports)} reports for {len(inputs)} files")
    for f, report in zip(inputs, reports):
        page = work / f"{f.stem}.html"
        run([args.substratec, "report", str(f), "--html", str(page)])
        out.append((page, {report["name"]: [n["node"] for n in report["tree"]]}))
    scene = work / "scene"
    run([args.substratec, "scene", str(args.source / "examples/scenes/all_examples.json"), "-o", str(scene)])
    out.append((scene / "report.html", None))
    return out


def check_dom(page, dom, trees, problems):
    """The page's tree boxes against the compiled trees; the count of node boxes checked."""
    sections = re.split(r'<section class="material"', dom)[1:]
    checked = 0
    if trees is not None and len(sections) != len(trees):
        problems.append(f"{page.name}: {len(sections)} material sections for {len(trees)} materials")
    for section in sections:
        name = re.match(r'[^>]*data-material="([^"]*)"', section).group(1)
        views = tree_views(section)
        if not views:
            problems.append(f"{page.name}: {name}: no tree diagram")
            continue
        final = views.get("simplified", views.get("authored"))
        if trees is not None and sorted(final) != sorted(trees.get(name, [])):
            problems.append(f"{page.name}: {name}: tree boxes {sorted(final)} are not the tree's nodes "
                            f"{sorted(trees.get(name, []))}")
        checked += len(final)
    return checked


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--substratec", required=True)
    ap.add_argument("--source", required=True, type=pathlib.Path)
    ap.add_argument("--work", required=True, type=pathlib.Path)
    ap.add_argument("--chromium", default="chromium")
    args = ap.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True)
    start = time.monotonic()
    written = pages(args, args.work)
    problems, nodes, screenshots = [], 0, 0
    for page, _ in written:
        html = page.read_text(encoding="utf-8")
        problems += [f"{page.name}: external reference {r}" for r in external_references(html)]
        problems += [f"{page.name}: tidy: {p}" for p in tidy_problems(page)]
    with HeadlessBrowser(chromium=args.chromium) as browser:
        for page, trees in written:
            r = browser.load(page, max_height=SCREENSHOT_HEIGHT, scale=0.5)
            problems += [f"{page.name}: console: {e}" for e in r.console_errors]
            if [u for u in r.requests if not u.startswith("data:")] != [page.resolve().as_uri()]:
                problems.append(f"{page.name}: requests {r.requests}")
            colours = png_distinct_colours(r.screenshot_png)
            if png_is_blank(r.screenshot_png) or colours < MIN_COLOURS:
                problems.append(f"{page.name}: screenshot has {colours} colours")
            else:
                screenshots += 1
            nodes += check_dom(page, r.dom, trees, problems)
    print(f"[ html     ] {len(written)} pages ({len(written) - 1} reports and the all-examples scene): "
          f"{screenshots} screenshots not blank, {nodes} tree boxes matched to the compiled trees' nodes, "
          f"no external reference, tidy clean, no console error ({time.monotonic() - start:.1f} s)"
          if not problems else f"[ html     ] {len(problems)} problems in {len(written)} pages")
    for p in problems[:60]:
        print("  " + p)
    if problems:
        return 1
    if len(written) < 2 or nodes == 0 or screenshots == 0:
        print("nothing was checked")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

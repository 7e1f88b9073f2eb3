#!/usr/bin/env python3
"""The persistent worker against one-shot processes (bench/worker.sh; docs/performance.md).

Usage: worker.py SUBSTRATEC OUT_DIR MATERIAL...

For every material, `substratec compile MATERIAL -o DIR` (both languages,
validated) is timed:
  one-shot:    a process per material, one at a time (wall clock per process);
  singleplex:  one `substratec compile --persistent_worker`, a request at a time,
               as Bazel sends them (wall clock from request to response); the
               first request (glslang's built-in tables) is reported apart;
  multiplex:   one worker, every request at once with its requestId (the
               worker runs them on the machine's threads); materials per second.
The outputs of the three modes must be byte-identical (exit 2 otherwise), and
every response must report exit status 0. Prints a Markdown table.
"""
import hashlib
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path


def tree_digest(root):
    h = hashlib.sha256()
    files = sorted(p for p in Path(root).rglob("*") if p.is_file())
    for p in files:
        h.update(str(p.relative_to(root)).encode() + b"\0" + p.read_bytes())
    return h.hexdigest(), len(files)


def request(material, out, request_id):
    return json.dumps({"arguments": [material, "-o", out], "requestId": request_id}) + "\n"


def one_shot(binary, materials, out):
    times = []
    for m in materials:
        t0 = time.perf_counter()
        r = subprocess.run([binary, "compile", m, "-o", out], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        times.append(time.perf_counter() - t0)
        if r.returncode != 0:
            sys.exit("worker.py: one-shot compile of %s failed: %s" % (m, r.stderr.decode()))
    return times


def start_worker(binary):
    return subprocess.Popen([binary, "compile", "--persistent_worker"], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, bufsize=1)


def check_response(line, what):
    response = json.loads(line)
    if response.get("exitCode", 0) != 0:
        sys.exit("worker.py: %s failed: %s" % (what, response.get("output", "")))
    return response


def singleplex(binary, materials, out):
    worker = start_worker(binary)
    times = []
    for m in materials:
        t0 = time.perf_counter()
        worker.stdin.write(request(m, out, 0))
        check_response(worker.stdout.readline(), m)
        times.append(time.perf_counter() - t0)
    worker.stdin.close()
    worker.wait()
    return times


def multiplex(binary, materials, out):
    worker = start_worker(binary)
    warm = time.perf_counter()  # one request first, so the figure is the warm worker's
    worker.stdin.write(request(materials[0], out, 1))
    check_response(worker.stdout.readline(), materials[0])
    warm = time.perf_counter() - warm
    t0 = time.perf_counter()
    for i, m in enumerate(materials[1:], start=2):
        worker.stdin.write(request(m, out, i))
    worker.stdin.flush()
    seen = set()
    for _ in materials[1:]:
        seen.add(check_response(worker.stdout.readline(), "a multiplex request")["requestId"])
    seconds = time.perf_counter() - t0
    worker.stdin.close()
    worker.wait()
    if seen != set(range(2, len(materials) + 1)):
        sys.exit("worker.py: multiplex responses do not answer every request once")
    return warm, seconds


def ms(seconds):
    return "%.1f" % (1000 * seconds)


def main(argv):
    binary, out = argv[1], Path(argv[2])
    materials = [os.path.abspath(m) for m in argv[3:]]
    if not materials:
        sys.exit("usage: worker.py SUBSTRATEC OUT_DIR MATERIAL...")
    dirs = {mode: str(out / mode) for mode in ("one_shot", "singleplex", "multiplex")}
    shot = one_shot(binary, materials, dirs["one_shot"])
    single = singleplex(binary, materials, dirs["singleplex"])
    first, seconds = multiplex(binary, materials, dirs["multiplex"])
    digests = {mode: tree_digest(d) for mode, d in dirs.items()}
    if len({d for d, _ in digests.values()}) != 1:
        print("worker.py: the modes' outputs differ: %s" % digests, file=sys.stderr)
        return 2
    n = len(materials)
    print("| mode | first material ms | median ms per material (warm) | materials/s |")
    print("|---|---:|---:|---:|")
    print("| a process per material (one-shot) | %s | %s | %.1f |"
          % (ms(shot[0]), ms(statistics.median(shot[1:] or shot)), n / sum(shot)))
    print("| worker, singleplex (a request at a time) | %s | %s | %.1f |"
          % (ms(single[0]), ms(statistics.median(single[1:] or single)), (n - 1) / max(sum(single[1:]), 1e-9)))
    print("| worker, multiplex (every request at once) | %s | %s (wall / requests) | %.1f |"
          % (ms(first), ms(seconds / max(n - 1, 1)), (n - 1) / seconds))
    print()
    print("%d materials; outputs byte-identical in the three modes (%d files)." % (n, digests["one_shot"][1]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

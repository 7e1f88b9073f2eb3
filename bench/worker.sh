#!/usr/bin/env bash
# The persistent worker (`substratec compile --persistent_worker`, issue 21)
# against a process per material: bench/worker.py says what is timed. Works
# from any directory. Materials: the examples and WORKER_MATERIALS generated
# ones (bench/gen_materials.py), compiled for both languages and validated.
#
#   WORKER_MATERIALS [100]    generated materials added to the examples
#   WORKER_BUILD     [build]  build directory (relative to the source root, or absolute)
#
# Exit status: 0 on success, 2 on a build or run error (or outputs that differ).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${WORKER_BUILD:-build}"
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
N="${WORKER_MATERIALS:-100}"

if [ ! -f "$BUILD/build.ninja" ]; then
  cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null || exit 2
fi
cmake --build "$BUILD" --target substratec >/dev/null || exit 2

tmp="$(mktemp -d "${TMPDIR:-/tmp}/worker.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
python3 "$ROOT/bench/gen_materials.py" "$tmp/materials" "$N" || exit 2

echo "nproc: $(nproc); load: $(cut -d' ' -f1-3 /proc/loadavg); tree: $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?')"
python3 "$ROOT/bench/worker.py" "$BUILD/bin/substratec" "$tmp/out" "$ROOT"/examples/*.json "$tmp"/materials/*.json || exit 2

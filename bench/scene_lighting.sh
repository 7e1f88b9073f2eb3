#!/usr/bin/env bash
# Scene lighting cost on lavapipe (issue 9; docs/performance.md, "Scene lighting").
# Works from any directory: builds the scene_lighting target (configuring the
# build directory if needed), prints the machine, then runs build/bin/scene_lighting,
# which prints one markdown table: the simple-only scene's lighting, the
# all-examples scene's (per class, and its SPECIAL shader on everything), and the
# hand-written minimal GGX + Lambert kernel, in ns per pixel.
#
# Environment knobs (defaults in brackets):
#   SCENE_LIGHTING_SIZE  [1024]   the G-buffer is SIZE x SIZE pixels
#   SCENE_LIGHTING_RUNS  [9]      timed rounds after one warm-up (medians reported)
#   SCENE_LIGHTING_BUILD [build]  build directory (relative to the source root, or absolute)
#
# Exit status: 0 on success, 2 on a build or run error.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${SCENE_LIGHTING_BUILD:-build}"
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
SIZE="${SCENE_LIGHTING_SIZE:-1024}"
RUNS="${SCENE_LIGHTING_RUNS:-9}"

cd "$ROOT"
if [ ! -f "$BUILD/build.ninja" ]; then
  cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null || exit 2
fi
cmake --build "$BUILD" --target scene_lighting || exit 2

echo
echo "== machine"
echo "nproc: $(nproc)"
echo "cpu:   $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')"
echo "load:  $(cut -d' ' -f1-3 /proc/loadavg)"
echo "tree:  $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?')$(git -C "$ROOT" status --porcelain 2>/dev/null | grep -q . && echo ' + uncommitted changes')"
echo "run:   $BUILD/bin/scene_lighting --size $SIZE --runs $RUNS"
echo
start=$(date +%s)
"$BUILD/bin/scene_lighting" --size "$SIZE" --runs "$RUNS" || exit 2
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg) ($(( $(date +%s) - start )) s)"

#!/usr/bin/env bash
# Scene lighting cost on lavapipe (issue 9; docs/performance.md, "Scene lighting cost").
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
#   SCENE_LIGHTING_VARIANTS [1]   1: also time two edits of all_examples' SPECIAL shader on the
#                                 simple pixels, to split what the SIMPLE shader saves: (a) its
#                                 unpacker and closure loop replaced by substrate_unpack_simple and one
#                                 closure (every feature still compiled in), (b) every SUBSTRATE_USE_*
#                                 set to 0 (the generic unpacker and loop kept); and the shader as
#                                 emitted (c), timed in the same rounds
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
args=(--size "$SIZE" --runs "$RUNS")
if [ "${SCENE_LIGHTING_VARIANTS:-1}" = 1 ]; then
  tmp="$(mktemp -d "${TMPDIR:-/tmp}/scene_lighting.XXXXXX")"
  trap 'rm -rf "$tmp"' EXIT
  "$BUILD/bin/scene_lighting" --size 8 --runs 1 --dump "$tmp/dump" >/dev/null || exit 2
  mkdir -p "$tmp/extra"
  special="$tmp/dump/all_examples.lighting_special.comp"
  cp "$special" "$tmp/extra/c_special_as_emitted.comp"
  sed 's/^#define SUBSTRATE_USE_\([A-Z_0-9]*\) 1/#define SUBSTRATE_USE_\1 0/' "$special" >"$tmp/extra/b_special_features_off.comp"
  python3 - "$special" "$tmp/extra/a_special_simple_unpacker.comp" <<'PY' || exit 2
import sys
s = open(sys.argv[1]).read()
a = s.index("  SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES];")
b = s.index("  SUBSTRATE_SCENE_STORE(pixel")
one = """  SubstrateClosure c;
  substrate_unpack_simple(words, topLayer, c);
  color += substrate_light_closure(c, V, L, frame.lightRadiance.rgb);
  color += substrate_closure_view_throughput(c, dot(c.N, V)) *
           substrate_env_split_sum(c, V, SUBSTRATE_ENV_PREFILTERED(substrate_reflection_dir(c, V),
                                   substrate_env_mip(substrate_env_roughness(c), frame.envParams.x)),
                                   SUBSTRATE_ENV_IRRADIANCE(c.N));
"""
open(sys.argv[2], "w").write(s[:a] + one + s[b:])
PY
  args+=(--extra "$tmp/extra")
fi
echo "run:   $BUILD/bin/scene_lighting ${args[*]}"
echo
start=$(date +%s)
"$BUILD/bin/scene_lighting" "${args[@]}" || exit 2
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg) ($(( $(date +%s) - start )) s)"

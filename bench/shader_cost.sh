#!/usr/bin/env bash
# Generated-shader cost on lavapipe (issue 6; docs/performance.md, "Generated-shader
# cost"). Works from any directory.
#
#   1. builds the shader_cost target (configuring the build directory if needed),
#   2. prints the machine (nproc, cpu, load average, git revision),
#   3. runs build/bin/shader_cost, which prints five markdown tables:
#        1. the simple layout (row12_simple) against a hand-written minimal
#           GGX + Lambert kernel (bench/shaders/minimal_ggx_lambert.comp): the floor;
#        2. cost against the number of closures (synthetic 1–8 closure materials),
#           with least-squares lines and R²;
#        3. every example at budgets own / 80 / 48 / 20 / full simplification;
#        4. row12_simple under each diffuse model;
#        5. every example in float32 and in half precision (`--precision half`, issue 7).
#
# Environment knobs (defaults in brackets):
#   SHADER_COST_PIXELS [1048576]  shading points per timed dispatch
#   SHADER_COST_RUNS   [5]        timed dispatches per kernel, after 1 warm-up (median reported)
#   SHADER_COST_PARTS  [12345]    which tables
#   SHADER_COST_BUILD  [build]    build directory (relative to the source root, or absolute);
#                                 configured RelWithDebInfo with Ninja when it has no build.ninja
#   SHADER_COST_CALLGRIND [0]     1: instead of timing, count the x86 instructions lavapipe's
#                                 JIT-compiled code executes per pixel for the kernels of
#                                 tables 1, 2, 4 and 5 (valgrind --tool=callgrind, one dispatch of
#                                 65,536 pixels each; deterministic, unlike the timings on a
#                                 shared machine)
#
# Exit status: 0 on success, 2 on a build or run error. It judges nothing: the
# "Target" line of table 1 says whether the 1.1× target is met.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${SHADER_COST_BUILD:-build}"
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
PIXELS="${SHADER_COST_PIXELS:-1048576}"
RUNS="${SHADER_COST_RUNS:-5}"
PARTS="${SHADER_COST_PARTS:-12345}"

cd "$ROOT"
if [ ! -f "$BUILD/build.ninja" ]; then
  if [ "$BUILD" = "$ROOT/build" ]; then
    cmake --preset default >/dev/null || exit 2
  else
    cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null || exit 2
  fi
fi
# Only the target this needs.
cmake --build "$BUILD" --target shader_cost || exit 2

echo
echo "== machine"
echo "nproc: $(nproc)"
echo "cpu:   $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')"
echo "load:  $(cut -d' ' -f1-3 /proc/loadavg)"
echo "tree:  $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?')$(git -C "$ROOT" status --porcelain 2>/dev/null | grep -q . && echo ' + uncommitted changes')"
if [ "${SHADER_COST_CALLGRIND:-0}" = 1 ]; then
  command -v valgrind >/dev/null || { echo "shader_cost.sh: valgrind is not installed" >&2; exit 2; }
  CG_PIXELS=65536
  tmp="$(mktemp -d "${TMPDIR:-/tmp}/shader_cost.XXXXXX")"
  trap 'rm -rf "$tmp"' EXIT
  echo "run:   valgrind --tool=callgrind --collect-atstart=yes --instr-atstart=no --smc-check=all-non-file" \
       "$BUILD/bin/shader_cost --callgrind --pixels $CG_PIXELS --parts $PARTS"
  echo
  valgrind --tool=callgrind --collect-atstart=yes --instr-atstart=no --smc-check=all-non-file \
    --callgrind-out-file="$tmp/cg.%p" "$BUILD/bin/shader_cost" --callgrind --pixels "$CG_PIXELS" --parts "$PARTS" \
    >"$tmp/log" 2>&1 ||
    { cat "$tmp/log" >&2; exit 2; }
  echo "| kernel | x86 instructions per pixel (lavapipe's JIT code, one dispatch) |"
  echo "|---|---:|"
  # One dump per kernel (cg.<pid>.<n>), in dispatch order; the JIT code is the object without a name.
  for f in $(ls -v "$tmp"/cg.*.*); do
    label="$(sed -n 's/^desc: Trigger: Client Request: //p' "$f")"
    callgrind_annotate --threshold=100 "$f" | grep -F '[???]' |
      awk -v label="$label" -v px="$CG_PIXELS" '{ gsub(",", "", $1); s += $1 } END { printf "| %s | %.1f |\n", label, s / px }'
  done | tee "$tmp/table"
  # Table 2's materials: least squares of instructions per pixel against closures.
  awk -F'|' '$2 ~ /^ synthetic_[0-9]+ $/ {
      split($2, p, "_"); x[n + 0] = p[2] + 0; y[n + 0] = $3 + 0; n++ }
    END {
      if (n < 2) exit
      for (i = 0; i < n; i++) { sx += x[i]; sy += y[i]; sxx += x[i] * x[i]; sxy += x[i] * y[i] }
      b = (n * sxy - sx * sy) / (n * sxx - sx * sx); a = (sy - b * sx) / n
      for (i = 0; i < n; i++) { e = y[i] - a - b * x[i]; r += e * e; t += (y[i] - sy / n) ^ 2 }
      printf "\nsynthetic materials: instructions per pixel = %.1f + %.1f * closures, R^2 = %.5f (%d points)\n", a, b, 1 - r / t, n
    }' "$tmp/table"
  exit 0
fi
echo "run:   $BUILD/bin/shader_cost --pixels $PIXELS --runs $RUNS --parts $PARTS"
echo
start=$(date +%s)
"$BUILD/bin/shader_cost" --pixels "$PIXELS" --runs "$RUNS" --parts "$PARTS" || exit 2
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg) ($(( $(date +%s) - start )) s)"

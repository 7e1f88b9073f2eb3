#!/usr/bin/env bash
# The worst case under the limits (issue 16, severe 6; docs/performance.md,
# "The widest material"). Works from any directory.
#
#   1. builds substratec (configuring build/ with the default preset if needed);
#   2. writes bench/gen_wide_mix.py's material: 512 slabs mixed in pairs (1023
#      tree nodes, the tree-size limit is 1024), every mix weight and every
#      slab's diffuse albedo an input (1023 inputs, the limit is 1024);
#   3. runs each command on it under /usr/bin/time -v and prints its wall
#      time, peak RSS and exit status:
#        report, compile (both targets), report --spirv (SPIRV-Tools'
#        performance passes on every entry), stability --no-gpu, and sweep
#        (lavapipe: every simplification step timed and measured).
#
# Environment knobs (defaults in brackets):
#   WIDE_SLABS   [512]    slabs (a power of two)
#   WIDE_PIXELS  [65536]  sweep --pixels (shading points per timed dispatch)
#   WIDE_RUNS    [1]      sweep --runs
#   WIDE_SKIP    []       commands to skip, space-separated (e.g. "sweep")
#
# Exit status: 0 when every command exits 0, 1 otherwise, 2 on a build error.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build"
SLABS="${WIDE_SLABS:-512}"
PIXELS="${WIDE_PIXELS:-65536}"
RUNS="${WIDE_RUNS:-1}"
SKIP=" ${WIDE_SKIP:-} "

cd "$ROOT"
if [ ! -f "$BUILD/build.ninja" ]; then cmake --preset default >/dev/null || exit 2; fi
cmake --build "$BUILD" --target substratec >/dev/null || exit 2
BIN="$BUILD/bin/substratec"

tmp="$(mktemp -d "${TMPDIR:-/tmp}/wide_mix.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
python3 "$ROOT/bench/gen_wide_mix.py" "$tmp/wide.json" "$SLABS"

echo "== machine"
echo "nproc: $(nproc)"
echo "cpu:   $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')"
echo "load:  $(cut -d' ' -f1-3 /proc/loadavg)"
echo "tree:  $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?')$(git -C "$ROOT" status --porcelain 2>/dev/null | grep -q . && echo ' + uncommitted changes')"
echo "material: $SLABS slabs mixed in pairs ($(wc -c < "$tmp/wide.json") bytes, bench/gen_wide_mix.py)"
echo
printf '%-28s %10s %12s %5s\n' "command" "wall s" "peak RSS MB" "exit"

status=0
measure() {  # name, then the substratec arguments
  local name="$1"
  shift
  case "$SKIP" in *" $name "*) return ;; esac
  local code=0
  /usr/bin/time -v -o "$tmp/time.txt" "$BIN" "$@" >"$tmp/out.txt" 2>"$tmp/err.txt" || code=$?
  local wall rss
  wall="$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, t, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + t[i]; print s}' "$tmp/time.txt")"
  rss="$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$tmp/time.txt")"
  printf '%-28s %10.2f %12s %5s\n' "$name" "$wall" "$rss" "$code"
  if [ "$code" -ne 0 ]; then
    status=1
    sed 's/^/    /' "$tmp/err.txt" | tail -5
  fi
}

measure "report" report "$tmp/wide.json"
measure "compile" compile "$tmp/wide.json" -o "$tmp/out"
measure "report --spirv" report --spirv "$tmp/wide.json"
measure "stability --no-gpu" stability "$tmp/wide.json" --no-gpu --evaluations 2000
measure "sweep" sweep "$tmp/wide.json" --pixels "$PIXELS" --runs "$RUNS"
exit "$status"

#!/usr/bin/env bash
# Issue 10's measurements, from any directory:
#   1. import speed: build/bin/import_bench (Google Benchmark, median of
#      BENCH_REPS [5] repetitions of >= BENCH_MIN_TIME [0.5] s), materials/s;
#   2. the oracle: build/bin/import_oracle, rel_mse of every constant-parameter
#      glTF corpus material against the glTF 2.0 reference BRDF (the table of
#      docs/import.md; its summary lines are printed here).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build"
BENCH_MIN_TIME="${BENCH_MIN_TIME:-0.5}"
BENCH_REPS="${BENCH_REPS:-5}"
cd "$ROOT"
if [ ! -f "$BUILD/build.ninja" ]; then cmake --preset default >/dev/null || exit 2; fi
cmake --build "$BUILD" --target import_bench import_oracle || exit 2
echo "== machine: nproc $(nproc), load $(cut -d' ' -f1-3 /proc/loadavg), tree $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
echo "== import speed"
"$BUILD/bin/import_bench" --benchmark_min_time="$BENCH_MIN_TIME" --benchmark_repetitions="$BENCH_REPS" \
  --benchmark_display_aggregates_only=true --benchmark_counters_tabular=true
echo "== oracle (glTF 2.0 reference BRDF)"
"$BUILD/bin/import_oracle" | tail -n 4

#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, in the "asan" preset's build-asan/:
# clang 14, ASan + UBSan) and runs each for SECONDS (default 60) from a seed corpus made of
# examples/*.json and tests/bad/*.json, with the format's dictionary.
# Fails if any target finds a crash, a leak, a timeout (> 10 s per input) or
# an out-of-memory (> 2 GiB); the input is kept in build-asan/fuzz/artifacts/.
# Prints the executions each target ran. docs/robustness.md describes it.
#
#   scripts/fuzz.sh [SECONDS]          # both targets
#   FUZZ_TARGETS=parser_fuzzer scripts/fuzz.sh 30
#
# New inputs that reach new coverage accumulate in build-asan/fuzz/corpus/<target>/
# between runs (a clean clone starts from the seeds alone).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
TARGETS="${FUZZ_TARGETS:-parser_fuzzer pipeline_fuzzer}"
BUILD=build-asan/fuzz

cmake --preset asan >/dev/null
cmake --build --preset fuzz

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:symbolize=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

# The seeds, rebuilt every run. The pipeline target reads one mode byte before
# the material (0: its own settings, 1+4k: a budget of 8+4k bytes, 2+4k: 1+k
# closures, 3: full simplification), so each seed goes in with a few modes.
SEEDS="$BUILD/seeds"
rm -rf "$SEEDS"
mkdir -p "$SEEDS/parser_fuzzer" "$SEEDS/pipeline_fuzzer" "$BUILD/artifacts"
for f in examples/*.json tests/bad/*.json; do
  [ -f "$f" ] || continue  # tests/bad/280 is a link to a missing file
  name="$(basename "$f" .json)"
  case "$f" in examples/*) name="ex_$name" ;; *) name="bad_$name" ;; esac
  cp "$f" "$SEEDS/parser_fuzzer/$name"
  printf '\000' | cat - "$f" >"$SEEDS/pipeline_fuzzer/$name"
  case "$f" in examples/*)
    printf '\003' | cat - "$f" >"$SEEDS/pipeline_fuzzer/${name}_full"    # full simplification
    printf '\021' | cat - "$f" >"$SEEDS/pipeline_fuzzer/${name}_b24"     # budget 24 bytes
    printf '\002' | cat - "$f" >"$SEEDS/pipeline_fuzzer/${name}_c1" ;;   # one closure
  esac
done

status=0
for t in $TARGETS; do
  corpus="$BUILD/corpus/$t"
  mkdir -p "$corpus"
  log="$BUILD/$t.log"
  echo "fuzz: $t for ${SECONDS_EACH}s (log: $log)"
  set +e
  build-asan/bin/$t -max_total_time="$SECONDS_EACH" -dict=fuzz/substrate.dict -timeout=10 -rss_limit_mb=2048 \
    -max_len=16384 -print_final_stats=1 -artifact_prefix="$BUILD/artifacts/$t-" \
    "$corpus" "$SEEDS/$t" >"$log" 2>&1
  rc=$?
  set -e
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  units="$(ls "$corpus" | wc -l)"
  if [ "$rc" -ne 0 ]; then
    echo "fuzz: $t FAILED (exit $rc) after ${execs:-?} executions; the last lines of $log:" >&2
    grep -E "ERROR|SUMMARY|Test unit written|runtime error" "$log" | head -20 >&2 || true
    tail -40 "$log" >&2
    status=1
  else
    echo "fuzz: $t ran ${execs:-?} executions in ${SECONDS_EACH}s, no crash (corpus: $units inputs)"
  fi
done
exit $status

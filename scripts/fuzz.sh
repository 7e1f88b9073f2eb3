#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, in the "asan" preset's build-asan/:
# clang 14, ASan + UBSan) and runs each from its seed corpus with its
# dictionary: parser_fuzzer and pipeline_fuzzer (the material format; seeds
# examples/*.json and tests/bad/*.json; fuzz/substrate.dict) for SECONDS each
# (default 60); mtlx_fuzzer, gltf_fuzzer and manifest_fuzzer (the MaterialX
# and glTF importers and the scene manifest; seeds tests/import/corpus — the
# same files as ../shared/corpus — with .glb containers made from a few of its
# glTF extracts, examples/scenes and tests/import/fuzz_regressions;
# fuzz/mtlx.dict, gltf.dict, scene.dict) for IMPORT_SECONDS each (default 30:
# CI's budget, 3 x 30 s on top of 2 x 60 s); image_fuzzer (the PNG and JPEG
# decoders; seeds examples/textures/*.png and fuzz/image_seeds) for
# IMPORT_SECONDS too.
# The targets run FUZZ_JOBS at a time (default: one per core).
# Fails if any target finds a crash, a leak, a timeout (> 10 s per input) or
# an out-of-memory (> 2 GiB); the input is kept in build-asan/fuzz/artifacts/.
# Prints the executions each target ran. docs/robustness.md describes it.
#
#   scripts/fuzz.sh [SECONDS]          # every target
#   FUZZ_TARGETS=parser_fuzzer scripts/fuzz.sh 30
#   IMPORT_SECONDS=60 FUZZ_TARGETS="mtlx_fuzzer gltf_fuzzer" scripts/fuzz.sh
#
# New inputs that reach new coverage accumulate in build-asan/fuzz/corpus/<target>/
# between runs (a clean clone starts from the seeds alone).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
IMPORT_SECONDS="${IMPORT_SECONDS:-30}"
TARGETS="${FUZZ_TARGETS:-parser_fuzzer pipeline_fuzzer mtlx_fuzzer gltf_fuzzer manifest_fuzzer image_fuzzer}"
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

# The importers' and the manifest's seeds.
mkdir -p "$SEEDS/mtlx_fuzzer" "$SEEDS/gltf_fuzzer" "$SEEDS/manifest_fuzzer"
find tests/import/corpus/materialx tests/import/fuzz_regressions -name '*.mtlx' | sort | while read -r f; do
  cp "$f" "$SEEDS/mtlx_fuzzer/$(echo "$f" | tr / _)"
done
for f in tests/import/corpus/gltf/*.json tests/import/fuzz_regressions/*.gltf tests/import/fuzz_regressions/*.glb; do
  if [ -f "$f" ]; then cp "$f" "$SEEDS/gltf_fuzzer/$(basename "$f")"; fi
done
# .glb containers of three extracts, with a binary chunk a buffer and an image view point into.
python3 - "$SEEDS/gltf_fuzzer" tests/import/corpus/gltf/CompareVolume.materials.json \
  tests/import/corpus/gltf/ClearCoatTest.materials.json tests/import/corpus/gltf/CompareSheen.materials.json <<'PY'
import json, struct, sys, os
out = sys.argv[1]
for path in sys.argv[2:]:
    doc = json.load(open(path, encoding="utf-8"))
    doc["buffers"] = [{"byteLength": 16}]
    doc["bufferViews"] = [{"buffer": 0, "byteOffset": 4, "byteLength": 8}]
    doc.setdefault("images", []).append({"bufferView": 0, "mimeType": "image/png"})
    text = json.dumps(doc).encode("utf-8")
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I", len(text)) + b"JSON" + text + struct.pack("<I", 16) + b"BIN\0" + bytes(16)
    name = os.path.basename(path).replace(".materials.json", ".glb")
    open(os.path.join(out, name), "wb").write(b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body)
PY
for f in examples/scenes/*.json tests/import/fuzz_regressions/*.scene.json; do
  if [ -f "$f" ]; then cp "$f" "$SEEDS/manifest_fuzzer/$(basename "$f")"; fi
done

mkdir -p "$SEEDS/image_fuzzer"
cp examples/textures/*.png fuzz/image_seeds/* "$SEEDS/image_fuzzer/"

# One target: fuzz it, then write what it found to $BUILD/$t.result (the
# report line, then the exit status).
fuzz_one() {
  local t="$1" dict secs
  case "$t" in
    mtlx_fuzzer) dict=fuzz/mtlx.dict; secs="$IMPORT_SECONDS" ;;
    gltf_fuzzer) dict=fuzz/gltf.dict; secs="$IMPORT_SECONDS" ;;
    manifest_fuzzer) dict=fuzz/scene.dict; secs="$IMPORT_SECONDS" ;;
    image_fuzzer) dict=""; secs="$IMPORT_SECONDS" ;;
    *) dict=fuzz/substrate.dict; secs="$SECONDS_EACH" ;;
  esac
  local corpus="$BUILD/corpus/$t" log="$BUILD/$t.log" result="$BUILD/$t.result"
  mkdir -p "$corpus"
  echo "fuzz: $t for ${secs}s (log: $log)"
  set +e
  build-asan/bin/$t -max_total_time="$secs" ${dict:+-dict="$dict"} -timeout=10 -rss_limit_mb=2048 \
    -max_len=16384 -print_final_stats=1 -artifact_prefix="$BUILD/artifacts/$t-" \
    "$corpus" "$SEEDS/$t" >"$log" 2>&1
  local rc=$?
  set -e
  local execs units
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  units="$(ls "$corpus" | wc -l)"
  if [ "$rc" -ne 0 ]; then
    { echo "fuzz: $t FAILED (exit $rc) after ${execs:-?} executions; the last lines of $log:"
      grep -E "ERROR|SUMMARY|Test unit written|runtime error" "$log" | head -20 || true
      tail -40 "$log"; } >"$result.text"
  else
    echo "fuzz: $t ran ${execs:-?} executions in ${secs}s, no crash (corpus: $units inputs)" >"$result.text"
  fi
  echo "$rc" >"$result"
}

# FUZZ_JOBS targets at a time (default: one per core). Each target is one
# process for its own time, so two at a time on 2 cores fuzz as many inputs in
# half the wall time; in the default order the longest targets start first.
JOBS="${FUZZ_JOBS:-$(nproc)}"
running=0
for t in $TARGETS; do
  rm -f "$BUILD/$t.result" "$BUILD/$t.result.text"
  if [ "$running" -ge "$JOBS" ]; then wait -n || true; running=$((running - 1)); fi
  fuzz_one "$t" &
  running=$((running + 1))
done
wait || true

status=0
for t in $TARGETS; do
  if [ ! -f "$BUILD/$t.result" ]; then
    echo "fuzz: $t did not report" >&2; status=1; continue
  fi
  if [ "$(cat "$BUILD/$t.result")" -ne 0 ]; then
    cat "$BUILD/$t.result.text" >&2; status=1
  else
    cat "$BUILD/$t.result.text"
  fi
done
exit $status

#!/usr/bin/env bash
# Regenerates, measured in one run on this machine:
#   docs/accuracy/layering.md: `substratec accuracy --json` of every example, of
#     the one-effect controls in bench/materials/ and of every material of the
#     MaterialX corpus in tests/import/corpus/materialx (the shipping model against
#     the Monte Carlo truth: directional albedo at NoV 1 / 0.6 / 0.2 / 0.1 with
#     standard errors, BRDF error, reciprocity, white furnace, what the truth
#     excludes);
#   docs/accuracy/sweeps.md and docs/accuracy/<example>.svg: the `substratec
#     sweep` of every example (cost against error from the authored tree down to
#     one closure, against the authored tree and against the truths).
# Knobs: SWEEP_PIXELS (default 1048576), SWEEP_RUNS (5), TRUTH_SAMPLES (32768)
# and TRUTH_EVAL_SAMPLES (2048) of `accuracy`, SWEEP_TRUTH_SAMPLES (8192) and
# SWEEP_TRUTH_EVAL_SAMPLES (512) of `sweep`.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/bin/substratec"
if [ ! -f "$ROOT/build/build.ninja" ]; then cmake --preset default >/dev/null; fi
cmake --build "$ROOT/build" --target substratec
OUT="$ROOT/docs/accuracy"
PIXELS="${SWEEP_PIXELS:-1048576}"
RUNS="${SWEEP_RUNS:-5}"
SAMPLES="${TRUTH_SAMPLES:-32768}"
EVAL_SAMPLES="${TRUTH_EVAL_SAMPLES:-2048}"
SWEEP_SAMPLES="${SWEEP_TRUTH_SAMPLES:-8192}"
SWEEP_EVAL_SAMPLES="${SWEEP_TRUTH_EVAL_SAMPLES:-512}"
REV="$(git -C "$ROOT" rev-parse --short HEAD)"
mkdir -p "$OUT" 
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
mkdir -p "$TMP/examples" "$TMP/controls" "$TMP/sweeps"
: > "$TMP/examples_unread.txt"
for f in "$ROOT"/examples/*.json; do
  stem="$(basename "$f" .json)"
  # An example `accuracy` cannot measure (unlit nodes only: nothing reflects) is
  # listed with its error; its sweep still runs.
  if ! "$BIN" accuracy "$f" --json --samples "$SAMPLES" --eval-samples "$EVAL_SAMPLES" > "$TMP/examples/$stem.json" \
    2> "$TMP/examples/$stem.err"; then
    echo "$stem: $(grep -m1 'error' "$TMP/examples/$stem.err" | sed "s|$ROOT/||g")" >> "$TMP/examples_unread.txt"
    rm -f "$TMP/examples/$stem.json"
  fi
  "$BIN" sweep "$f" --json --pixels "$PIXELS" --runs "$RUNS" --truth-samples "$SWEEP_SAMPLES" \
    --truth-eval-samples "$SWEEP_EVAL_SAMPLES" --plot "$TMP/sweeps/$stem.svg" > "$TMP/sweeps/$stem.json"
done
for f in "$ROOT"/bench/materials/*.json; do
  stem="$(basename "$f" .json)"
  # The controls' base is Lambertian, as the walk's is.
  "$BIN" accuracy "$f" --json --diffuse lambert --samples "$SAMPLES" --eval-samples "$EVAL_SAMPLES" \
    > "$TMP/controls/$stem.json"
done
# The MaterialX corpus (tests/import/corpus/materialx): every material of every
# file, by name (the names `import` gives them); a file that does not import, or
# a material `accuracy` cannot measure, is listed with its first error.
mkdir -p "$TMP/corpus" "$TMP/imported"
: > "$TMP/corpus_unread.txt"
while IFS= read -r f; do
  stem="$(basename "$f" .mtlx)"
  if ! "$BIN" import "$f" -o "$TMP/imported/$stem" > /dev/null 2> "$TMP/imported/$stem.err"; then
    echo "$(grep -m1 'error' "$TMP/imported/$stem.err" | sed "s|$ROOT/||g")" >> "$TMP/corpus_unread.txt"
    continue
  fi
  for j in "$TMP/imported/$stem"/*.json; do
    name="$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["name"])' "$j")"
    out="$TMP/corpus/$stem--$name.json"
    if ! "$BIN" accuracy "$f" --material "$name" --json --samples "$SAMPLES" --eval-samples "$EVAL_SAMPLES" \
      > "$out" 2> "$out.err"; then
      echo "$name: $(grep -m1 'error' "$out.err" | sed "s|$ROOT/||g")" >> "$TMP/corpus_unread.txt"
      rm -f "$out"
    fi
  done
done < <(find "$ROOT/tests/import/corpus/materialx" -name '*.mtlx' | sort)
python3 "$ROOT/bench/accuracy_tables.py" "$TMP" "$OUT" "$REV" "$(cut -d' ' -f1-3 /proc/loadavg)" \
  "$SAMPLES" "$EVAL_SAMPLES" "$PIXELS" "$RUNS" "$SWEEP_SAMPLES" "$SWEEP_EVAL_SAMPLES"
cp "$TMP"/sweeps/*.svg "$OUT/"

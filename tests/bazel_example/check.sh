#!/usr/bin/env bash
# ctest bazel_example: builds examples/bazel with Debian's Bazel (bazel-bootstrap,
# installed by scripts/deps.sh; offline: the workspace needs nothing fetched)
# and checks, in a scratch copy of the workspace:
#   1. the build runs every material's action in substratec's persistent worker
#      (Bazel's "N worker" process count) and writes what one-shot
#      `substratec compile` writes, byte for byte;
#   2. a second build has nothing to do, and after one material changes exactly
#      one action runs (in the worker);
#   3. the same actions run one-shot (`--strategy=SubstrateCompile=standalone`:
#      `substratec compile @PARAMS`) write the same bytes.
#
#   check.sh SOURCE_DIR SUBSTRATEC WORK_DIR
set -euo pipefail
SOURCE="$1"
BIN="$2"
WORK="$3"
command -v bazel >/dev/null || { echo "bazel_example: no bazel (scripts/deps.sh installs bazel-bootstrap)" >&2; exit 1; }

# A fresh start: Bazel's action cache (under WORK) would otherwise remember the last run.
if [ -d "$WORK" ]; then chmod -R u+w "$WORK" && rm -rf "$WORK"; fi
mkdir -p "$WORK"
cp -RL "$SOURCE/examples/bazel" "$WORK/workspace"  # -L: the materials become files this test may touch
cd "$WORK/workspace"
# The workspace's tools/substratec runs the one on PATH; here it is the one under test.
ln -sf "$BIN" tools/substratec
materials=(car_paint row12_simple silk_in_plastic)

# Bazel's server and its caches live under WORK; --batch: no server stays behind.
bazel_build() {  # LOG ARGS...
  local log="$1"
  shift
  bazel --batch --nohome_rc --output_user_root="$WORK/bazel-root" build //... "$@" >"$log" 2>&1 || {
    cat "$log" >&2
    echo "bazel_example: the build failed" >&2
    exit 1
  }
}
expect_line() {  # LOG PATTERN WHAT
  grep -Eq "$2" "$1" || { cat "$1" >&2; echo "bazel_example: expected $3 (/$2/)" >&2; exit 1; }
}
same_outputs() {  # WHAT
  for m in "${materials[@]}"; do
    mkdir -p "$WORK/expected/$m"
    "$BIN" compile "materials/$m.json" -o "$WORK/expected/$m" >/dev/null
    diff -r "$WORK/expected/$m" "bazel-bin/$m" >&2 || { echo "bazel_example: $1: $m differs from one-shot" >&2; exit 1; }
  done
}

bazel_build "$WORK/first.log"
expect_line "$WORK/first.log" "INFO: [0-9]+ processes?: .*\b${#materials[@]} worker" "${#materials[@]} worker actions"
same_outputs "the worker's outputs"
echo "bazel_example: ${#materials[@]} materials built in the persistent worker, the same bytes as one-shot"

bazel_build "$WORK/again.log"
expect_line "$WORK/again.log" "INFO: 1 process: 1 internal" "nothing to do on a second build"
printf ' \n' >>materials/row12_simple.json
bazel_build "$WORK/touched.log"
expect_line "$WORK/touched.log" "INFO: [0-9]+ processes?: .*\b1 worker" "exactly one worker action after one material changed"
echo "bazel_example: after one material changed, one action ran"

bazel --batch --nohome_rc --output_user_root="$WORK/bazel-root" clean >/dev/null 2>&1
bazel_build "$WORK/standalone.log" --strategy=SubstrateCompile=standalone
expect_line "$WORK/standalone.log" "INFO: [0-9]+ processes?: .*\b${#materials[@]} (local|linux-sandbox|processwrapper-sandbox|standalone)" \
  "${#materials[@]} one-shot actions"
same_outputs "the one-shot (@PARAMS) outputs"
echo "bazel_example: the same actions one-shot (substratec compile @PARAMS) write the same bytes"

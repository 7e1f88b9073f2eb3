#!/usr/bin/env bash
# The second command: the whole test suite (installs and builds what it needs
# first, so it works on a fresh clone).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
cmake --preset default >/dev/null
cmake --build --preset default
ctest --preset default

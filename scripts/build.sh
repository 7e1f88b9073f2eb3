#!/usr/bin/env bash
# The first command: install what is missing, configure, build, and run the
# main job — `substratec report` over every bundled example.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
cmake --preset default >/dev/null
cmake --build --preset default
for f in examples/*.json; do
  build/bin/substratec report "$f"
  echo
done
# And one scene: its materials for its platform and the lighting they need (docs/scenes.md).
build/bin/substratec scene examples/scenes/street.json -o build/scenes/street >/dev/null
echo "scene street: build/scenes/street/scene.json"

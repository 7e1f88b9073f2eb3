#!/usr/bin/env bash
# Regenerates docs/gallery/: every example rendered by `substratec preview`
# (studio environment, 128 px) and the simplification sweep of the worked
# example, then docs/gallery.md. Run after scripts/build.sh; deterministic
# (the same build gives the same bytes).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/bin/substratec"
OUT="$ROOT/docs/gallery"
mkdir -p "$OUT"
{
  echo "# Gallery"
  echo
  echo "Every example in \`examples/\`, rendered by \`substratec preview FILE --size 128\` on lavapipe"
  echo "(the generated GLSL preview kernel: three lights and the procedural \"studio\" environment,"
  echo "exposed and white-balanced so that a Lambertian lands on its albedo at the centre; each texture"
  echo "bound to its input's \`file\` or, without one, to its neutral texel: docs/textures.md)."
  echo "Regenerate with \`scripts/gallery.sh\`."
  echo
  echo "| | | | |"
  echo "|---|---|---|---|"
  row=""
  n=0
  for f in "$ROOT"/examples/*.json; do
    stem="$(basename "$f" .json)"
    "$BIN" preview "$f" -o "$OUT/$stem.png" --size 128 >/dev/null 2>"$OUT/notes.tmp" || { cat "$OUT/notes.tmp" >&2; exit 1; }
    row="$row| ![$stem]($stem.png)<br>\`$stem\` "
    n=$((n + 1))
    if [ $((n % 4)) -eq 0 ]; then echo "$row|"; row=""; fi
  done
  if [ -n "$row" ]; then echo "$row|"; fi
  echo
  echo "## Simplification sweep"
  echo
  echo "\`substratec preview examples/worked_example_72.json --sweep --size 160\`: the material as"
  echo "authored, after each simplification step that changes its size, and fully simplified."
  echo
  "$BIN" preview "$ROOT/examples/worked_example_72.json" -o "$OUT/worked_example_72.sweep.png" --sweep --size 160 >/dev/null
  echo "![worked_example_72 sweep](worked_example_72.sweep.png)"
} > "$OUT/README.md.tmp"
sed 's|](\([a-z0-9_.]*\.png\))|](gallery/\1)|g' "$OUT/README.md.tmp" > "$ROOT/docs/gallery.md"
rm -f "$OUT/README.md.tmp" "$OUT/notes.tmp"
echo "wrote $ROOT/docs/gallery.md and $(ls "$OUT" | wc -l) images"

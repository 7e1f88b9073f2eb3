#!/usr/bin/env bash
# Regenerates docs/gallery/: every example rendered by `substratec preview`
# (studio environment, 128 px), the simplification sweep of the worked
# example and the MaterialX corpus on the shader ball (below), then
# docs/gallery.md. Run after scripts/build.sh; deterministic
# (the same build gives the same bytes).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/bin/substratec"
OUT="$ROOT/docs/gallery"
mkdir -p "$OUT"
# The MaterialX corpus on MaterialX's shader ball: every material of
# tests/import/corpus/materialx drawn by `render` at the console platform's
# budget and at the full budget, when the shared assets are next to the
# repository (or at SUBSTRATEC_MATERIALX_ASSETS): the mesh and images are not
# in the repository.
ASSETS="${SUBSTRATEC_MATERIALX_ASSETS:-$ROOT/../shared/corpus/assets/materialx}"
shaderball_section() {
  local bt='`'
  echo
  echo "## The MaterialX corpus on the shader ball"
  echo
  if [ ! -f "$ASSETS/Geometry/shaderball.glb" ]; then
    echo "(Not regenerated: MaterialX's shader ball was not found at ${bt}$ASSETS${bt}.)"
    return
  fi
  cat <<'EOF'
Every material of the MaterialX example documents in `tests/import/corpus/materialx`, imported on
the fly and drawn by `substratec render shaderball.glb --material DOC:NAME --size 96x96
--search-path ASSETS` on lavapipe (deferred: the emitted base passes, tile classification and
lighting; the "studio" environment and its key light) at the **full** budget (the file's own,
80 B), at the **console** platform's (`--platform console`: 48 B, 4 closures, no glints) and at
the **mobile** one's (`--platform mobile`: 20 B, one closure, no SSS, fuzz, glint or specular
profile). The bytes a pixel are those of the same simplification (`compile --platform P`'s
layout). Where a render is the same image as the one to its left, the cell says so: every
corpus material fits the console budget (36 B at most). Mesh and images: MaterialX's
`resources/` (Apache-2.0), at `../shared/corpus/assets/materialx`; a document whose image is not
there is listed with the error `render` gives (`brass_color.jpg`, `onyx_color.jpg`, the chess set's and the
boombox textures are missing from that snapshot).

| document | material | full | B | console | B | mobile | B |
|---|---|---|---:|---|---:|---|---:|
EOF
  local dir="$OUT/shaderball" tmp
  rm -rf "$dir"
  mkdir -p "$dir"
  tmp="$(mktemp -d)"
  for doc in "$ROOT"/tests/import/corpus/materialx/*/*.mtlx; do
    local rel="${doc#"$ROOT"/tests/import/corpus/}" stem
    stem="$(basename "$doc" .mtlx)"
    rm -rf "$tmp/import"
    if ! "$BIN" import "$doc" -o "$tmp/import" >/dev/null 2>"$tmp/err"; then
      echo "| ${bt}$rel${bt} | | not imported: $(grep -m1 -o 'error: .*' "$tmp/err" | cut -c1-160 | sed 's/|/\\|/g') | | | |"
      continue
    fi
    for json in "$tmp"/import/*.json; do
      local name cells="" first=""
      name="$(basename "$json" .json)"
      for budget in full console mobile; do
        local flags=() png="shaderball/$stem.$name.$budget.png" bytes
        [ "$budget" != full ] && flags=(--platform "$budget")
        if "$BIN" render "$ASSETS/Geometry/shaderball.glb" --material "$doc:$name" --size 96x96 \
             --search-path "$ASSETS" "${flags[@]}" -o "$OUT/$png" >/dev/null 2>"$tmp/err"; then
          # The bytes of the same simplification: compile's layout for that platform.
          rm -rf "$tmp/layout"
          "$BIN" compile "$json" "${flags[@]}" --target glsl --skip-validation -o "$tmp/layout" >/dev/null 2>&1
          bytes="$(sed -n 's/^  "bytes_per_pixel": \([0-9]*\),$/\1/p' "$tmp"/layout/*.layout.json | head -1)"
          if [ -n "$first" ] && cmp -s "$OUT/$first" "$OUT/$png"; then
            rm -f "$OUT/$png"
            cells="$cells| the same | $bytes "
          else
            cells="$cells| ![$name]($png) | $bytes "
            first="$png"
          fi
        else
          cells="$cells| $(grep -m1 -o 'error: .*' "$tmp/err" | cut -c1-160 | sed 's/|/\\|/g') | "
          if [ -z "$first" ]; then cells="$cells| | | | "; break; fi  # the other budgets fail alike
        fi
      done
      echo "| ${bt}$rel${bt} | ${bt}$name${bt} $cells|"
    done
  done
  rm -rf "$tmp"
}

{
  echo "# Gallery"
  echo
  echo "Every example in \`examples/\`, rendered by \`substratec preview FILE --size 128\` on lavapipe"
  echo "(the generated GLSL preview kernel: render's key light and the procedural \"studio\" environment,"
  echo "exposed and white-balanced so that a Lambertian lands on its albedo at the centre; each texture"
  echo "bound to its input's \`file\` or, without one, to its neutral texel: docs/textures.md). A volume"
  echo "(\`fog_*\`: a volumetric fog cloud) is marched through the cube [-1.2, 1.2]^3 instead of a sphere."
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
  shaderball_section
} > "$OUT/README.md.tmp"
sed 's|](\([A-Za-z0-9_./-]*\.png\))|](gallery/\1)|g' "$OUT/README.md.tmp" > "$ROOT/docs/gallery.md"
rm -f "$OUT/README.md.tmp" "$OUT/notes.tmp"
echo "wrote $ROOT/docs/gallery.md and $(ls "$OUT" | wc -l) images"

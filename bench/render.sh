#!/usr/bin/env bash
# `substratec render` of a mesh at 512 x 512 on lavapipe (issue 20; docs/performance.md,
# "render"): each pass's time (`--timings`: the GPU timestamps of the raster passes, the
# host wall time of every submission — the timestamps of render's compute dispatches read
# implausibly low, docs/performance.md says more), the wall time and the peak memory (GNU time's maximum resident set) of the
# whole command, deferred and forward, GLSL and HLSL. Works from any directory.
#
#   RENDER_MESH      [../shared/corpus/assets/materialx/Geometry/shaderball.glb] the glTF/.glb drawn
#   RENDER_MATERIAL  [examples/car_paint.json]  drawn on every primitive (--material)
#   RENDER_SIZE      [512x512]
#   RENDER_RUNS      [3]   runs per row (each a fresh process; the median wall time is printed)
#   RENDER_BUILD     [build] build directory with bin/substratec
#
# Exit status: 0 on success, 2 when the build or a render fails. It judges nothing.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
mesh="${RENDER_MESH:-$root/../shared/corpus/assets/materialx/Geometry/shaderball.glb}"
material="${RENDER_MATERIAL:-$root/examples/car_paint.json}"
size="${RENDER_SIZE:-512x512}"
runs="${RENDER_RUNS:-3}"
build="${RENDER_BUILD:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
bin="$build/bin/substratec"
[ -x "$bin" ] || { echo "render.sh: no $bin (build first: cmake --build --preset default)" >&2; exit 2; }
[ -f "$mesh" ] || { echo "render.sh: no mesh $mesh (set RENDER_MESH)" >&2; exit 2; }
command -v /usr/bin/time >/dev/null || { echo "render.sh: needs GNU time (Debian: time)" >&2; exit 2; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1-3 /proc/loadavg), $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
echo "mesh: $(basename "$mesh"), material: $(basename "$material"), $size"
echo
echo "| path | target | opaque GPU ms | opaque wall ms | classify wall ms | lighting wall ms | forward wall ms | command wall s (median of $runs) | peak RSS MiB |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
for path in deferred forward; do
  for target in glsl hlsl; do
    flags=(--target "$target")
    [ "$path" = forward ] && flags+=(--forward)
    walls=()
    line=""
    rss=0
    for ((i = 0; i < runs; i++)); do
      if ! /usr/bin/time -f '%e %M' -o "$out/time" "$bin" render "$mesh" --material "$material" --size "$size" \
           -o "$out/r.png" --timings "${flags[@]}" > "$out/stdout" 2> "$out/stderr"; then
        cat "$out/stderr" >&2
        exit 2
      fi
      read -r wall kb < "$out/time"
      walls+=("$wall")
      rss=$(( kb > rss ? kb : rss ))
      gpu="$(grep '^GPU ms' "$out/stdout")"
      line="$(grep '^wall ms' "$out/stdout")"
    done
    median="$(printf '%s\n' "${walls[@]}" | sort -g | sed -n "$(( (runs + 1) / 2 ))p")"
    # "... ms (...): opaque A, classify B, lighting C, forward D" (the last run's)
    fields='s/.*opaque ([0-9.]+), classify ([0-9.]+), lighting ([0-9.]+), forward ([0-9.]+).*/\1 \2 \3 \4/'
    read -r gpuOpaque _ < <(echo "$gpu" | sed -E "$fields")
    read -r opaque classify lighting forward < <(echo "$line" | sed -E "$fields")
    echo "| $path | $target | $gpuOpaque | $opaque | $classify | $lighting | $forward | $median | $(( rss / 1024 )) |"
  done
done

#!/usr/bin/env bash
# Times every stage of every backend on the thesis-sized scenes with
# `cloudbench run` (the thesis's per-step timing: wall time around each stage
# call, device time from GPU timestamp queries) and keeps each run's
# results.json under reports/backends/<scene>/<variant>/. The OpenGL automaton
# is also run in the thesis's RGBA8 layout (simulation stages only).
# tools/backend_table.py prints the tables of docs/performance.md from them.
# Usage: tools/bench_backends.sh [scene ...]   (default: thesis-low thesis-medium thesis-high)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cli="$root/build/release/cloudbench"
if [ ! -x "$cli" ]; then
  cmake --preset release -S "$root" >/dev/null
  cmake --build "$root/build/release" --target cloudbench
fi
scenes=("$@")
[ ${#scenes[@]} -eq 0 ] && scenes=(thesis-low thesis-medium thesis-high)
# 100 warm-up steps (the scenes' own), then 30 timed steps with a frame every 10.
common=(--steps 130 --set warmup_steps=100 --set render.every_steps=10 --quiet)
for scene in "${scenes[@]}"; do
  out="$root/reports/backends/$scene"
  for backend in cpu vk gl; do
    "$cli" run "$scene" --backend "$backend" "${common[@]}" --out "$out/$backend" || echo "bench: $backend on $scene failed"
  done
  "$cli" run "$scene" --backend gl --gl-ca-layout rgba8 "${common[@]}" \
    --set 'stages=["region","ca","smooth","density"]' --out "$out/gl-rgba8" || echo "bench: gl rgba8 on $scene failed"
  # Keep the numbers, not the images.
  find "$out" -name '*.exr' -o -name '*.png' | xargs -r rm -f
done
echo "wrote $root/reports/backends/"

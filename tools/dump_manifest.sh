#!/usr/bin/env bash
# The array-for-array fingerprint of every backend's dumps, for refactors that
# must change no result: sha256 of each .npy, and of each frame's EXR with its
# capture date blanked (the only field that differs between runs). The scenes
# cover every renderer: the splat path with wind and the ground shadow, the ray
# march over noise with lightning and with its light options, and the layers with each opacity and relighting.
# usage: tools/dump_manifest.sh BUILD_DIR OUT_FILE
set -euo pipefail
bin="$1/cloudbench"; out="$2"
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
for be in cpu vk gl; do
  "$bin" dump ci-small --backend "$be" --steps 6 --set 'ca.wind_shift=[[1,0]]' --out "$work/ci-$be" --quiet >/dev/null
done
"$bin" dump thesis-low --backend cpu --steps 4 --out "$work/low-cpu" --quiet >/dev/null
for be in cpu vk gl; do
  for scene in ci-small-wind ground-shadow noise-layer lightning; do
    "$bin" dump "$scene" --backend "$be" --steps 2 --out "$work/$scene-$be" --quiet >/dev/null
  done
done
for be in cpu vk gl; do
  "$bin" dump layers-small --backend "$be" --steps 2 --out "$work/layers-$be" --quiet >/dev/null
  "$bin" dump layers-small --backend "$be" --steps 2 --set 'layers.wang={"coverage":0.6,"density":2}' \
    --set layers.relight=vector --set 'sun.speed={"azimuth_deg":20}' --out "$work/layers-wang-$be" --quiet >/dev/null
  "$bin" dump noise-layer --backend "$be" --steps 2 --set march.light=march --set 'march.powder={"enabled":true}' \
    --set 'march.adaptive={"enabled":true}' --set march.jitter=true --set phase.function=mie --out "$work/march-options-$be" --quiet >/dev/null
done
( cd "$work"
  for f in $(find . -name '*.npy' | sort); do echo "$(sha256sum < "$f" | cut -c1-64)  $f"; done
  for f in $(find . -name '*.exr' | sort); do
    echo "$(LC_ALL=C sed -E 's/[0-9]{4}:[0-9]{2}:[0-9]{2} [0-9]{2}:[0-9]{2}:[0-9]{2}/DATE/' "$f" | sha256sum | cut -c1-64)  $f"
  done ) > "$out"
echo "$(wc -l < "$out") arrays fingerprinted into $out"

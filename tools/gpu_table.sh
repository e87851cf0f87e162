#!/usr/bin/env bash
# The measurements to make on a real GPU, in one call of a few minutes.
# Here:       cmake --workflow --preset release, then tools/bundle.sh build/release bundle (docs/gpu.md)
# GPU host:   . bundle/env.sh && tools/gpu_table.sh "$OUT"      (carry bundle/; $OUT comes back)
# Writes to DIR (default /tmp/gpu16): devices.txt, conform-*.txt, run-*.txt with their results.json,
# gtest-*.txt, and summary.txt, the lines for a new dated report under reports/perf/. Every command has
# its own time limit, so one that hangs costs only itself.
set -uo pipefail
out=${1:-/tmp/gpu16}
mkdir -p "$out"
cli=${CLOUDBENCH_CLI:-bundle/bin/cloudbench}
tests=${CLOUDBENCH_TESTS:-bundle/bin/cloudbench_tests}
scenes=${CLOUDBENCH_SCENES:-bundle/share/cloudbench/scenes}
[ -x "$cli" ] || { echo "gpu_table: no $cli; make it with tools/bundle.sh (docs/gpu.md)" >&2; exit 1; }
step() {  # step NAME SECONDS COMMAND...: runs it, keeps its output and exit status
    local name=$1 limit=$2; shift 2
    echo "== $name: $*" | tee -a "$out/summary.txt"
    local t0=$SECONDS
    timeout "$limit" "$@" >"$out/$name.txt" 2>&1
    echo "   exit $?, $((SECONDS - t0)) s" | tee -a "$out/summary.txt"
}
step devices 60 "$cli" devices
# Conformance on the GPU (SPEC's rules, storage quanta as integer codes).
step conform-ci-small 120 "$cli" conform "$scenes/ci-small.json" --gl-context egl --out "$out/conform-ci-small"
step conform-thesis-medium 300 "$cli" conform "$scenes/thesis-medium.json" --gl-context egl --steps 120 \
    --out "$out/conform-thesis-medium"
# The real-GPU table (docs/performance.md, "Real GPUs"): thesis-medium per stage, both timing modes, both
# cameras every step.
step run-thesis-medium 300 "$cli" run "$scenes/thesis-medium.json" --backend vk,gl,cpu --gl-context egl \
    --timing both --steps 140 --set warmup_steps=100 --set render.every_steps=1 --out "$out/run-thesis-medium"
# thesis-high at 1920 x 1080 (the table's last row).
step run-thesis-high-1080p 300 "$cli" run "$scenes/thesis-high.json" --backend vk,gl,cpu --gl-context egl \
    --timing both --steps 120 --set warmup_steps=100 --set render.every_steps=1 \
    --set render.width=1920 --set render.height=1080 --out "$out/run-thesis-high-1080p"
# The 1024 x 1024 x 64 grid: region's tile lists and shade at scale.
step run-1024x1024x64 300 "$cli" run "$scenes/thesis-medium.json" --backend vk,gl,cpu --gl-context egl \
    --timing both --steps 6 --set warmup_steps=2 --set 'grid.size=[1024,1024,64]' \
    --set ellipsoids.target_count=640 --set render.every_steps=0 --out "$out/run-1024x1024x64"
# One round trip's cost, batched against one by one, and shade's blocks against per-slice dispatches.
step gtest-pipelined 300 "$tests" --gtest_also_run_disabled_tests --gtest_filter='*DISABLED_ThesisMediumNumbers*'
step gtest-shade-blocks 300 "$tests" --gtest_also_run_disabled_tests --gtest_filter='ShadeBlockVk.DISABLED_Bench'
# The summary: each run's per-stage lines and its timing line.
for r in run-thesis-medium run-thesis-high-1080p run-1024x1024x64; do
    echo "== $r" >>"$out/summary.txt"
    grep -E "^backend|^  [a-z_]+ +[0-9]|frame |pipelined|synchronized" "$out/$r.txt" >>"$out/summary.txt"
done
grep -hE "pass|fail" "$out"/conform-*.txt | head -60 >>"$out/summary.txt"
cat "$out/summary.txt"

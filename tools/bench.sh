#!/usr/bin/env bash
# Runs the CPU stage benchmarks on the thesis-sized scenes and the machine
# figures, 10 repetitions each, and writes reports/bench-cpu.json (Google
# Benchmark's JSON: every repetition plus mean, median, stddev and cv); then
# the exact reference's benchmarks into reports/bench-reference.json.
# Usage: tools/bench.sh [extra Google Benchmark flags for the CPU stages]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bench="$root/build/release/tests/cloudbench_bench_cpu"
if [ ! -x "$bench" ] || [ ! -x "$root/build/release/tests/cloudbench_bench_reference" ]; then
  cmake --preset release -S "$root" >/dev/null
  cmake --build "$root/build/release" --target cloudbench_bench_cpu cloudbench_bench_reference
fi
mkdir -p "$root/reports"
"$bench" --benchmark_filter='thesis|Machine' --benchmark_repetitions=10 --benchmark_min_time=0.1 \
  --benchmark_report_aggregates_only=false --benchmark_display_aggregates_only=true \
  --benchmark_out="$root/reports/bench-cpu.json" --benchmark_out_format=json "$@"
echo "wrote $root/reports/bench-cpu.json"
# The exact reference's speed (docs/accuracy.md): rays per second per scene.
"$root/build/release/tests/cloudbench_bench_reference" --benchmark_filter=thesis --benchmark_repetitions=5 \
  --benchmark_min_time=0.5 --benchmark_display_aggregates_only=true \
  --benchmark_out="$root/reports/bench-reference.json" --benchmark_out_format=json
echo "wrote $root/reports/bench-reference.json"

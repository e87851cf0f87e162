#!/usr/bin/env python3
"""Prints reports/bench-cpu.json (Google Benchmark, with repetitions) as a
Markdown table: median, standard deviation and coefficient of variation of
the wall time of each benchmark, in milliseconds."""
import json
import sys
from pathlib import Path

path = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent.parent / "reports" / "bench-cpu.json")
doc = json.loads(path.read_text())
rows = {}
for b in doc["benchmarks"]:
    if b.get("run_type") == "aggregate":
        rows.setdefault(b["run_name"], {})[b["aggregate_name"]] = b
scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
print("| benchmark | median ms | std dev ms | cv | rate |")
print("|---|---:|---:|---:|---|")
for name, agg in rows.items():
    med, sd = agg["median"], agg["stddev"]
    k = scale[med["time_unit"]]
    rate = ""
    if "bytes_per_second" in med:
        rate = f"{med['bytes_per_second'] / 1e9:.1f} GB/s"
    elif "items_per_second" in med:
        rate = f"{med['items_per_second'] / 1e9:.2f} G/s"
    cv = agg.get("cv", {}).get("real_time", 0.0)
    print(f"| {name} | {med['real_time'] * k:.3f} | {sd['real_time'] * k:.3f} | {100 * cv:.1f} % | {rate} |")
ctx = doc["context"]
repetitions = next(iter(rows.values()))["median"].get("repetitions", "?")
print(f"\n{ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, {ctx.get('date')}; {repetitions} repetitions each.")

#!/usr/bin/env python3
"""The tables of docs/performance.md "All three backends side by side", from
reports/backends/<scene>/<variant>/results.json (tools/bench_backends.sh):
thesis-medium in full (median ms [q1-q3] and the device time), then
thesis-low and thesis-high as medians."""
import json
import pathlib
import sys

STAGES = ["region", "ca", "smooth", "density", "shade", "shadow"]
VARIANTS = ["cpu", "vk", "gl", "gl-rgba8"]
CAMERAS = [("above", "frame above (1024x768)"), ("ground", "frame ground")]


def fmt(x):
    return f"{x:.3g}" if x < 10 else (f"{x:.1f}" if x < 100 else f"{x:.0f}")


def load(root, scene, variant):
    path = root / scene / variant / "results.json"
    if not path.exists():
        return {}
    backends = json.loads(path.read_text())["backends"]
    return next(iter(backends.values()), {}) or {}


def full_table(runs):
    lines = ["| stage | " + " | ".join(VARIANTS) + " |", "|---|" + "---:|" * len(VARIANTS)]
    for stage in STAGES:
        row = []
        for v in VARIANTS:
            e = runs[v].get("stages", {}).get(stage)
            text = f"{fmt(e['median_ms'])} [{fmt(e['q1_ms'])}-{fmt(e['q3_ms'])}]" if e else ""
            if e and e.get("device"):
                text += f" dev {fmt(e['device']['median_ms'])}"
            row.append(text)
        lines.append(f"| {stage} | " + " | ".join(row) + " |")
    for camera, label in CAMERAS:
        row = []
        for v in VARIANTS:
            f = runs[v].get("frames", {}).get(camera)
            row.append(f"{fmt(f['median_ms'])} [{fmt(f['q1_ms'])}-{fmt(f['q3_ms'])}], {f['fps_median']:.1f} fps" if f else "")
        lines.append(f"| {label} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def median_table(scenes):
    header = [f"{name.split('-')[1]} {v}" for name, _ in scenes for v in VARIANTS]
    lines = ["| stage | " + " | ".join(header) + " |", "|---|" + "---:|" * len(header)]
    for key, label in [(s, s) for s in STAGES] + [(c, f"frame {c}") for c, _ in CAMERAS]:
        row = []
        for _, runs in scenes:
            for v in VARIANTS:
                r = runs[v]
                e = r.get("frames", {}).get(key) if key in ("above", "ground") else r.get("stages", {}).get(key)
                row.append(fmt(e["median_ms"]) if e else "")
        lines.append(f"| {label} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "reports/backends")
    runs = {s: {v: load(root, s, v) for v in VARIANTS} for s in ["thesis-low", "thesis-medium", "thesis-high"]}
    print("### thesis-medium\n")
    print(full_table(runs["thesis-medium"]))
    print("\n### thesis-low and thesis-high (median ms)\n")
    print(median_table([("thesis-low", runs["thesis-low"]), ("thesis-high", runs["thesis-high"])]))


if __name__ == "__main__":
    main()

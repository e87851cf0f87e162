#!/usr/bin/env python3
"""Markdown tables of reports/backends/<scene>/<variant>/results.json
(tools/bench_backends.sh): per stage and backend, the median wall time with
its quartiles, and the device time where the backend measures one."""
import json
import pathlib
import sys

STAGES = ["region", "ca", "smooth", "density", "shade", "shadow", "render_splat"]
VARIANTS = ["cpu", "vk", "gl", "gl-rgba8"]


def cell(entry):
    if not entry:
        return ""
    text = f"{entry['median_ms']:.2f} [{entry['q1_ms']:.2f}-{entry['q3_ms']:.2f}]"
    device = entry.get("device")
    if device:
        text += f" dev {device['median_ms']:.2f}"
    return text


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "reports/backends")
    for scene in sorted(p for p in root.iterdir() if p.is_dir()):
        runs = {}
        for variant in VARIANTS:
            path = scene / variant / "results.json"
            if path.exists():
                data = json.loads(path.read_text())["backends"]
                runs[variant] = next(iter(data.values())) if data else None
        if not runs:
            continue
        print(f"\n### {scene.name}: median ms [q1-q3], device ms\n")
        print("| stage | " + " | ".join(runs) + " |")
        print("|---|" + "---:|" * len(runs))
        for stage in STAGES:
            row = [cell((r or {}).get("stages", {}).get(stage)) for r in runs.values()]
            if any(row):
                print(f"| {stage} | " + " | ".join(row) + " |")
        cameras = sorted({c for r in runs.values() if r for c in r.get("frames", {})})
        for camera in cameras:
            row = []
            for r in runs.values():
                frame = (r or {}).get("frames", {}).get(camera)
                row.append(f"{frame['median_ms']:.1f} [{frame['q1_ms']:.1f}-{frame['q3_ms']:.1f}], {frame['fps_median']:.1f} fps"
                           if frame else "")
            print(f"| frame {camera} | " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()

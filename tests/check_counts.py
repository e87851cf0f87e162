#!/usr/bin/python3
"""Checks cloudbench-count/1 files of exact mode (docs/performance.md).

  check_counts.py same A.json B.json
      the same scene counted twice: every stage's total and every step's count
      identical (render_splat's within 1e-5: see same()), and the simulation
      stages all counted (non-zero).
  check_counts.py more SMALL.json LARGE.json STAGE[,STAGE...]
      LARGE ran the same scene with twice the voxels: each named stage, whose
      work is a pass over every voxel, counts more than 2 % more (the exact
      mode's gate) and at most 2.5 times as much.
"""
import json
import sys

SIMULATION_STAGES = ["region", "ca", "smooth", "density"]
LAYOUT_SENSITIVE = {"render_splat"}


def load(path):
    with open(path) as f:
        doc = json.load(f)
    assert doc["format"] == "cloudbench-count/1", doc.get("format")
    assert "provenance" in doc, "no provenance"
    (scene, by_backend), = doc["instructions"].items()
    return doc, by_backend["cpu"], doc["per_step"][scene]["cpu"]


def same(a_path, b_path):
    a, a_totals, a_steps = load(a_path)
    b, b_totals, b_steps = load(b_path)
    for stage in SIMULATION_STAGES:
        assert a_totals.get(stage, 0) > 0, f"{stage} not counted: {a_totals}"
    # render_splat alone may move by a few instructions: on 2026-12-07 (an AVX2-only machine) two identical ctest
    # counts of ci-small gave 5787851 and 5787816 (6e-6) in 3 of 5 runs, every other stage identical, while six
    # counts run by hand all gave 5787851; where the heap puts its buffers moves the vectorised stages' counts
    # (tests/exact.cmake). It is held to 1e-5 of its count; every other stage to the instruction.
    def close(stage, x, y):
        return x == y or (stage in LAYOUT_SENSITIVE and abs(x - y) <= 1e-5 * max(x, y))
    assert a_totals.keys() == b_totals.keys(), f"stages differ:\n{a_totals}\n{b_totals}"
    for stage in a_totals:
        assert close(stage, a_totals[stage], b_totals[stage]), f"totals differ:\n{a_totals}\n{b_totals}"
        assert a_steps[stage].keys() == b_steps[stage].keys(), f"{stage}: counted steps differ"
        for step, n in a_steps[stage].items():
            assert close(stage, n, b_steps[stage][step]), f"{stage}: step {step} counts differ"
    first, last = a["counted_steps"]
    for stage, total in a_totals.items():
        counted = sum(n for step, n in a_steps[stage].items() if first <= int(step) <= last)
        assert counted == total, f"{stage}: total {total} is not the sum of its counted steps {counted}"
    print("identical:", ", ".join(f"{s} {n}" for s, n in sorted(a_totals.items())))


def more(small_path, large_path, stages):
    _, small, _ = load(small_path)
    _, large, _ = load(large_path)
    for stage in stages.split(","):
        ratio = large[stage] / small[stage]
        print(f"{stage}: {small[stage]} -> {large[stage]} instructions, x{ratio:.3f}")
        assert 1.02 < ratio <= 2.5, f"{stage}: twice the voxels counted x{ratio:.3f}, not in (1.02, 2.5]"
    print("twice the work counted more")


if __name__ == "__main__":
    mode, *args = sys.argv[1:]
    {"same": same, "more": more}[mode](*args)

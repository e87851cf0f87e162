#!/usr/bin/python3
"""Multiple-scattering octaves that change neither the extinction nor the phase (a = c = 1) scale the sun's light by
1 + b + ... + b^(n-1) (n with b = 1, which a <= b then requires): with no ambient light and a black background every renderer's image, on every backend, is
then the single-scattering image times that sum (the light enters each renderer linearly). A renderer that ignored
the octaves, or applied them twice, fails; conform alone cannot see either, since every backend would share it.

    check_octaves_scale.py CLI OUT
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_bad_inputs import exr_floats, run_every_backend  # noqa: E402

HERE = Path(__file__).resolve().parent
# name: (scene, steps): ci-small's automaton needs a few steps to form clouds.
SCENES = {"ci-small": ("ci-small", 12), "imgacc-small": (str(HERE / "scenes/imgacc-small.json"), 1),
          "layers-small": ("layers-small", 1)}
N, B = 3, 1.0  # a <= b: with a = 1, b is 1 too
FACTOR = sum(B ** i for i in range(N))  # 3


def run(cli, scene, steps, out, octaves):
    sets = ["lighting.ambient=[0,0,0]", "lighting.background=[0,0,0]"]
    if octaves:
        sets.append(f'lighting.octaves={{"count":{N},"attenuation":1,"contribution":{B},"eccentricity":1}}')
    run_every_backend(cli, scene, steps, out, sets)


def main():
    cli, out = sys.argv[1], Path(sys.argv[2])
    compared = 0
    for name, (scene, steps) in SCENES.items():
        single, octaves = out / f"{name}-single", out / f"{name}-octaves"
        run(cli, scene, steps, single, False)
        run(cli, scene, steps, octaves, True)
        for frame in sorted(single.glob("frame-*.exr")):
            a, b = exr_floats(frame), exr_floats(octaves / frame.name)
            assert a.max() > 0, f"{name} {frame.name}: the single-scattering image is black"
            worst = float(np.max(np.abs(b - FACTOR * a)) / a.max())
            print(f"{name} {frame.name}: worst |octaves - {FACTOR} single| / max = {worst:.2e}")
            assert worst <= 1e-5, f"{name} {frame.name}: the octaves do not scale the image by {FACTOR}"
            compared += 1
    assert compared >= 3, f"only {compared} frames compared"
    print(f"octaves scale: ok ({compared} frames)")


if __name__ == "__main__":
    main()

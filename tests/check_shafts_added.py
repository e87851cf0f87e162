#!/usr/bin/python3
"""Shafts of light are added after the renderer (SPEC 18): on every backend, every renderer's frame with the shafts
minus the same frame without them is the shells' light, which does not depend on the renderer. So the differences of
two renderers of one camera agree, each backend's agree with the CPU's, and they are not zero. A renderer whose
frames miss the shafts on every backend alike passes conform; it fails here.

    check_shafts_added.py CLI OUT
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_bad_inputs import exr_floats, run_every_backend  # noqa: E402

SHAFTS = '{"shells":24,"extinction":0.0002,"falloff_deg":60}'
# name: (scene, steps, extra --set): crepuscular's automaton needs a few steps to form clouds; layers-small runs
# the density stage for the shafts' D.
SCENES = {"crepuscular": ("crepuscular", 8, []),
          "layers-small": ("layers-small", 1, ['stages=["noise","density","shade","render_layers","render_march"]'])}


def run(cli, scene, steps, extra, out, shafts):
    run_every_backend(cli, scene, steps, out, extra + ([f"lighting.shafts={SHAFTS}"] if shafts else []))


def main():
    cli, out = sys.argv[1], Path(sys.argv[2])
    compared = 0
    for name, (scene, steps, extra) in SCENES.items():
        plain, shafts = out / f"{name}-plain", out / f"{name}-shafts"
        run(cli, scene, steps, extra, plain, False)
        run(cli, scene, steps, extra, shafts, True)
        added = {}  # (camera, backend): {renderer: the difference}
        for frame in sorted(plain.glob("frame-*.exr")):
            _, renderer, rest = frame.stem.split("-", 2)
            camera, backend = rest.rsplit("-", 1)
            added.setdefault((camera, backend), {})[renderer] = exr_floats(shafts / frame.name) - exr_floats(frame)
        for (camera, backend), by_renderer in sorted(added.items()):
            cpu = added[(camera, "cpu")]
            for renderer, difference in by_renderer.items():
                peak = float(np.max(np.abs(cpu[renderer])))
                assert peak > 1e-4, f"{name} {camera} {renderer} {backend}: the shafts add nothing (peak {peak:.2e})"
                for other, theirs in list(by_renderer.items()) + [("cpu " + renderer, cpu[renderer])]:
                    worst = float(np.max(np.abs(difference - theirs))) / peak
                    assert worst <= 1e-4, (f"{name} {camera}: {renderer} on {backend} adds other shafts than {other} "
                                           f"(worst {worst:.2e} of the peak)")
                print(f"{name} {camera} {renderer} {backend}: shafts peak {peak:.3g}, agree")
                compared += 1
    assert compared >= 6, f"only {compared} frames compared"
    print(f"shafts added: ok ({compared} frames)")


if __name__ == "__main__":
    main()

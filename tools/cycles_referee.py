#!/usr/bin/python3
"""Blender's Cycles as an outside referee for cloudbench's exact reference render (docs/accuracy.md, "Cycles as an
outside referee").

    tools/cycles_referee.py SCENE [--cli BUILD/cloudbench] [--out DIR] [--samples N] [--bounces N] [--check]

1. `cloudbench dump SCENE --reference --vdb` writes the last step's q as OpenVDB (q.vdb) and the exact reference
   render of the first camera (frame-reference-<camera>.exr: single scattering of the sun through the trilinear
   field, exact light); the render_march frame too. A second dump with multiple forward scattering
   (shade.scattering, albedo 1) gives the march's frame with seed 002's light.
2. Blender's Cycles (tools/cycles_render.py, `blender -b --factory-startup --python`) renders q.vdb with the same
   camera, sun, sigma and Henyey-Greenstein g, twice (seeds 1 and 2): with no volume bounce (single scattering) and
   with --bounces (multiple scattering).
3. Single scattering: the mean of the two seeds against the reference. Where only Monte-Carlo noise separates
   them, their RMS difference is the noise's RMS (estimated from the two seeds' difference) and the image totals
   differ by a few standard errors. --check exits 1 unless the RMS ratio is at most 1.5 and the totals' relative
   difference at most 4 standard errors plus 0.002 (the bounds' reasons at RMS_RATIO_BOUND below).
4. Multiple scattering: how far each of cloudbench's images (the single-scattering reference, the march with the
   scene's settings, the march with multiple forward scattering, and with --octaves the march and the exact-light
   render with multiple-scattering octaves) is from Cycles with many bounces.
Writes DIR/referee.json and DIR/referee.md (DIR: --out, default out/<scene>/referee).

The scene must state every field the referee reads (grid, sun, phase, shade.sigma, render, the first camera) and
light the clouds by the sun alone: no ambient light, a black background, Henyey-Greenstein phase, no powder, no
tiling, no sky light, no point light, no eye scattering or city glow.
"""
import argparse
import json
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RENDER_SCRIPT = HERE / "cycles_render.py"


class SceneError(Exception):
    pass


def need(scene, path, file):
    """The scene's value at dotted `path`, which the referee needs stated in the file."""
    node = scene
    for key in path.split("."):
        if not isinstance(node, dict) or key not in node:
            raise SceneError(f"{file}: {path}: the Cycles referee needs this field stated in the scene")
        node = node[key]
    return node


def scene_parameters(scene, file):
    """What Cycles needs from the scene, after refusing what it does not model."""
    phase = need(scene, "phase.function", file)
    if phase != "henyey-greenstein":
        raise SceneError(f"{file}: phase.function: the referee compares Henyey-Greenstein only, got '{phase}'")
    for field in ("ambient", "background"):
        value = need(scene, f"lighting.{field}", file)
        if any(v != 0 for v in value):
            raise SceneError(f"{file}: lighting.{field}: must be [0, 0, 0]: Cycles is lit by the sun alone")
    extra = set(scene.get("lighting", {})) - {"ambient", "background"}
    if extra:
        raise SceneError(f"{file}: lighting.{sorted(extra)[0]}: the referee models the sun alone")
    if scene.get("grid", {}).get("tiling"):
        raise SceneError(f"{file}: grid.tiling: the referee renders one volume, not a tiled one")
    if scene.get("march", {}).get("powder"):
        raise SceneError(f"{file}: march.powder: not a physical term; the referee needs it off")
    if "lightning" in scene or "sky" in scene:
        raise SceneError(f"{file}: {'lightning' if 'lightning' in scene else 'sky'}: the referee models the sun alone")
    cameras = need(scene, "render.cameras", file)
    if not cameras:
        raise SceneError(f"{file}: render.cameras: the referee needs a camera")
    camera = cameras[0]
    for key in ("name", "eye", "target", "fov_deg", "near", "far"):
        need(camera, key, f"{file}: render.cameras[0]")
    size = need(scene, "grid.size", file)
    h = need(scene, "grid.voxel_size", file)
    origin = need(scene, "grid.origin", file)
    el = math.radians(need(scene, "sun.elevation_deg", file))
    az = math.radians(need(scene, "sun.azimuth_deg", file))
    return {
        "camera": camera["name"],
        "sigma": need(scene, "shade.sigma", file),
        "g": need(scene, "phase.g", file),
        "sun_direction": [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)],
        "sun_color": need(scene, "sun.color", file),
        "sun_intensity": need(scene, "sun.intensity", file),
        "width": need(scene, "render.width", file),
        "height": need(scene, "render.height", file),
        "eye": camera["eye"], "target": camera["target"], "up": camera.get("up", [0, 0, 1]),
        "fov_deg": camera["fov_deg"], "near": camera["near"], "far": camera["far"],
        "box_lo": list(origin),
        "box_hi": [origin[a] + size[a] * h for a in range(3)],
        # Blender centres a VDB's voxel i at index i + 1/2 (tools/cycles_render.py): half a voxel back.
        "volume_offset": [-0.5 * h] * 3,
        "grid": "q",
    }


def run(command, what):
    started = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"cycles_referee: {what} failed (exit {done.returncode}): {' '.join(map(str, command))}\n"
                 f"{done.stdout[-2000:]}{done.stderr[-2000:]}")
    return time.monotonic() - started


def blender(blender_bin, params, path):
    path.write_text(json.dumps(params, indent=1))
    return run([blender_bin, "-b", "--factory-startup", "--python", str(RENDER_SCRIPT), "--", str(path)],
               f"Blender ({path.name})")


def compare_noisy(ours, a, b):
    """Cycles' two seeds a and b against cloudbench's image `ours` (each (height, width, 3), linear)."""
    m, e = (a + b) / 2, (a - b) / 2  # the estimate, and a residual with (for independent seeds) its noise's variance
    total = float(ours.sum())
    mse = float(np.mean((m - ours) ** 2))
    peak = float(m.max()) if m.max() > 0 else 1.0
    lit = (ours > 0) | (m > 0)
    return {
        "total_ours": total,
        "total_cycles": float(m.sum()),
        "relative_difference": (float(m.sum()) - total) / total if total > 0 else float("nan"),
        "relative_noise": float(np.sqrt((e ** 2).sum())) / total if total > 0 else float("nan"),
        "rms_difference": math.sqrt(mse),
        "rms_noise": float(np.sqrt(np.mean(e ** 2))),
        "rms_ratio": math.sqrt(mse / float(np.mean(e ** 2))) if np.any(e) else float("inf"),
        "seed_correlation": float(np.corrcoef((a - ours)[lit], (b - ours)[lit])[0, 1]) if lit.sum() > 2 else 0.0,
        "psnr_db": 10 * math.log10(peak * peak / mse) if mse > 0 else float("inf"),
    }


# Only noise between the images: the RMS difference is the noise's RMS (ratio 1) and the totals differ by a few
# standard errors. The two seeds' errors are correlated (0.17 to 0.18 measured on cycles-small at 128 x 96: Cycles'
# sampling patterns are not independent across seeds), which makes their difference underestimate the noise by
# sqrt(1.18 / 0.82) = 1.2; the bound 1.5 leaves room for that. The totals may also differ by the reference's own step error (1/8 voxel:
# below 1e-3 relative here) and Cycles' ray-marching step: 0.002.
RMS_RATIO_BOUND = 1.5
TOTAL_ALLOWANCE = 0.002


def agrees(c):
    c["rms_ratio_bound"] = RMS_RATIO_BOUND
    c["total_bound"] = 4 * c["relative_noise"] + TOTAL_ALLOWANCE
    return c["rms_ratio"] <= RMS_RATIO_BOUND and abs(c["relative_difference"]) <= c["total_bound"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="a scene file that states every field the referee reads")
    ap.add_argument("--cli", default=str(HERE.parent / "build/release/cloudbench"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--out", help="output folder (default out/<scene>/referee)")
    ap.add_argument("--samples", type=int, default=128, help="Cycles samples a pixel, each seed (default 128)")
    ap.add_argument("--bounces", type=int, default=32, help="volume bounces of the multiple-scattering render; 0 skips it")
    ap.add_argument("--step-rate", type=float, default=0.1, help="Cycles' ray-marching step, in voxels (default 0.1)")
    ap.add_argument("--set", action="append", default=[], metavar="PATH=VALUE", help="passed to cloudbench")
    ap.add_argument("--octaves", action="append", default=[], metavar="N,A,B,C",
                    help="also measure render_march and the exact-light render with these multiple-scattering "
                         "octaves (lighting.octaves count, attenuation, contribution, eccentricity) against Cycles' "
                         "multiple scattering; repeatable")
    ap.add_argument("--cycles-param", action="append", default=[], metavar="NAME=JSON",
                    help="override one of Cycles' parameters (tools/cycles_render.py), e.g. volume_offset=[0,0,0] "
                         "to see a convention's effect")
    ap.add_argument("--check", action="store_true", help="exit 1 unless single scattering agrees within the noise")
    args = ap.parse_args()

    if not shutil.which(args.blender):
        print(f"cycles_referee: {args.blender} not found: install Debian's package blender", file=sys.stderr)
        sys.exit(77)  # what the test suite reads as skipped
    file = Path(args.scene)
    try:
        scene = json.loads(file.read_text())
    except (OSError, json.JSONDecodeError) as error:
        sys.exit(f"cycles_referee: {file}: {error}")
    for item in args.set:  # the overrides cloudbench applies, applied here too (a dotted path, a JSON value)
        path, _, value = item.partition("=")
        if "[" in path:  # read here as a key, it would leave Cycles' copy of the field unchanged
            sys.exit(f"cycles_referee: --set {path}: the referee applies dotted paths only; give the whole array "
                     f"(e.g. render.cameras=[...]) or edit the scene file")
        node = scene
        keys = path.split(".")
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        try:
            node[keys[-1]] = json.loads(value)
        except json.JSONDecodeError:
            node[keys[-1]] = value
    try:
        params = scene_parameters(scene, file)
    except SceneError as error:
        sys.exit(f"cycles_referee: {error}")
    octave_settings = []
    for setting in args.octaves:
        try:
            n, a, b, c = setting.split(",")
            int(n), float(a), float(b), float(c)
        except ValueError:
            sys.exit(f"cycles_referee: --octaves: needs N,A,B,C (count, attenuation, contribution, eccentricity), "
                     f"got '{setting}'")
        octave_settings.append((n, a, b, c))
    out = Path(args.out or f"out/{file.stem}/referee").resolve()
    out.mkdir(parents=True, exist_ok=True)
    steps = int(scene.get("steps", 1))
    sets = [a for s in args.set for a in ("--set", s)]
    seconds = {}

    def dump(folder, extra):
        seconds[folder] = run([args.cli, "dump", str(file), "--reference", "--vdb", "--backend", "cpu", "--quiet",
                               "--out", str(out / folder)] + sets + extra, f"cloudbench dump ({folder})")
        return out / folder / f"step_{steps - 1:04d}"

    step_dir = dump("dump", [])
    forward_dir = dump("dump-forward", ["--set", "shade.scattering.enabled=true", "--set", "shade.scattering.albedo=1"])
    camera = params["camera"]
    ours = {
        "reference": step_dir / f"frame-reference-{camera}.exr",
        "march": step_dir / f"frame-march-{camera}.exr",
        "march_forward": forward_dir / f"frame-march-{camera}.exr",
    }
    labels = {"reference": "exact reference (single scattering)", "march": "render_march, the scene's settings",
              "march_forward": "render_march, multiple forward scattering"}
    for k, (n, a, b, c) in enumerate(octave_settings if args.bounces > 0 else []):
        octaves = json.dumps({"count": int(n), "attenuation": float(a), "contribution": float(b),
                              "eccentricity": float(c)}, separators=(",", ":"))
        folder = dump(f"dump-octaves-{k}", ["--set", f"lighting.octaves={octaves}"])
        ours[f"reference_octaves_{k}"] = folder / f"frame-reference-{camera}.exr"
        ours[f"march_octaves_{k}"] = folder / f"frame-march-{camera}.exr"
        labels[f"reference_octaves_{k}"] = f"exact light, octaves n={n} a={a} b={b} c={c}"
        labels[f"march_octaves_{k}"] = f"render_march, octaves n={n} a={a} b={b} c={c}"
    blender(args.blender, {"convert": [[str(p), str(out / f"{k}.npy")] for k, p in ours.items() if p.exists()]},
            out / "convert.json")
    images = {k: np.load(out / f"{k}.npy") for k, p in ours.items() if p.exists()}

    base = dict(params, vdb=str(step_dir / "q.vdb"), samples=args.samples, step_rate=args.step_rate,
                max_steps=100000, threads=0)
    for item in args.cycles_param:
        name, _, value = item.partition("=")
        if name not in base:
            sys.exit(f"cycles_referee: --cycles-param: unknown parameter '{name}' (one of {', '.join(sorted(base))})")
        base[name] = json.loads(value)
    renders = {}
    for name, bounces in (("single", 0), ("multiple", args.bounces)):
        if name == "multiple" and bounces == 0:
            continue
        for seed in (1, 2):
            key = f"{name}-{seed}"
            p = dict(base, seed=seed, volume_bounces=bounces, exr=str(out / f"cycles-{key}.exr"),
                     npy=str(out / f"cycles-{key}.npy"))
            seconds[f"cycles {key}"] = blender(args.blender, p, out / f"cycles-{key}.json")
            renders[key] = np.load(p["npy"])

    single = compare_noisy(images["reference"], renders["single-1"], renders["single-2"])
    single_ok = agrees(single)
    result = {"scene": str(file), "labels": labels, "samples": args.samples, "step_rate": args.step_rate, "bounces": args.bounces,
              "width": params["width"], "height": params["height"], "single_scattering": single,
              "single_scattering_agrees": single_ok, "seconds": seconds}
    if "multiple-1" in renders:
        result["multiple_scattering"] = {
            k: compare_noisy(img, renders["multiple-1"], renders["multiple-2"]) for k, img in images.items()}
    (out / "referee.json").write_text(json.dumps(result, indent=1) + "\n")
    lines = [f"# Cycles against cloudbench: {file.name}", "",
             f"{params['width']}x{params['height']}, {args.samples} samples a pixel and seed, Cycles step "
             f"{args.step_rate} voxel; {args.bounces} volume bounces for multiple scattering.", "",
             "| cloudbench image | Cycles | total, Cycles / ours - 1 | its noise | RMS difference | RMS noise | "
             "ratio | PSNR dB |", "|---|---|---:|---:|---:|---:|---:|---:|"]

    def row(label, cycles, c):
        lines.append(f"| {label} | {cycles} | {c['relative_difference']:+.4f} | {c['relative_noise']:.4f} | "
                     f"{c['rms_difference']:.3g} | {c['rms_noise']:.3g} | {c['rms_ratio']:.2f} | {c['psnr_db']:.1f} |")
    row("exact reference (single scattering)", "no bounce", single)
    for k, c in result.get("multiple_scattering", {}).items():
        row(labels[k], f"{args.bounces} bounces", c)
    verdict = "agrees" if single_ok else "DISAGREES"
    lines += ["", f"Single scattering {verdict}: RMS difference {single['rms_ratio']:.2f} times the noise's "
              f"(bound {RMS_RATIO_BOUND}), total {single['relative_difference']:+.4f} (bound "
              f"+-{single['total_bound']:.4f}); the seeds' errors correlate {single['seed_correlation']:.2f}."]
    (out / "referee.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    if args.check and not single_ok:
        sys.exit(1)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Plots a `cloudbench sweep` result: error against time, one series per backend,
one panel per stage (shade, shadow; the renderers render_march, render_splat and
render_layers share one "images" panel, one series per renderer x backend), the
Pareto front marked and its points labelled with their settings (every point when
at most 2 fields vary and a series has at most 24). With metric psnr the y axis is the PSNR in dB (higher is
better) and an infinite PSNR (null) is a triangle labelled "inf" above the rest.

Usage: plot_sweep.py SWEEP_JSON OUT_PNG [NAME]
NAME is how messages name OUT_PNG (cloudbench passes /proc/self/fd/3, the
temporary file it opened, and the file's real name). On any failure the script
prints one line on standard error, "plot_sweep.py: REASON" (a write that fails:
"plot_sweep.py: NAME: cannot write: <strerror>"), never a traceback, and exits 1."""
import json
import sys


class Failure(Exception):
    """A reason to stop, printed as the one line of the failure."""


def plot(doc, source):
    """The figure of the sweep `doc` (read from `source`), with matplotlib's Agg backend."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise Failure("matplotlib cannot be imported: %s" % e)
    metric = doc["metric"]
    rows = [r for r in doc["rows"] if r["status"] == "ok"]
    psnr = metric == "psnr"
    if psnr:
        # PSNR (renderers only, higher is better); null is infinite (the image equals the reference): drawn as
        # a triangle 10 dB above the highest finite value, labelled "inf".
        finite = [r["error"]["psnr_db"] for r in rows if r["error"].get("psnr_db") is not None]
        ceiling = (max(finite) + 10) if finite else 100.0
    for r in rows:
        if psnr:
            value = r["error"].get("psnr_db")
            r["y"], r["inf"] = (ceiling, True) if value is None else (value, False)
        else:
            r["y"], r["inf"] = r["error"]["all"][metric], False
    renderers = ("render_march", "render_splat", "render_layers")
    for r in rows:
        # The renderers' rows go in one panel, a series per renderer x backend.
        r["panel"] = "images" if r["stage"] in renderers else r["stage"]
        r["series"] = (r["stage"].replace("render_", "") + " " + r["backend"]) if r["stage"] in renderers \
            else r["backend"]
    stages = [s for s in ("shade", "shadow", "images") if any(r["panel"] == s for r in rows)]
    if not stages:
        raise Failure("no measured rows in " + source)
    fig, axes = plt.subplots(1, len(stages), figsize=(6.5 * len(stages), 5), squeeze=False)
    varied = [v["path"] for v in doc["vary"]]
    # One colour per backend in every panel.
    colours = {b: f"C{n}" for n, b in enumerate(sorted({r["series"] for r in rows}))}
    for ax, stage in zip(axes[0], stages):
        stage_rows = [r for r in rows if r["panel"] == stage]
        backends = sorted({r["series"] for r in stage_rows})
        for backend in backends:
            mine = [r for r in stage_rows if r["series"] == backend]
            t = [r["time"]["median_ms"] for r in mine]
            e = [r["y"] for r in mine]
            lo = [r["time"]["median_ms"] - r["time"]["q1_ms"] for r in mine]
            hi = [r["time"]["q3_ms"] - r["time"]["median_ms"] for r in mine]
            ax.errorbar(t, e, xerr=[lo, hi], fmt="o", capsize=2, label=backend, alpha=0.8,
                        color=colours[backend])
            for r, x, y in zip(mine, t, e):
                if r["inf"]:
                    ax.plot([x], [y], marker="^", color=colours[backend])
                    ax.annotate("inf", (x, y), textcoords="offset points", xytext=(4, -9), fontsize=7)
            # Every point is labelled with its values of the varied fields when the panel stays legible; past
            # that, the points on the front still are, since they are the ones a reader picks from.
            few = len(varied) <= 2 and len(mine) <= 24
            for r, x, y in zip(mine, t, e):
                if few or r.get("pareto"):
                    label = ",".join(str(r["settings"].get(p, "any")) for p in varied)
                    ax.annotate(label, (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7)
        front = sorted((r["time"]["median_ms"], r["y"]) for r in stage_rows if r.get("pareto"))
        if front:
            ax.plot([p[0] for p in front], [p[1] for p in front], "k--", lw=1, label="Pareto front")
            ax.scatter([p[0] for p in front], [p[1] for p in front], s=120, facecolors="none", edgecolors="k")
        ax.set_xscale("log")
        if not psnr and all(r["y"] > 0 for r in stage_rows):
            ax.set_yscale("log")
        ax.set_xlabel("median time of the stage (ms)")
        if psnr:
            ax.set_ylabel("PSNR (dB) against the exact reference render, higher is better")
        else:
            ax.set_ylabel(f"{metric} |error| against the exact reference render" if stage == "images"
                          else f"{metric} |error| against the Embree reference")
        ax.set_title(f"{doc['scene']}: {stage}\nvarying {', '.join(varied)}", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def main():
    if len(sys.argv) not in (3, 4):
        print("usage: plot_sweep.py SWEEP_JSON OUT_PNG [NAME]", file=sys.stderr)
        return 2
    source, out = sys.argv[1], sys.argv[2]
    shown = sys.argv[3] if len(sys.argv) == 4 else out
    try:
        try:
            with open(source) as f:
                doc = json.load(f)
        except OSError as e:
            raise Failure("%s: cannot read: %s" % (source, e.strerror or e))
        except ValueError as e:
            raise Failure("%s: not JSON: %s" % (source, e))
        try:
            fig = plot(doc, source)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as e:
            raise Failure("%s: not a sweep.json this script reads (%s: %s)" % (source, type(e).__name__, e))
        try:
            fig.savefig(out, format="png", dpi=110)
        except OSError as e:
            raise Failure("%s: cannot write: %s" % (shown, e.strerror or e))
    except Failure as e:
        print("plot_sweep.py: %s" % e, file=sys.stderr)
        return 1
    except Exception as e:  # anything else still ends in one line, not a traceback
        print("plot_sweep.py: %s: %s" % (type(e).__name__, e), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

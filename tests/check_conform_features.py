#!/usr/bin/python3
"""conform's deqp-runner features: the cover count compared,
conform.csv, --baseline and --flake-reruns, on ci-small against one backend.
A mismatch is planted with the test-only CLOUDBENCH_TEST_CONFORM_MISMATCH
switch (harness/conform/Conform.h): <backend>:<row stage>[:<attempts it fails on>].

With --matrix (cases "matrix" and "matrix-baseline"), every case of the built-in
set must appear, worked out by hand from scenes/ci-small.json (tests/ConformMatrixTest.cpp
says how), and a mismatch planted in one case (<...>@<case>) fails that case only.

usage: check_conform_features.py CLI OUTDIR BACKEND CASE"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys

cli, out, backend, case = sys.argv[1:5]
folder = os.path.join(out, case)
shutil.rmtree(folder, ignore_errors=True)
os.makedirs(out, exist_ok=True)


def fail(message, proc=None):
    print("FAIL:", message)
    if proc is not None:
        print("exit", proc.returncode, "\nstdout:\n", proc.stdout, "\nstderr:\n", proc.stderr)
    sys.exit(1)


def conform(extra=(), mismatch="", steps="2", every=False):
    env = dict(os.environ, CLOUDBENCH_TEST_CONFORM_MISMATCH=mismatch,
               CLOUDBENCH_TEST_CONFORM_MISMATCH_EVERY="1" if every else "")
    env.pop("CLOUDBENCH_TEST_FAULT", None)
    return subprocess.run([cli, "conform", "ci-small", "--backend", backend, "--steps", steps, "--out", folder]
                          + list(extra), env=env, capture_output=True, text=True, timeout=600)


# The built-in cases of ci-small (--matrix), by hand from scenes/ci-small.json.
MATRIX_CASES = [
    "scene", "smooth.radius=0", "smooth.radius=2", "shade.attenuation=thesis", "shade.filter=nearest",
    "shade.resolution=2", "shade.resolution=4", "shade.storage=fp16", "shade.storage=unorm8",
    "shade.scattering.enabled=true", "phase.function=none+shade.scattering.enabled=true",
    "phase.function=cornette-shanks+shade.scattering.enabled=true",
    "phase.function=mie+shade.scattering.enabled=true",
    "phase.function=dual-lobe+shade.scattering.enabled=true",
    "shadow.form=thesis", "shadow.form=wang", "render.culling=false", "render.skipping=false",
    "sun.elevation_deg=20+sun.azimuth_deg=10", "sun.elevation_deg=70+sun.azimuth_deg=30", "ca.wind_shift=[[1,-1]]",
] + (["gl-ca-layout=rgba8"] if backend == "gl" else [])
PLANTED = "shade.storage=fp16"


def matrix_rows(proc, quiet=False):
    """(case, stage) -> status from conform.json and conform.csv (case first), which must agree row for row;
    a progress line per case on stdout, none with --quiet."""
    with open(os.path.join(folder, "conform.json")) as f:
        doc = json.load(f)
    from_json = [(r.get("case"), r["stage"], r["backend"], r["status"]) for r in doc["results"]]
    with open(os.path.join(folder, "conform.csv"), newline="") as f:
        rows = list(csv.reader(f))
    if rows[0] != ["case", "stage", "backend", "status", "rule", "worst", "tolerance", "detail"]:
        fail("conform.csv header: %s" % rows[0], proc)
    if [tuple(r[:4]) for r in rows[1:]] != from_json:
        fail("conform.csv differs from conform.json", proc)
    if [c["name"] for c in doc["cases"]] != MATRIX_CASES:
        fail("cases %s, expected %s" % ([c["name"] for c in doc["cases"]], MATRIX_CASES), proc)
    got = {}
    for c, stage, b, status in from_json:
        if b != backend:
            fail("a row of backend %s" % b, proc)
        got[(c, stage)] = status
    for c in MATRIX_CASES:
        if not any(k[0] == c for k in got):
            fail("no row of case " + c, proc)
        line = "case %d/%d: %s\n" % (MATRIX_CASES.index(c) + 1, len(MATRIX_CASES), c)
        if quiet and line in proc.stdout:
            fail("a progress line under --quiet: " + line.strip(), proc)
        if not quiet and line not in proc.stdout:
            fail("no progress line for case " + c, proc)
    return doc, got


def expect_matrix(proc, code, want, quiet=False):
    """Exit `code`; the (case, stage) rows of `want` have their status, every other row passes."""
    if proc.returncode != code:
        fail("expected exit %d" % code, proc)
    doc, got = matrix_rows(proc, quiet)
    for key, status in want.items():
        if got.get(key) != status:
            fail("%s: expected %s, got %s" % (key, status, got.get(key)), proc)
    others = {k: v for k, v in got.items() if k not in want and v != "pass"}
    if others:
        fail("rows other than %s should pass: %s" % (list(want), others), proc)
    return doc


def baseline(text):
    path = os.path.join(out, case + ".baseline")
    with open(path, "w") as f:
        f.write(text)
    return path


def statuses(proc):
    """(stage -> status) from conform.json and from conform.csv, which must agree row for row."""
    with open(os.path.join(folder, "conform.json")) as f:
        doc = json.load(f)
    from_json = [(r["stage"], r["backend"], r["status"], r["detail"]) for r in doc["results"]]
    with open(os.path.join(folder, "conform.csv"), newline="") as f:
        rows = list(csv.reader(f))
    if rows[0] != ["stage", "backend", "status", "rule", "worst", "tolerance", "detail"]:
        fail("conform.csv header: %s" % rows[0], proc)
    from_csv = [(r[0], r[1], r[2], r[6]) for r in rows[1:]]
    if from_csv != from_json:
        fail("conform.csv %s differs from conform.json %s" % (from_csv, from_json), proc)
    for r in rows[1:]:
        float(r[4]), float(r[5])  # worst and tolerance are numbers
    return {stage: status for stage, b, status, _ in from_json if b == backend}


def expect(proc, code, want):
    if proc.returncode != code:
        fail("expected exit %d" % code, proc)
    got = statuses(proc)
    for stage, status in want.items():
        if got.get(stage) != status:
            fail("%s: expected %s, got %s (all: %s)" % (stage, status, got.get(stage), got), proc)
    # Every row not named passes.
    others = {s: v for s, v in got.items() if s not in want and v != "pass"}
    if others:
        fail("rows other than %s should pass: %s" % (list(want), others), proc)


def scene_field(section, field, default):
    """A field of scenes/ci-small.json, read independently of the binary."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "ci-small.json")
    with open(path) as f:
        return json.load(f).get(section, {}).get(field, default)


def report_exit(proc):
    """The exit code of the verdict `cloudbench report` shows for this conform.json: it must follow conform's."""
    html = os.path.join(folder, "report.html")
    r = subprocess.run([cli, "report", os.path.join(folder, "conform.json"), "-o", html], capture_output=True,
                       text=True, timeout=300)
    if r.returncode != 0:
        fail("report exited %d: %s" % (r.returncode, r.stderr), proc)
    with open(html) as f:
        verdict = re.search(r"Verdict: [^<]*\(exit code (\d+)\)", f.read())
    if not verdict:
        fail("no verdict in " + html, proc)
    return int(verdict.group(1))


if case == "csv":
    # No mismatch: every row passes, the cover row among them, and the CSV matches the JSON.
    p = conform()
    expect(p, 0, {"density.cover": "pass"})
    if "conform.csv" not in p.stdout:
        fail("the results line should name conform.csv", p)
    # The coverage summary names every compared row's stage, compared on this backend, with its options.
    with open(os.path.join(folder, "conform.json")) as f:
        doc = json.load(f)
    coverage = doc["coverage"]
    compared = {r["stage"] for r in doc["results"] if r["status"] == "pass"}
    if set(coverage) != compared:
        fail("coverage %s should name the compared stages %s" % (sorted(coverage), sorted(compared)), p)
    for stage, entry in coverage.items():
        if entry["compared_on"] != [backend]:
            fail("coverage of %s: compared_on %s" % (stage, entry["compared_on"]), p)
    # ci-small's own settings (scenes/ci-small.json).
    if coverage["smooth"]["options"]["radius"] != scene_field("smooth", "radius", 1):
        fail("coverage of smooth: radius %s" % coverage["smooth"]["options"], p)
elif case == "cover":
    # The cover count one higher on the backend: only density.cover fails (exit 5), worst 1.
    p = conform(mismatch=backend + ":density.cover")
    expect(p, 5, {"density.cover": "fail"})
    with open(os.path.join(folder, "conform.json")) as f:
        row = [r for r in json.load(f)["results"] if r["stage"] == "density.cover"][0]
    if row["worst"] != 1:
        fail("density.cover worst should be 1, got %s" % row["worst"], p)
elif case == "share":
    # Every region code one off on the backend: within the rule's |dR| <= 1, but 100 % of the elements
    # differ against the 0.5 % allowed, so region fails (exit 5) with worst 1, on the share alone.
    p = conform(mismatch=backend + ":region", every=True)
    expect(p, 5, {"region": "fail"})
    with open(os.path.join(folder, "conform.json")) as f:
        row = [r for r in json.load(f)["results"] if r["stage"] == "region"][0]
    if row["worst"] != 1:
        fail("region worst should be 1 (within the tolerance), got %s" % row["worst"], p)
elif case == "baseline-expected":
    # A listed failure is expected-fail and the exit is 0; comments and a CSV header are allowed.
    path = baseline("# known failures\nstage,backend,status\n\nshade,%s,fail\n" % backend)
    p = conform(["--baseline", path], backend + ":shade")
    expect(p, 0, {"shade": "expected-fail"})
    if report_exit(p) != 0:
        fail("the report's verdict on an expected failure should be exit 0", p)
elif case == "baseline-new":
    # A failure not listed still fails (5); the listed row that passes is unexpected-pass.
    path = baseline("shadow,%s,fail\n" % backend)
    expect(conform(["--baseline", path], backend + ":shade"), 5, {"shade": "fail", "shadow": "unexpected-pass"})
    # An unexpected pass alone also exits 5, in conform and in report.
    p = conform(["--baseline", path])
    expect(p, 5, {"shadow": "unexpected-pass"})
    if report_exit(p) != 5:
        fail("the report's verdict on an unexpected pass should be exit 5", p)
elif case == "baseline-from-csv":
    # A failing run's own conform.csv as the next run's baseline: the same failure is expected.
    first = conform(mismatch=backend + ":smooth")
    expect(first, 5, {"smooth": "fail"})
    path = os.path.join(out, case + ".csv")
    shutil.copy(os.path.join(folder, "conform.csv"), path)
    expect(conform(["--baseline", path], backend + ":smooth"), 0, {"smooth": "expected-fail"})
elif case == "baseline-bad":
    # A bad line: exit 3 with "file: line N: reason", before any work (no output folder).
    path = baseline("shade,%s,fail\n# fine\nsmooth,%s,maybe\n" % (backend, backend))
    p = conform(["--baseline", path])
    if p.returncode != 3 or (path + ": line 3: unknown status 'maybe'") not in p.stderr:
        fail("expected exit 3 and '%s: line 3: unknown status'" % path, p)
    if os.path.exists(folder):
        fail("nothing should be written for a bad baseline", p)
    p = conform(["--baseline", os.path.join(out, "no-such-baseline")])
    if p.returncode != 3 or "no-such-baseline: cannot read" not in p.stderr:
        fail("expected exit 3 for a missing baseline", p)
    p = conform(["--baseline", baseline("shade,%s\n" % backend)])
    if p.returncode != 3 or ": line 1: expected stage,backend,status" not in p.stderr:
        fail("expected exit 3 for a line of two fields", p)
elif case == "flaky":
    # Fails on the first attempt only: with reruns it is flaky (exit 0), without it fails.
    p = conform(["--flake-reruns", "2"], backend + ":shade:1")
    expect(p, 0, {"shade": "flaky"})
    if report_exit(p) != 0:
        fail("the report's verdict on a flaky row should be exit 0", p)
    with open(os.path.join(folder, "conform.json")) as f:
        doc = json.load(f)
    if doc.get("flake_reruns") != 2:
        fail("conform.json should record flake_reruns 2", p)
    if "rerun 1 of 2" not in p.stdout or "rerun 2" in p.stdout:
        fail("expected exactly one rerun", p)
    expect(conform([], backend + ":shade:1"), 5, {"shade": "fail"})
elif case == "flake-persistent":
    # Fails on every attempt: still a failure after the reruns (exit 5).
    p = conform(["--flake-reruns", "2"], backend + ":shade")
    expect(p, 5, {"shade": "fail"})
    if "rerun 2 of 2" not in p.stdout:
        fail("expected two reruns", p)
elif case == "flaky-baseline":
    # Flaky beats the baseline: a listed row that is flaky stays flaky, not unexpected-pass (exit 0).
    path = baseline("shade,%s,fail\n" % backend)
    expect(conform(["--flake-reruns", "1", "--baseline", path], backend + ":shade:1"), 0, {"shade": "flaky"})
elif case == "matrix":
    # The built-in set: every case runs, a mismatch planted in one case fails that case's row only (exit 5).
    p = conform(["--matrix"], backend + ":shade@" + PLANTED, steps="1")
    doc = expect_matrix(p, 5, {(PLANTED, "shade"): "fail"})
    if "1 of %d cases with a failing row" % len(MATRIX_CASES) not in p.stdout:
        fail("the summary should name one failing case", p)
    # The coverage lists every value compared on this backend: every phase in shade and render_splat,
    # every storage, radius, shadow form and attenuation.
    cov = doc["coverage"]
    want = {("shade", "phase"): ["none", "henyey-greenstein", "cornette-shanks", "mie", "dual-lobe"],
            ("render_splat", "phase"): ["none", "henyey-greenstein", "cornette-shanks", "mie", "dual-lobe"],
            ("shade", "storage"): ["fp32", "fp16", "unorm8"], ("shade", "attenuation"): ["beer", "thesis"],
            ("shade", "resolution"): ["1", "2", "4"], ("shade", "filter"): ["bilinear", "nearest"],
            ("smooth", "radius"): ["0", "1", "2"], ("shadow", "form"): ["beer", "thesis", "wang"],
            ("render_splat", "culling"): ["true", "false"], ("render_splat", "skipping"): ["true", "false"],
            ("ca", "wind"): ["false", "true"]}
    if backend == "gl":
        want[("ca", "gl_ca_layout")] = ["packed", "rgba8"]
    for (stage, option), values in want.items():
        got = cov.get(stage, {}).get("options", {}).get(option, {})
        if sorted(got) != sorted(values) or any(b != [backend] for b in got.values()):
            fail("coverage of %s %s: %s, expected %s on %s" % (stage, option, got, values, backend), p)
    # The mismatch's row names its case; the difference images of a case are in its folder.
    if not os.path.isdir(os.path.join(folder, "shade.storage=fp16")):
        fail("no folder for the case " + PLANTED, p)
    # The HTML report's matrix has a row per case and stage: the failing case shows, though later cases pass
    # shade (one row per stage, the last case's status, hid it).
    page = os.path.join(folder, "report.html")
    r = subprocess.run([cli, "report", os.path.join(folder, "conform.json"), "-o", page], capture_output=True,
                       text=True, timeout=120)
    with open(page) as f:
        html = f.read()
    cells = re.findall(r"<tr><td>([^<]*)</td><td>([^<]*)</td><td[^>]*>([^<]*)</td></tr>", html)
    statuses = {(c, s): st for c, s, st in cells}
    if statuses.get((PLANTED, "shade")) != "fail" or statuses.get(("scene", "shade")) != "pass":
        fail("the report's matrix should show %s shade failing and scene shade passing: %s" %
             (PLANTED, {k: v for k, v in statuses.items() if k[1] == "shade"}), r)
elif case == "matrix-baseline":
    # The failing run's conform.csv as the next run's baseline: the same failure in the same case is expected
    # (exit 0); planted in another case it is new (exit 5) and the listed case's row is an unexpected pass.
    first = conform(["--matrix"], backend + ":shade@" + PLANTED, steps="1")
    expect_matrix(first, 5, {(PLANTED, "shade"): "fail"})
    path = os.path.join(out, case + ".csv")
    shutil.copy(os.path.join(folder, "conform.csv"), path)
    expect_matrix(conform(["--matrix", "--baseline", path, "--quiet"], backend + ":shade@" + PLANTED, steps="1"), 0,
                  {(PLANTED, "shade"): "expected-fail"}, quiet=True)
    other = "shade.storage=unorm8"
    expect_matrix(conform(["--matrix", "--baseline", path], backend + ":shade@" + other, steps="1"), 5,
                  {(PLANTED, "shade"): "unexpected-pass", (other, "shade"): "fail"})
elif case == "usage":
    for bad in (["--flake-reruns", "-1"], ["--flake-reruns", "x"], ["--flake-reruns"], ["--baseline", ""],
                ["--vary", "smooth.radius"], ["--vary", "smooth.radius=0,"]):
        p = conform(bad)
        if p.returncode != 2:
            fail("expected exit 2 for %s" % bad, p)
else:
    fail("unknown case " + case)
print("conform features %s: ok" % case)

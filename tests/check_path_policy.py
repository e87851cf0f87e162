#!/usr/bin/python3
"""Every reader and writer of every command against the path policy's cases
(core/base/PathPolicy.h, docs/reliability.md#paths).

usage: check_path_policy.py CLOUDBENCH WORKDIR [TARGET_REGEX]

Each target is one file a command reads or writes: a scene, a results folder's
results.json and the frames it lists, a report's history, a kept interleave's
manifest and runs, a perf history, a suite, a conform baseline, a sweep shard,
a saved state's manifest and arrays, a perf compare verdict (a --json file,
or a kept folder's compare.json); report -o, perf history --json, perf record
--history, a kept interleave's runs.log and compare.json, and run --out's
results.json.
Its file is replaced in turn by

  link-out   a symbolic link to a valid file of the same kind outside the folder
  link-in    a symbolic link to a valid copy inside the same folder
  fifo       a FIFO no one writes
  folder     a folder
  dev-zero   a symbolic link to /dev/zero
  empty      an empty file
  too-large  a sparse file one byte over its kind's limit (readers only)

and the command is run with a timeout (a FIFO must not block it). The verdict
(accepted or refused, the exit code) and the message are checked against the
rule for the target's role:

  named    a path the user gave is taken as named: links followed; a FIFO,
           a device or a folder refused as "not a regular file (...)"
  beneath  a name found inside a folder the user gave: a link inside it is
           followed, one out of it refused as "leads out of FOLDER"
  writer   nothing is written through a link, in or out ("is a symbolic
           link"), nor into a FIFO, a device or a folder

For every refused link out, the outside file's marker must not reach any
output (the report's page in particular). Prints "FAIL: ..." for each
mismatch and a table of the verdicts; exits 1 on any failure.
"""
import base64
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

CLI = None
QUICK = ["--backend", "cpu", "--quiet", "--set", "warmup_steps=0", "--threads", "2"]
MIB = 1 << 20
LIMITS = {"scene": 16 * MIB, "document": 256 * MIB, "history": 1 << 30, "array": 4 << 30, "baseline": 16 * MIB}
CASES = ["link-out", "link-in", "fifo", "folder", "dev-zero", "empty", "too-large"]
failures = []


def fail(message):
    print("FAIL: " + message)
    failures.append(message)


def cloudbench(*args, timeout=120):
    try:
        proc = subprocess.run([CLI, *map(str, args)], stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              errors="replace", timeout=timeout)
        return proc.returncode, proc.stderr + proc.stdout
    except subprocess.TimeoutExpired:
        return "timeout", ""


def must(*args, codes=(0,)):
    code, out = cloudbench(*args, timeout=600)
    if code not in codes:
        raise RuntimeError("fixture: cloudbench %s exited %s: %s" % (" ".join(map(str, args)), code, out[-2000:]))


class Fixtures:
    """Valid inputs, made once by the CLI under test."""

    def __init__(self, folder):
        self.folder = Path(folder)
        shutil.rmtree(self.folder, ignore_errors=True)
        self.folder.mkdir(parents=True)
        f = self.folder
        self.suite = f / "suite.json"
        self.suite.write_text(json.dumps({"scenes": [{"scene": "ci-small", "set": ["steps=2", "warmup_steps=0"]}]}))
        must("run", "ci-small", "--steps", "2", *QUICK, "--out", f / "run")
        must("run", "ci-small", "--steps", "2", *QUICK, "--out", f / "state-run", "--save-state", f / "state")
        for _ in range(2):
            must("perf", "record", "--suite", self.suite, "--history", f / "history.jsonl", "--backend", "cpu",
                 "--quiet")
        for index in (1, 2):
            must("sweep", "ci-small", "--steps", "2", "--vary", "shade.resolution=1,2", "--repeat", "1", "--shard",
                 "%d/2" % index, *QUICK, "--out", f / ("shard%d" % index))
        (f / "baseline.csv").write_text("stage,backend,status\nshade,vk,fail\n")
        # A kept interleave, laid out by hand as --keep lays it out, from the run above.
        kept = f / "kept"
        runs = []
        for side in ("base", "head"):
            (kept / side / "r01-ci-small").mkdir(parents=True)
            shutil.copy(f / "run" / "results.json", kept / side / "r01-ci-small" / "results.json")
            runs.append({"side": side, "scene": "ci-small", "round": 0, "folder": side + "/r01-ci-small",
                         "load": [0.5, 0.5, 0.5], "exit": 0, "seconds": 1.0})
        (kept / "interleave.json").write_text(json.dumps(
            {"format": "cloudbench-interleave/1", "base": CLI, "head": CLI, "scenes": ["ci-small"], "rounds": 1,
             "order": "ABBA", "run_options": [], "runs": runs}))
        # Its verdict, as --keep writes it when the comparison ends (report DIR reads it).
        must("perf", "compare", kept, "--json", kept / "compare.json")


def copy_tree(source, target):
    shutil.rmtree(target, ignore_errors=True)
    shutil.copytree(source, target, symlinks=True)


MARKER = b"cloudbench-outside-marker-7f3a"


def carries_marker(path):
    """Whether the file holds the marker, as it is or inside a base64 data: URI (an embedded image)."""
    data = path.read_bytes()
    if MARKER in data:
        return True
    for encoded in re.findall(rb"base64,([A-Za-z0-9+/=]+)", data):
        try:
            if MARKER in base64.b64decode(encoded):
                return True
        except ValueError:
            pass
    return False


def plant(case, path, kind_limit, valid_bytes, outside):
    """Replaces `path` by the case; `valid_bytes` is a valid file of the same kind."""
    path = Path(path)
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path)
    if case == "link-out":
        outside.write_bytes(valid_bytes if valid_bytes is not None else MARKER)
        path.symlink_to(outside)
    elif case == "link-in":
        real = path.with_name("real-" + path.name)
        real.write_bytes(valid_bytes if valid_bytes is not None else b"")
        path.symlink_to(real.name)
    elif case == "fifo":
        os.mkfifo(path)
    elif case == "folder":
        path.mkdir()
    elif case == "dev-zero":
        path.symlink_to("/dev/zero")
    elif case == "empty":
        path.write_bytes(b"")
    elif case == "too-large":
        with open(path, "wb") as f:
            f.truncate(kind_limit + 1)


# What each role expects of each case: None = accepted; else a regex the message must match. A target may
# override a case (for example a folder where a folder is a valid input).
NOT_FILE = r"not a regular file \(%s\)"
EXPECT = {
    "named": {"link-out": None, "link-in": None, "fifo": NOT_FILE % "a FIFO", "folder": NOT_FILE % "a folder",
              "dev-zero": NOT_FILE % "a device", "empty": "EMPTY", "too-large": r"bytes, more than the"},
    "beneath": {"link-out": r"leads out of", "link-in": None, "fifo": NOT_FILE % "a FIFO",
                "folder": NOT_FILE % "a folder", "dev-zero": r"leads out of", "empty": "EMPTY",
                "too-large": r"bytes, more than the"},
    "writer": {"link-out": r"is a symbolic link; cloudbench does not write through links",
               "link-in": r"is a symbolic link; cloudbench does not write through links",
               "fifo": r"not a regular file \(a FIFO\); cloudbench (writes|replaces) only regular files",
               "folder": r"not a regular file \(a folder\)|Is a directory",
               "dev-zero": r"is a symbolic link; cloudbench does not write through links",
               "empty": None, "too-large": "SKIP"},
}


class Target:
    def __init__(self, name, role, kind, prepare, refused_codes=(3,), accepted_codes=(0,), empty=None,
                 overrides=None, page=None):
        self.name, self.role, self.kind, self.prepare = name, role, kind, prepare
        self.refused_codes, self.accepted_codes = refused_codes, accepted_codes
        self.empty = empty  # the message an empty file gets (a format error)
        self.overrides = overrides or {}
        self.page = page  # an output the refusal is written into instead of stderr (the report's page)


def targets(fx, work):
    """Each target's prepare(case_dir) returns (argv, path_to_replace, valid_bytes)."""
    f = fx.folder
    results_bytes = (f / "run" / "results.json").read_bytes()

    def scene(d):
        path = d / "scene.json"
        return ["run", path, "--steps", "1", *QUICK, "--out", d / "out"], path, SCENE_BYTES

    def report_results(d):
        copy_tree(f / "run", d / "run")
        return ["report", d / "run", "-o", d / "page.html"], d / "run" / "results.json", results_bytes

    def report_frame(d):
        copy_tree(f / "run", d / "run")
        frame = sorted(p.name for p in (d / "run").glob("frame-*-cpu.png"))[0]
        return ["report", d / "run", "-o", d / "page.html"], d / "run" / frame, (f / "run" / frame).read_bytes()

    def report_history(d):
        return (["report", f / "run" / "results.json", "--history", d / "h.jsonl", "-o", d / "page.html"],
                d / "h.jsonl", (f / "history.jsonl").read_bytes())

    def kept_manifest(d):
        copy_tree(f / "kept", d / "kept")
        return ["perf", "compare", d / "kept"], d / "kept" / "interleave.json", (f / "kept" / "interleave.json"
                                                                                  ).read_bytes()

    def kept_run(d):
        copy_tree(f / "kept", d / "kept")
        return ["perf", "compare", d / "kept"], d / "kept" / "base" / "r01-ci-small" / "results.json", results_bytes

    def kept_verdict(d):
        copy_tree(f / "kept", d / "kept")
        return (["report", d / "kept", "-o", d / "page.html"], d / "kept" / "compare.json",
                (f / "kept" / "compare.json").read_bytes())

    def compare_file(d):
        return (["report", d / "compare.json", "-o", d / "page.html"], d / "compare.json",
                (f / "kept" / "compare.json").read_bytes())

    def history(d):
        return ["perf", "history", d / "h.jsonl"], d / "h.jsonl", (f / "history.jsonl").read_bytes()

    def suite(d):
        return (["perf", "record", "--suite", d / "suite.json", "--history", d / "out.jsonl", "--backend", "cpu",
                 "--quiet"], d / "suite.json", fx.suite.read_bytes())

    def baseline(d):
        return (["conform", "ci-small", "--steps", "1", *QUICK, "--baseline", d / "baseline.csv", "--out", d / "c"],
                d / "baseline.csv", (f / "baseline.csv").read_bytes())

    def shard(d):
        return (["merge", d / "sweep.json", f / "shard2" / "sweep.json", "--out", d / "merged"], d / "sweep.json",
                (f / "shard1" / "sweep.json").read_bytes())

    def state_manifest(d):
        copy_tree(f / "state", d / "state")
        return (["run", "ci-small", "--steps", "3", *QUICK, "--resume", d / "state", "--out", d / "out"],
                d / "state" / "manifest.json", (f / "state" / "manifest.json").read_bytes())

    def state_array(d):
        copy_tree(f / "state", d / "state")
        array = sorted(p.name for p in (f / "state").glob("*.npy"))[0]
        return (["run", "ci-small", "--steps", "3", *QUICK, "--resume", d / "state", "--out", d / "out"],
                d / "state" / array, (f / "state" / array).read_bytes())

    def report_out(d):
        return ["report", f / "run", "-o", d / "page.html"], d / "page.html", b"old page"

    def history_json(d):
        return ["perf", "history", f / "history.jsonl", "--json", d / "h.json"], d / "h.json", b"{}"

    def record_history(d):
        return (["perf", "record", "--suite", fx.suite, "--history", d / "h.jsonl", "--backend", "cpu", "--quiet"],
                d / "h.jsonl", (f / "history.jsonl").read_bytes())

    def kept_log(d):
        (d / "kept").mkdir()
        return (["perf", "compare", "--interleave", CLI, CLI, "ci-small", "--rounds", "1", "--steps", "2",
                 "--set", "warmup_steps=0", "--backend", "cpu", "--quiet", "--keep", d / "kept"], d / "kept" / "runs.log", b"")

    def kept_verdict_out(d):
        (d / "kept").mkdir()
        return (["perf", "compare", "--interleave", CLI, CLI, "ci-small", "--rounds", "1", "--steps", "2",
                 "--set", "warmup_steps=0", "--backend", "cpu", "--quiet", "--keep", d / "kept"],
                d / "kept" / "compare.json", b"{}")

    def run_out(d):
        (d / "out").mkdir()
        return ["run", "ci-small", "--steps", "1", *QUICK, "--out", d / "out"], d / "out" / "results.json", b"{}"

    empty_json = r"not JSON|empty|not a |no record|missing"
    return [
        Target("run SCENE", "named", "scene", scene, empty=empty_json),
        Target("report DIR: results.json", "beneath", "document", report_results, empty=empty_json),
        Target("report DIR: a listed frame", "beneath", "array", report_frame, empty=r"not a PNG file",
               page=True),
        Target("report --history FILE", "named", "history", report_history, empty=None),
        Target("perf compare DIR: interleave.json", "beneath", "document", kept_manifest, empty=empty_json),
        Target("perf compare DIR: a run's results.json", "beneath", "document", kept_run, empty=empty_json),
        Target("report DIR: a kept interleave's compare.json", "beneath", "document", kept_verdict,
               empty=empty_json),
        # report takes a folder as well as a file: an empty folder in the file's place holds none it reads.
        Target("report FILE: a perf compare --json file", "named", "document", compare_file, empty=empty_json,
               overrides={"folder": r"no results.json, conform.json, accuracy.json, sweep.json or compare.json"}),
        # An empty history is a history of no record yet: "0 change points ... over 0 records".
        Target("perf history FILE", "named", "history", history, overrides={"empty": None}),
        Target("perf record --suite FILE", "named", "document", suite, empty=empty_json),
        Target("conform --baseline FILE", "named", "baseline", baseline, accepted_codes=(0, 4, 5),
               empty=None),
        Target("merge SHARD", "named", "history", shard, empty=empty_json),
        Target("run --resume DIR: state.json", "beneath", "document", state_manifest, empty=empty_json),
        Target("run --resume DIR: an array", "beneath", "array", state_array, empty=r"npy"),
        Target("report -o FILE", "writer", None, report_out, refused_codes=(1,)),
        Target("perf history --json FILE", "writer", None, history_json, refused_codes=(1,)),
        Target("perf record --history FILE", "writer", None, record_history, refused_codes=(1,)),
        Target("perf compare --keep DIR: runs.log", "writer", None, kept_log, refused_codes=(1,)),
        Target("perf compare --keep DIR: compare.json", "writer", None, kept_verdict_out, refused_codes=(1,)),
        Target("run --out DIR: results.json", "writer", None, run_out, refused_codes=(1,)),
    ]


SCENE_BYTES = None


def main():
    global CLI, SCENE_BYTES
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    CLI = os.path.abspath(sys.argv[1])
    work = Path(sys.argv[2]).absolute()
    only = re.compile(sys.argv[3]) if len(sys.argv) == 4 else None
    source = Path(__file__).resolve().parent.parent
    SCENE_BYTES = (source / "scenes" / "ci-small.json").read_bytes()
    fx = Fixtures(work / "fixtures")
    rows = []
    for target in targets(fx, work):
        if only and not only.search(target.name):
            continue
        verdicts = []
        for case in CASES:
            expected = target.overrides.get(case, EXPECT[target.role][case])
            if expected == "SKIP":
                verdicts.append("-")
                continue
            if expected == "EMPTY":
                expected = target.empty
            d = work / "cases" / re.sub(r"[^A-Za-z0-9]+", "-", target.name) / case
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir(parents=True)
            outside_dir = work / "outside" / d.relative_to(work / "cases")
            shutil.rmtree(outside_dir, ignore_errors=True)
            outside_dir.mkdir(parents=True)
            outside = outside_dir / "outside-file"
            argv, path, valid = target.prepare(d)
            limit = LIMITS.get(target.kind, 0)
            if case == "link-out" and target.page:
                valid = valid + MARKER  # a PNG with trailing bytes still decodes; the marker shows a leak
            plant(case, path, limit, valid, outside)
            before = outside.read_bytes() if outside.exists() else None
            code, out = cloudbench(*argv, timeout=120)
            label = "%s, %s" % (target.name, case)
            shown = out.strip().splitlines()[-1] if out.strip() else ""
            if code == "timeout":
                fail("%s: no answer in 120 s (blocked?)" % label)
                verdicts.append("HUNG")
                continue
            page_text = ""
            if target.page and (d / "page.html").exists():
                page_text = (d / "page.html").read_text(errors="replace")
            if expected is None:
                if code not in target.accepted_codes:
                    fail("%s: expected to be accepted, exited %s: %s" % (label, code, out[-600:]))
                verdicts.append("ok (%s)" % code)
            elif target.page:
                # The report shows a frame it cannot read in the page, and still writes it.
                if code != 0 or not re.search(expected, page_text):
                    fail("%s: expected the page to say /%s/, exit %s" % (label, expected, code))
                verdicts.append("refused in page")
            else:
                if code not in target.refused_codes:
                    fail("%s: expected exit %s, got %s: %s" % (label, target.refused_codes, code, out[-600:]))
                if not re.search(expected, out):
                    fail("%s: expected a message matching /%s/, got: %s" % (label, expected, out[-600:]))
                if str(path) not in out and path.name not in out:
                    fail("%s: the message does not name %s: %s" % (label, path, out[-600:]))
                verdicts.append("refused (%s)" % code)
            if case == "link-out" and expected is not None:
                # Nothing of the outside file may reach an output: the page, a JSON, a log.
                leaked = [str(p) for p in d.rglob("*") if p.is_file() and not p.is_symlink() and carries_marker(p)]
                if leaked:
                    fail("%s: the outside file's marker reached %s" % (label, ", ".join(leaked)))
                if before is not None and outside.read_bytes() != before:
                    fail("%s: the outside file was changed" % label)
        rows.append((target.name, target.role, verdicts))
    print("| target | role | " + " | ".join(CASES) + " |")
    print("|---|---|" + "---|" * len(CASES))
    for name, role, verdicts in rows:
        print("| %s | %s | %s |" % (name, role, " | ".join(verdicts)))
    if failures:
        print("%d failures" % len(failures))
        sys.exit(1)
    print("every reader and writer follows the path policy (%d targets, %d cases)" % (len(rows), len(CASES)))


if __name__ == "__main__":
    main()

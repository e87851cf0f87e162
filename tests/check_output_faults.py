#!/usr/bin/python3
"""Plants a failed write, rename or remove of each output of `cloudbench run`
in turn (CLOUDBENCH_TEST_FAIL_FS, docs/cli.md: results.json, the frame as
.exr and .png, the top view) and checks the folder's bookkeeping after it
(docs/results.md#output-folders):

- the command exits 1 and its message names the file;
- a file that was not placed is not in the folder, is not in results.json's
  "files", and the journal does not count it as placed;
- results.json, when there, names exactly the files the journal counts as
  placed (besides itself), each whole;
- a failed removal of the previous run's file stops the claim: the file and
  the journal stay, and results.json is there only if it names whole files;
- no temporary file is left, the lock is free afterwards, and a clean run then
  takes the folder over.

usage: check_output_faults.py CLOUDBENCH DIR
"""
import fcntl
import json
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import output_checks  # noqa: E402

FRAME = "frame-splat-above-cpu.png"
# What a whole run of ci-small on cpu places, worked from docs/results.md: results.json, each camera's frame
# as .exr and .png (one camera, "above"), and the backend's top view.
ALL = {"results.json", "frame-splat-above-cpu.exr", FRAME, "topview-cpu.png"}
# A frame is written as .exr, then .png: when the .exr fails, the frame's .png is not written either.
NOT_AFTER = {"frame-splat-above-cpu.exr": {FRAME}}


def run(cli, folder, plant=None):
    env = dict(os.environ)
    env.pop("CLOUDBENCH_TEST_FAIL_FS", None)
    if plant:
        env["CLOUDBENCH_TEST_FAIL_FS"] = plant
    args = [cli, "run", "ci-small", "--backend", "cpu", "--steps", "12", "--threads", "2", "--quiet", "--out", folder]
    return subprocess.run(args, env=env, capture_output=True, text=True, timeout=120)


def journal_placed(folder):
    """The names the journal counts as in place: a placement ('=') not undone by a failed rename ('-')."""
    count = {}
    for line in open(os.path.join(folder, ".cloudbench-run.files")).read().splitlines():
        if line[:2] in ("= ", "- "):
            count[line[2:]] = count.get(line[2:], 0) + (1 if line[0] == "=" else -1)
    return {name for name, n in count.items() if n > 0}


def listed(folder):
    path = os.path.join(folder, "results.json")
    return set(json.load(open(path))["files"]) if os.path.exists(path) else None


def lock_problems(folder):
    fd = os.open(os.path.join(folder, ".cloudbench.lock"), os.O_RDWR)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        fcntl.flock(fd, fcntl.LOCK_UN)
        return []
    except BlockingIOError:
        return ["the lock is still held"]
    finally:
        os.close(fd)


def check(cli, folder, op, name):
    plant = "%s:%s" % (op, name)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    if op == "remove":
        first = run(cli, folder)
        if first.returncode != 0:
            return ["the clean run before exited %d: %s" % (first.returncode, first.stderr)]
        journal_before = open(os.path.join(folder, ".cloudbench-run.files")).read()
    r = run(cli, folder, plant)
    problems = []
    if r.returncode != 1:
        problems.append("exit %d, expected 1" % r.returncode)
    shown = os.path.join(folder, name)
    want = shown + (": cannot remove the previous run's file: " if op == "remove" else
                    ": cannot move the finished file into place: " if op == "rename" else ": cannot write: ")
    if want + "Input/output error" not in r.stderr:
        problems.append("stderr does not say %r: %r" % (want, r.stderr))
    files = set(output_checks.visible_files(folder))
    placed = journal_placed(folder)
    inside = listed(folder)
    problems += output_checks.results_problems(folder)
    if op == "remove":
        # The claim stopped at the failed removal: the file is still there and the journal still lists it, so
        # the next claim removes it; results.json, removed first, is gone unless it is the file that stayed.
        if name not in files:
            problems.append("%s is gone although its removal failed" % name)
        if open(os.path.join(folder, ".cloudbench-run.files")).read() != journal_before:
            problems.append("the journal changed although the claim failed")
        if (inside is not None) != (name == "results.json"):
            problems.append("results.json is %s" % ("there" if inside is not None else "gone"))
    else:
        if name in files:
            problems.append("%s is in the folder although its %s failed" % (name, op))
        if name in placed:
            problems.append("the journal counts %s as placed" % name)
        if inside is not None and name in inside:
            problems.append("results.json lists %s, which was not placed" % name)
        if name == "results.json" and inside is not None:
            problems.append("results.json is there although its %s failed" % op)
        others = ALL - {name} - NOT_AFTER.get(name, set())
        if name != "results.json":
            if inside is None:
                problems.append("no results.json")
            elif inside != others - {"results.json"}:
                expected = sorted(others - {"results.json"})
                problems.append("results.json lists %s, expected %s" % (sorted(inside), expected))
        if placed != others:
            problems.append("the journal places %s, expected %s" % (sorted(placed), sorted(others)))
    if output_checks.temporary_files(folder):
        problems.append("temporary files left: %s" % output_checks.temporary_files(folder))
    problems += lock_problems(folder)
    after = run(cli, folder)
    if after.returncode != 0:
        problems.append("the clean run after exited %d: %s" % (after.returncode, after.stderr))
    problems += ["after a clean run: " + p for p in output_checks.complete_run_problems(folder)]
    return problems


def main():
    cli, folder = sys.argv[1], sys.argv[2]
    failed = False
    for op in ("write", "rename", "remove"):
        for name in sorted(ALL):
            problems = check(cli, os.path.join(folder, "%s-%s" % (op, name)), op, name)
            print("%s %s: %s" % (op, name, "; ".join(problems) if problems else "ok"), flush=True)
            failed |= bool(problems)
    if failed:
        sys.exit(1)
    print("every planted failure left the bookkeeping true")


if __name__ == "__main__":
    main()

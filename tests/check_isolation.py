#!/usr/bin/python3
"""Crash isolation: a backend killed on purpose through
CLOUDBENCH_TEST_FAULT is reported with its signal or reason and its stage, the
exit code is 1, and every other backend's results are kept in the JSON output.

usage: check_isolation.py CLI OUTDIR CASE
CASE: run, conform, accuracy, sweep (gl segfaults or aborts in shade),
      hang (a hang killed by --backend-timeout), oom (an allocation failure),
      noisolation-oom (the same without isolation: still a message, not exit 134),
      parentkill (SIGKILL of the parent leaves no child running)."""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

cli, out, case = sys.argv[1], sys.argv[2], sys.argv[3]
folder = os.path.join(out, case)
shutil.rmtree(folder, ignore_errors=True)


def fail(message, proc=None):
    print("FAIL:", message)
    if proc is not None:
        print("exit", proc.returncode, "\nstdout:\n", proc.stdout, "\nstderr:\n", proc.stderr)
    sys.exit(1)


def run(args, fault, timeout=600):
    env = dict(os.environ, CLOUDBENCH_TEST_FAULT=fault)
    return subprocess.run([cli] + args + ["--out", folder], env=env, capture_output=True, text=True,
                          timeout=timeout)


def expect_reported(proc, backend, status, signal_name, stage):
    if proc.returncode != 1:
        fail("expected exit 1", proc)
    pattern = rf"backend {backend} {re.escape(status)}"
    if signal_name:
        pattern += rf" \({signal_name}\)"
    pattern += rf" in stage {stage}"
    if not re.search(pattern, proc.stderr):
        fail(f"stderr does not match '{pattern}'", proc)


def load(name):
    with open(os.path.join(folder, name)) as f:
        return json.load(f)


steps = 3
common = ["ci-small", "--backend", "cpu,gl,vk", "--steps", str(steps), "--quiet"]
warm0 = ["--set", "warmup_steps=0"]  # run keeps warm-up steps, which must be fewer than the steps

if case == "run":
    proc = run(["run"] + common + warm0, "gl:shade:segv")
    expect_reported(proc, "gl", "crashed", "SIGSEGV", "shade")
    doc = load("results.json")
    b = doc["backends"]
    if not doc["complete"] or doc["pending"]:
        fail("results.json is not complete", proc)
    if b["cpu"]["status"] != "ok" or b["cpu"]["steps_completed"] != steps:
        fail(f"cpu's results are not complete: {b['cpu']}", proc)
    f = b["gl"].get("failure", {})
    if b["gl"]["status"] != "crashed" or f.get("signal") != "SIGSEGV" or f.get("stage") != "shade":
        fail(f"gl's entry does not hold the crash: {b['gl']}", proc)
    if b["vk"]["status"] not in ("ok", "unavailable"):
        fail(f"vk was not run or reported: {b['vk']}", proc)
    if b["vk"]["status"] == "ok" and b["vk"]["steps_completed"] != steps:
        fail("vk's results are not complete", proc)
    # The backend after the crashed one still wrote its frames.
    if not os.path.exists(os.path.join(folder, "topview-cpu.png")):
        fail("cpu's top view is missing", proc)
elif case == "conform":
    # gl aborts in shade at step 2 (the last): the comparisons of steps 0-1 are kept.
    proc = run(["conform"] + common, "gl:shade:abort:2")
    expect_reported(proc, "gl", "crashed", "SIGABRT", "shade")
    rows = load("conform.json")["results"]
    gl = [r for r in rows if r["backend"] == "gl"]
    crashed = [r for r in gl if r["status"] == "crashed"]
    if len(crashed) != 1 or "SIGABRT" not in crashed[0]["detail"] or "steps 0-1" not in crashed[0]["detail"]:
        fail(f"gl's rows do not hold the crash after steps 0-1: {gl}", proc)
    kept = {r["stage"] for r in gl if r["status"] == "pass"}
    if not {"region", "ca", "smooth", "density", "shade"} <= kept:
        fail(f"gl's comparisons of the finished steps are not kept: {gl}", proc)
    vk = [r for r in rows if r["backend"] == "vk"]
    if not vk or any(r["status"] not in ("pass", "skipped") for r in vk):
        fail(f"vk's rows are missing or wrong: {vk}", proc)
elif case in ("accuracy", "sweep"):
    args = [case, "ci-small", "--backend", "cpu,gl,vk", "--steps", "6", "--repeat", "1", "--quiet"]
    if case == "sweep":
        args += ["--vary", "shade.resolution=1,2"]
    proc = run(args, "gl:shade:segv")
    # accuracy and sweep call the stages directly, not through CallStage: the
    # fault fires where they measure shade.
    expect_reported(proc, "gl", "crashed", "SIGSEGV", "shade")
    rows = load(case + ".json")["rows"]
    cpu = [r for r in rows if r["backend"] == "cpu"]
    gl = [r for r in rows if r["backend"] == "gl"]
    if not cpu or any(r["status"] != "ok" for r in cpu):
        fail(f"cpu's rows are missing or not ok: {cpu}", proc)
    if not gl or any(r["status"] != "crashed" for r in gl):
        fail(f"gl's rows do not hold the crash: {gl}", proc)
    if not any(r["backend"] == "vk" for r in rows):
        fail("vk's rows are missing", proc)
elif case == "hang":
    start = time.monotonic()
    proc = run(["run", "ci-small", "--backend", "gl,cpu", "--steps", "2", "--quiet", "--backend-timeout", "10"] + warm0,
               "gl:density:hang")
    expect_reported(proc, "gl", "timed out", "", "density")
    b = load("results.json")["backends"]
    if b["gl"]["status"] != "timed out" or b["cpu"]["status"] != "ok":
        fail(f"results.json: {b}", proc)
    print(f"hang killed after {time.monotonic() - start:.1f} s")
elif case in ("oom", "noisolation-oom"):
    extra = ["--no-isolation"] if case == "noisolation-oom" else []
    proc = run(["run", "ci-small", "--backend", "cpu", "--steps", "2", "--quiet"] + warm0 + extra, "cpu:smooth:oom")
    if proc.returncode != 1:
        fail("expected exit 1 (not 134, an abort)", proc)
    if case == "oom":
        expect_reported(proc, "cpu", "out of memory", "", "smooth")
        if load("results.json")["backends"]["cpu"]["status"] != "out of memory":
            fail("results.json does not say out of memory", proc)
    else:
        # Without isolation the backend's allocation failure is still caught and reported...
        expect_reported(proc, "cpu", "out of memory", "", "smooth")
        # ...and in a command that is not isolated (dump), main() reports it.
        proc = run(["dump", "ci-small", "--backend", "cpu", "--steps", "2", "--quiet"], "cpu:smooth:oom")
        if proc.returncode != 1 or not re.search(r"cloudbench: out of memory in smooth at step 0", proc.stderr):
            fail("dump: expected exit 1 and an out-of-memory message naming the stage", proc)
elif case == "parentkill":
    env = dict(os.environ, CLOUDBENCH_TEST_FAULT="cpu:region:hang")
    parent = subprocess.Popen([cli, "run", "ci-small", "--backend", "cpu", "--steps", "2", "--quiet", "--out", folder] + warm0,
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    # Wait until the child is in the hang (it says so on stderr), then find it.
    line = parent.stderr.readline()
    if "CLOUDBENCH_TEST_FAULT: hang" not in line:
        parent.kill()
        fail(f"the child did not reach the hang: {line!r}")
    children = subprocess.run(["pgrep", "-P", str(parent.pid)], capture_output=True, text=True).stdout.split()
    if len(children) != 1:
        parent.kill()
        fail(f"expected one child of {parent.pid}, found {children}")
    child = int(children[0])
    parent.send_signal(signal.SIGKILL)
    parent.wait()
    for _ in range(200):  # up to 10 s for the kernel to deliver PR_SET_PDEATHSIG
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        # A zombie (reparented, killed, not yet reaped) counts as gone.
        try:
            with open(f"/proc/{child}/stat") as f:
                if f.read().split(")")[-1].split()[0] == "Z":
                    break
        except FileNotFoundError:
            break
        time.sleep(0.05)
    else:
        os.kill(child, signal.SIGKILL)
        fail(f"child {child} still runs after its parent was killed")
else:
    fail(f"unknown case {case}")
print(f"isolation {case}: ok")

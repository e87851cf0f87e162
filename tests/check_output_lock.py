#!/usr/bin/python3
"""Two commands never write into one folder at once (docs/results.md#output-folders).

usage: check_output_lock.py CLOUDBENCH DIR held COMMAND ARGS...
  The test holds DIR/.cloudbench.lock (as a cloudbench command with pid 4242
  running "sweep" would) and runs `CLOUDBENCH COMMAND ARGS... --out DIR`: it
  must exit 1 at once with exactly
  "DIR: in use by another cloudbench command (pid 4242, sweep)" and write nothing.

usage: check_output_lock.py CLOUDBENCH DIR concurrent
  Two real `run`s into DIR: the first is stopped (SIGSTOP) once it holds the
  lock, the second must then exit 1 naming the first's pid; the first, resumed,
  completes, and DIR holds exactly its run. A third run after it succeeds.
"""
import fcntl
import json
import os
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import output_checks  # noqa: E402


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def held(cli, folder, command):
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    with open(os.path.join(folder, ".cloudbench.lock"), "w") as lock:
        lock.write("4242 sweep\n")
        lock.flush()
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        result = subprocess.run([cli] + command + ["--quiet", "--out", folder], capture_output=True, text=True,
                                timeout=60)
    expected = "%s: in use by another cloudbench command (pid 4242, sweep)\n" % folder
    if result.returncode != 1 or result.stderr != expected:
        fail("exit %d, stderr %r; expected exit 1 and %r" % (result.returncode, result.stderr, expected))
    written = sorted(set(os.listdir(folder)) - {".cloudbench.lock"})
    if written:
        fail("the refused command wrote %s" % written)
    print("refused while the lock is held: %s" % result.stderr.strip())


def run_command(cli, folder, steps):
    return [cli, "run", "ci-small", "--backend", "cpu", "--steps", str(steps), "--threads", "2", "--quiet",
            "--out", folder]


def concurrent(cli, folder):
    shutil.rmtree(folder, ignore_errors=True)
    first = subprocess.Popen(run_command(cli, folder, 1000), stdout=subprocess.DEVNULL)
    lock_path = os.path.join(folder, ".cloudbench.lock")
    deadline = time.monotonic() + 60
    holder = "%d run\n" % first.pid
    while first.poll() is None and time.monotonic() < deadline:
        if os.path.exists(lock_path) and open(lock_path).read() == holder:
            break
        time.sleep(0.001)
    first.send_signal(signal.SIGSTOP)
    try:
        if first.poll() is not None:
            fail("the first run ended (exit %d) before the second could start: inconclusive" % first.returncode)
        if open(lock_path).read() != holder:
            fail("the first run did not record itself in %s within 60 s" % lock_path)
        second = subprocess.run(run_command(cli, folder, 12), capture_output=True, text=True, timeout=60)
    finally:
        first.send_signal(signal.SIGCONT)
    expected = "%s: in use by another cloudbench command (pid %d, run)\n" % (folder, first.pid)
    if second.returncode != 1 or second.stderr != expected:
        fail("second run: exit %d, stderr %r; expected exit 1 and %r" % (second.returncode, second.stderr, expected))
    print("second run refused: %s" % second.stderr.strip())
    if first.wait(timeout=120) != 0:
        fail("the first run exited %d" % first.returncode)
    problems = output_checks.complete_run_problems(folder)
    if problems:
        fail("after the first run: " + "; ".join(problems))
    if json.load(open(os.path.join(folder, "results.json")))["scene"]["steps"] != 1000:
        fail("results.json is not the first run's (1000 steps)")
    third = subprocess.run(run_command(cli, folder, 12), capture_output=True, text=True, timeout=60)
    if third.returncode != 0:
        fail("a run after the first ended: exit %d: %s" % (third.returncode, third.stderr))
    problems = output_checks.complete_run_problems(folder)
    if problems:
        fail("after the third run: " + "; ".join(problems))
    print("one run proceeded, the other was refused; the folder holds one complete run")


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    cli, folder, mode = sys.argv[1], sys.argv[2], sys.argv[3]
    if mode == "held":
        held(cli, folder, sys.argv[4:])
    elif mode == "concurrent":
        concurrent(cli, folder)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()

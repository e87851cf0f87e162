#!/usr/bin/python3
"""Output folders on a full and on a read-only file system, each a
small tmpfs mounted in a private mount namespace (`unshare -rm`, or `unshare -m`
as root); exits 77 (skipped) where neither may mount.

usage: check_output_mounts.py CLOUDBENCH DIR full|readonly|writers-full|writers-readonly|count

full: (1) a run that fits into a 256 KiB tmpfs, with tiny frames; the disk is
  then filled, leaving 32 KiB; a run with the scene's real frames must exit 1
  naming a file and "No space left on device", and leave results.json absent or
  whole and coherent (every file it names whole; no file of run (1) beside a
  new results.json; no temporary file). (2) A results.json that no cloudbench
  run wrote into the folder, on a disk with room for the lock and the journal
  but not for a new results.json: exit 1 naming results.json and the errno,
  and the file is kept byte for byte.
readonly: a folder holding a results.json, then remounted read-only: a run into
  it, and into a new folder under it, exits 1 at once with
  "DIR: cannot write: Read-only file system"; the results.json is kept.
writers-full, writers-readonly: the writers of the other commands, into a full
  (nothing left) or a read-only tmpfs: perf compare --json, perf export --gbench,
  perf history --json, report -o, merge (shards and histories) each exit 1 with
  "PATH: cannot write: No space left on device" (or "Read-only file system")
  naming the file or folder, and leave no temporary file. writers-full also
  fills the disk so that sweep.json fits but sweep.png does not: sweep exits
  1 with "DIR/sweep.png: cannot write: No space left on device", no Python
  traceback, sweep.json and sweep.md written and no sweep.png.
count: CLOUDBENCH is a build that counts (without -march=native, valgrind
  installed; tests/exact.cmake): count --out FILE on a full and on a read-only
  tmpfs exits 1 with "FILE: cannot write: <reason>".
"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import output_checks  # noqa: E402

SKIP = 77
INSIDE = "CLOUDBENCH_OUTPUTS_IN_NAMESPACE"


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def reexec_in_namespace():
    for flags in (["-rm"], ["-m"]):
        if subprocess.run(["unshare"] + flags + ["true"], capture_output=True).returncode == 0:
            env = dict(os.environ, **{INSIDE: "1"})
            sys.exit(subprocess.run(["unshare"] + flags + [sys.executable] + sys.argv, env=env).returncode)
    print("skipped: neither unshare -rm nor unshare -m may create a mount namespace here")
    sys.exit(SKIP)


def mount_tmpfs(path, size):
    os.makedirs(path, exist_ok=True)
    result = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=%s" % size, "cloudbench-test", path],
                            capture_output=True, text=True)
    if result.returncode != 0:
        print("skipped: cannot mount a tmpfs: " + result.stderr.strip())
        sys.exit(SKIP)


def fill(folder, leave_bytes):
    """Fills the file system of `folder` so that about `leave_bytes` stay free: a filler file
    written until the disk is full, then a spacer of `leave_bytes` removed."""
    spacer = os.path.join(folder, "spacer")
    with open(spacer, "wb") as f:
        f.write(b"\0" * leave_bytes)
    try:
        with open(os.path.join(folder, "filler"), "wb") as f:
            while True:
                f.write(b"\0" * 4096)
                f.flush()
    except OSError:
        pass
    os.remove(spacer)


def run(cli, folder, *extra):
    return subprocess.run([cli, "run", "ci-small", "--backend", "cpu", "--steps", "12", "--threads", "2", "--quiet",
                           "--out", folder] + list(extra), capture_output=True, text=True, timeout=120)


def full(cli, work):
    mount = os.path.join(work, "full")
    mount_tmpfs(mount, "256k")
    folder = os.path.join(mount, "out")
    tiny = ["--set", "render.width=16", "--set", "render.height=12", "--set", "grid.size=[16,16,8]"]
    first = run(cli, folder, *tiny)
    if first.returncode != 0:
        fail("the first run, which fits, exited %d: %s" % (first.returncode, first.stderr))
    before = output_checks.visible_files(folder)
    fill(mount, 32 * 1024)
    second = run(cli, folder)
    print("run on a full disk: exit %d\n%s" % (second.returncode, second.stderr.strip()))
    if second.returncode != 1:
        fail("exit %d on a full disk, expected 1" % second.returncode)
    named = [line for line in second.stderr.splitlines()
             if line.startswith(folder + "/") and ": cannot write: " in line and "No space left on device" in line]
    if not named:
        fail("no line 'FILE: cannot write: ... No space left on device' naming a file in %s" % folder)
    # Every failed write on the full disk says so, not a stale errno left by an image library.
    misnamed = [line for line in second.stderr.splitlines()
                if ": cannot write: " in line and "No space left on device" not in line]
    if misnamed:
        fail("failed writes on a full disk that do not say 'No space left on device': %s" % misnamed)
    output_checks.FRAME_SIZE = output_checks.TOPVIEW_SIZE = None  # either run's images may be named
    problems = output_checks.results_problems(folder)
    after = output_checks.visible_files(folder)
    survivors = [name for name, identity in after.items() if before.get(name) == identity]
    if "results.json" in after and after["results.json"] != before.get("results.json") and survivors:
        problems.append("the first run's files survive beside the new results.json: %s" % survivors)
    if "results.json" in after and after["results.json"] == before.get("results.json") and after != before:
        problems.append("the first run's results.json kept, but its files changed")
    if output_checks.temporary_files(folder):
        problems.append("temporary files left: %s" % output_checks.temporary_files(folder))
    if problems:
        fail("; ".join(problems))
    state = ("absent" if "results.json" not in after else
             "kept" if after["results.json"] == before.get("results.json") else "replaced whole")
    print("results.json %s; the folder is coherent" % state)

    # A results.json that this folder's journal does not list: never removed, and kept when it cannot be replaced.
    os.remove(os.path.join(mount, "filler"))
    shutil.rmtree(folder)
    os.makedirs(folder)
    seeded = os.path.join(folder, "results.json")
    with open(seeded, "w") as f:
        f.write('{"format": "cloudbench-results/1", "seeded": true}\n' + " " * 9000 + "\n")
    original = open(seeded, "rb").read()
    fill(mount, 2 * 4096)  # a page for the probe and then the lock holder's line, one for the journal
    third = run(cli, folder)
    print("run with room for the journal only: exit %d\n%s" % (third.returncode, third.stderr.strip()))
    if third.returncode != 1:
        fail("exit %d, expected 1" % third.returncode)
    if "%s: cannot write: No space left on device" % seeded not in third.stderr:
        fail("no message naming %s and 'No space left on device'" % seeded)
    if open(seeded, "rb").read() != original:
        fail("the seeded results.json was changed")
    if output_checks.temporary_files(folder):
        fail("temporary files left: %s" % output_checks.temporary_files(folder))
    print("the seeded results.json is kept byte for byte")


def readonly(cli, work):
    mount = os.path.join(work, "readonly")
    mount_tmpfs(mount, "64k")
    folder = os.path.join(mount, "out")
    os.makedirs(folder)
    kept = os.path.join(folder, "results.json")
    with open(kept, "w") as f:
        f.write('{"seeded": true}\n')
    result = subprocess.run(["mount", "-o", "remount,ro", mount], capture_output=True, text=True)
    if result.returncode != 0:
        print("skipped: cannot remount read-only: " + result.stderr.strip())
        sys.exit(SKIP)
    for target in (folder, os.path.join(folder, "sub")):
        outcome = run(cli, target)
        expected = "%s: cannot write: Read-only file system\n" % target
        if outcome.returncode != 1 or outcome.stderr != expected:
            fail("--out %s: exit %d, stderr %r; expected exit 1 and %r"
                 % (target, outcome.returncode, outcome.stderr, expected))
        print("refused: " + outcome.stderr.strip())
    if open(kept).read() != '{"seeded": true}\n':
        fail("results.json changed on a read-only file system")


def writer_inputs(cli, work, kind):
    """What the writers read, made outside the tmpfs: a results.json, two sweep shards, a history."""
    inputs = os.path.join(work, "inputs-" + kind)
    shutil.rmtree(inputs, ignore_errors=True)
    fast = ["--backend", "cpu", "--steps", "2", "--set", "warmup_steps=0", "--threads", "2", "--quiet"]
    made = {"results": os.path.join(inputs, "run", "results.json"), "history": os.path.join(inputs, "history.jsonl"),
            "shards": [os.path.join(inputs, "shard-%d" % i, "sweep.json") for i in (1, 2)]}
    commands = [["run", "ci-small"] + fast + ["--out", os.path.dirname(made["results"])]]
    commands += [["sweep", "ci-small", "--vary", "shade.resolution=1,2", "--shard", "%d/2" % i] + fast +
                 ["--out", os.path.dirname(made["shards"][i - 1])] for i in (1, 2)]
    os.makedirs(inputs)
    suite = os.path.join(inputs, "suite.json")
    with open(suite, "w") as f:
        f.write('{"scenes": [{"scene": "ci-small", "set": ["steps=2", "warmup_steps=0"]}]}\n')
    commands.append(["perf", "record", "--suite", suite, "--history", made["history"], "--backend", "cpu", "--quiet"])
    for command in commands:
        result = subprocess.run([cli] + command, capture_output=True, text=True, timeout=120)
        if result.returncode != 0:
            fail("%s exited %d: %s" % (" ".join(command), result.returncode, result.stderr))
    return made


def make_unwritable(mount, kind):
    """Fills the tmpfs at `mount` ("full") or remounts it read-only ("readonly"; skipped, 77, when it cannot)."""
    if kind == "full":
        fill(mount, 0)
        return
    result = subprocess.run(["mount", "-o", "remount,ro", mount], capture_output=True, text=True)
    if result.returncode != 0:
        print("skipped: cannot remount read-only: " + result.stderr.strip())
        sys.exit(SKIP)


def writers(cli, work, kind):
    made = writer_inputs(cli, work, kind)
    mount = os.path.join(work, "writers-" + kind)
    mount_tmpfs(mount, "256k")
    folder = os.path.join(mount, "out")
    os.makedirs(folder)
    reason = "No space left on device" if kind == "full" else "Read-only file system"
    failed = []
    make_unwritable(mount, kind)
    cases = [
        ("perf compare --json", os.path.join(folder, "compare.json"),
         ["perf", "compare", made["results"], made["results"], "--json", os.path.join(folder, "compare.json")]),
        ("perf export --gbench", os.path.join(folder, "gbench.json"),
         ["perf", "export", "--gbench", os.path.join(folder, "gbench.json"), made["results"]]),
        ("perf history --json", os.path.join(folder, "changes.json"),
         ["perf", "history", made["history"], "--json", os.path.join(folder, "changes.json")]),
        ("report -o", os.path.join(folder, "report.html"),
         ["report", made["results"], "-o", os.path.join(folder, "report.html")]),
        ("merge of shards", os.path.join(folder, "merged"),
         ["merge"] + made["shards"] + ["--out", os.path.join(folder, "merged")]),
        ("merge of histories", os.path.join(folder, "histories"),
         ["merge", made["history"], "--out", os.path.join(folder, "histories")]),
    ]
    for name, path, command in cases:
        result = subprocess.run([cli] + command, capture_output=True, text=True, timeout=120)
        # The file, or for merge its folder or a file in it; "merge: " may come first.
        named = re.compile(r"^(merge: )?%s(/[^/:]+)?: cannot write: %s$" % (re.escape(path), re.escape(reason)))
        lines = [line for line in result.stderr.splitlines() if named.match(line)]
        if result.returncode != 1 or not lines:
            failed.append("%s: exit %d, stderr %r; expected exit 1 and a line '%s: cannot write: %s'"
                          % (name, result.returncode, result.stderr, path, reason))
            print("FAIL: " + failed[-1])
        else:
            print("%s: %s" % (name, lines[0]))
    if output_checks.temporary_files(mount):
        failed.append("temporary files left: %s" % output_checks.temporary_files(mount))
    if kind == "full":
        sweep_png_full(cli, work)
    if failed:
        fail("%d writer(s) did not say why" % len(failed))


def sweep_png_full(cli, work):
    """A disk with room for sweep.json and sweep.md but not sweep.png."""
    plots = subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"], capture_output=True).returncode == 0
    if not plots:
        print("no python3 with matplotlib: sweep promises no plot; sweep.png not checked")
        return
    mount = os.path.join(work, "sweep-full")
    mount_tmpfs(mount, "256k")
    folder = os.path.join(mount, "out")
    # The lock, the journal and the probe take a page each; sweep.json (7 KiB for two points) two pages;
    # sweep.md one. sweep.png (40 KiB) then finds no room.
    fill(mount, 8 * 4096)
    command = [cli, "sweep", "ci-small", "--vary", "shade.resolution=1,2", "--backend", "cpu", "--steps", "2",
               "--set", "warmup_steps=0", "--threads", "2", "--quiet", "--out", folder]
    result = subprocess.run(command, capture_output=True, text=True, timeout=120)
    print("sweep with no room for sweep.png: exit %d\n%s" % (result.returncode, result.stderr.strip()))
    expected = "%s/sweep.png: cannot write: No space left on device" % folder
    problems = []
    if result.returncode != 1:
        problems.append("exit %d, expected 1" % result.returncode)
    if expected not in result.stderr.splitlines():
        problems.append("no line %r" % expected)
    if "Traceback" in result.stderr:
        problems.append("a Python traceback reached the user")
    for name in ("sweep.json", "sweep.md"):
        if not os.path.isfile(os.path.join(folder, name)):
            problems.append("no %s" % name)
    if os.path.exists(os.path.join(folder, "sweep.png")):
        problems.append("a sweep.png was left")
    if output_checks.temporary_files(folder):
        problems.append("temporary files left: %s" % output_checks.temporary_files(folder))
    if problems:
        fail("; ".join(problems))
    print("sweep.png: %s; sweep.json and sweep.md written" % expected)


def count(cli, work):
    for kind, reason in (("full", "No space left on device"), ("readonly", "Read-only file system")):
        mount = os.path.join(work, "count-" + kind)
        mount_tmpfs(mount, "64k")
        make_unwritable(mount, kind)
        path = os.path.join(mount, "count.json")
        result = subprocess.run([cli, "count", "ci-small", "--steps", "2", "--set", "warmup_steps=1", "--quiet",
                                 "--out", path], capture_output=True, text=True, timeout=300)
        expected = "%s: cannot write: %s" % (path, reason)
        if result.returncode != 1 or expected not in result.stderr.splitlines():
            fail("count on a %s disk: exit %d, stderr %r; expected exit 1 and %r"
                 % (kind, result.returncode, result.stderr, expected))
        print("count --out on a %s disk: %s" % (kind, expected))


def main():
    modes = ("full", "readonly", "writers-full", "writers-readonly", "count")
    if len(sys.argv) != 4 or sys.argv[3] not in modes:
        sys.exit(__doc__)
    if not os.environ.get(INSIDE):
        reexec_in_namespace()
    cli, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    if sys.argv[3].startswith("writers-"):
        writers(cli, work, sys.argv[3][len("writers-"):])
    elif sys.argv[3] == "count":
        count(cli, work)
    else:
        {"full": full, "readonly": readonly}[sys.argv[3]](cli, work)
    print("ok")


if __name__ == "__main__":
    main()

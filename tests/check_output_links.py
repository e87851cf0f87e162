#!/usr/bin/python3
"""No output follows a link (docs/results.md#output-folders).

usage: check_output_links.py CLOUDBENCH DIR GROUP

For each case a symbolic link is planted at one name a command creates,
replaces, locks or removes, pointing outside the output folder at a victim (a
file, or a folder holding one file). The command must exit 1 with the line
"SHOWN: is a symbolic link; cloudbench does not write through links (remove it)"
naming the link, the victim must be unchanged byte for byte, no file may
appear in the victim's folder, and the link must still be there. GROUP is one of:

  run       run's lock, journal, results.json and its temporary name, the frames
            (.exr, .png), the top view, a previous run's journalled file that is
            now a link, and run --save-state DIR with DIR a link
  dump      a step folder that is a link, a .npy and a frame in a step folder,
            the temporary name of a .npy, and a previous dump's journalled
            step_0000/q.npy whose step_0000 is now a link
  commands  conform.json, conform.csv, conform's lock, a conform --vary case
            folder, accuracy.json, accuracy.md
  sweep     sweep.json, sweep.md, sweep.png, a shard's sweep.json and sweep.png,
            merge's sweep.json, sweep.png and history.jsonl
  named     files the user names: report -o FILE and its temporary name,
            perf compare --json FILE, perf compare --keep DIR (its manifest and side folders),
            perf export --gbench OUT,
            perf history --json FILE
  count     count --out FILE and its temporary name (CLOUDBENCH must be a build
            that counts: without -march=native, valgrind installed)
  followed  what is followed: --out DIR given as a link, a link among DIR's
            leading folders, and a link among the folders of report -o FILE;
            the outputs land in the folder the link points to

Every run is ci-small, cut to 2 steps without warm-up, on the cpu backend.
"""
import json
import os
import shutil
import subprocess
import sys

CLI = None
WORK = None
FAST = ["--backend", "cpu", "--steps", "2", "--set", "warmup_steps=0", "--threads", "2", "--quiet"]
VICTIM_BYTES = b"the victim's bytes: a file of another user\n"
failures = []


def fail(message):
    print("FAIL: " + message)
    failures.append(message)


def cloudbench(*args):
    return subprocess.run([CLI] + list(args), capture_output=True, text=True, timeout=300)


def fresh(name):
    path = os.path.join(WORK, "".join(c if c.isalnum() or c in "/-_" else "_" for c in name))
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path)
    return path


class Victim:
    """A file outside every output folder, alone in a folder of its own."""

    def __init__(self, case):
        self.folder = fresh("victims/" + case)
        self.file = os.path.join(self.folder, "victim.txt")
        with open(self.file, "wb") as f:
            f.write(VICTIM_BYTES)
        self.listing = sorted(os.listdir(self.folder))

    def problems(self):
        found = []
        with open(self.file, "rb") as f:
            if f.read() != VICTIM_BYTES:
                found.append("the victim %s was changed" % self.file)
        if sorted(os.listdir(self.folder)) != self.listing:
            found.append("files appeared in the victim's folder %s: %s"
                         % (self.folder, sorted(os.listdir(self.folder))))
        return found


def plant(link, victim, folder_link=False):
    os.makedirs(os.path.dirname(link), exist_ok=True)
    if os.path.lexists(link):
        if os.path.isdir(link) and not os.path.islink(link):
            shutil.rmtree(link)
        else:
            os.remove(link)
    os.symlink(victim.folder if folder_link else victim.file, link)


def check_refused(case, result, link, shown, victim, folder_link=False):
    """The command exited 1 naming the link, and nothing outside the folder changed."""
    message = "%s: is a symbolic link; cloudbench does not write through links (remove it)" % shown
    problems = victim.problems()
    if result.returncode != 1:
        problems.append("exit %d, expected 1" % result.returncode)
    # The line may say more around it ("dump stopped at step 0: MESSAGE (steps before it are in DIR)").
    if not any(line.startswith(message) or (": " + message) in line for line in result.stderr.splitlines()):
        problems.append("no line %r in stderr %r" % (message, result.stderr))
    if not os.path.islink(link) or os.readlink(link) != (victim.folder if folder_link else victim.file):
        problems.append("the link %s was removed or changed" % link)
    if problems:
        fail("%s: %s" % (case, "; ".join(problems)))
    else:
        print("refused: %s: %s" % (case, message))


def refused_case(case, name, make_command, folder=None, folder_link=False, prepare=None):
    """Plants a link at FOLDER/NAME, runs the command `make_command(FOLDER)`, checks the refusal."""
    folder = folder or fresh("cases/" + case)
    if prepare:
        prepare(folder)
    victim = Victim(case)
    link = os.path.join(folder, name)
    plant(link, victim, folder_link)
    result = cloudbench(*make_command(folder))
    check_refused(case, result, link, os.path.join(folder, name), victim, folder_link)
    return folder


def run_command(folder, *extra):
    return ["run", "ci-small"] + FAST + ["--out", folder] + list(extra)


def group_run():
    for case, name in [("lock", ".cloudbench.lock"), ("journal", ".cloudbench-run.files"),
                       ("results", "results.json"), ("results-temporary", ".results.partial.json"),
                       ("frame-exr", "frame-splat-above-cpu.exr"), ("frame-png", "frame-splat-above-cpu.png"),
                       ("frame-png-temporary", ".frame-splat-above-cpu.partial.png"),
                       ("topview", "topview-cpu.png")]:
        refused_case("run " + case, name, run_command)

    # A previous run's file, listed in the journal, that is now a link: the claim refuses to remove it.
    def previous_run(folder):
        result = cloudbench(*run_command(folder))
        if result.returncode != 0:
            fail("run (to leave a journal) exited %d: %s" % (result.returncode, result.stderr))
    refused_case("run previous results.json", "results.json", run_command, prepare=previous_run)
    refused_case("run previous frame", "frame-splat-above-cpu.png", run_command, prepare=previous_run)

    # run --save-state DIR, DIR a link to a folder outside: never replaced through the link.
    state_parent = fresh("cases/save-state")
    refused_case("run --save-state", "state", lambda f: run_command(os.path.join(f, "out"), "--save-state",
                                                                     os.path.join(f, "state")),
                 folder=state_parent, folder_link=True)


def dump_command(folder):
    return ["dump", "ci-small", "--steps", "1", "--quiet", "--out", folder]


def group_dump():
    refused_case("dump step folder", "step_0000", dump_command, folder_link=True)
    step = lambda folder: os.makedirs(os.path.join(folder, "step_0000"))  # noqa: E731
    refused_case("dump step .npy", "step_0000/q.npy", dump_command, prepare=step)
    refused_case("dump step .npy temporary", "step_0000/.q.partial.npy", dump_command, prepare=step)
    refused_case("dump step frame", "step_0000/frame-splat-above.exr", dump_command, prepare=step)

    # A previous dump's journal lists step_0000/q.npy; step_0000 is now a link to a folder holding a q.npy.
    folder = fresh("cases/dump previous")
    result = cloudbench(*dump_command(folder))
    if result.returncode != 0:
        fail("dump (to leave a journal) exited %d: %s" % (result.returncode, result.stderr))
    victim = Victim("dump previous")
    shutil.copy(os.path.join(folder, "step_0000", "q.npy"), os.path.join(victim.folder, "q.npy"))
    victim.listing = sorted(os.listdir(victim.folder))
    q_bytes = open(os.path.join(victim.folder, "q.npy"), "rb").read()
    link = os.path.join(folder, "step_0000")
    plant(link, victim, folder_link=True)
    result = cloudbench(*dump_command(folder))
    check_refused("dump previous step_0000/q.npy through a link", result, link, link, victim, folder_link=True)
    if open(os.path.join(victim.folder, "q.npy"), "rb").read() != q_bytes:
        fail("dump previous: the q.npy behind the link was changed")


def group_commands():
    conform = lambda f: ["conform", "ci-small"] + FAST + ["--out", f]  # noqa: E731
    accuracy = lambda f: ["accuracy", "ci-small"] + FAST + ["--out", f]  # noqa: E731
    refused_case("conform.json", "conform.json", conform)
    refused_case("conform.csv", "conform.csv", conform)
    refused_case("conform lock", ".cloudbench.lock", conform)
    refused_case("accuracy.json", "accuracy.json", accuracy)
    refused_case("accuracy.md", "accuracy.md", accuracy)
    # conform --vary: a folder per case for its difference images.
    refused_case("conform case folder", "smooth.radius=0", lambda f: conform(f)[:2] + ["--vary", "smooth.radius=0,2"]
                 + conform(f)[2:], folder_link=True)


def sweep_command(folder, *extra):
    return ["sweep", "ci-small", "--vary", "shade.resolution=1,2"] + FAST + ["--out", folder] + list(extra)


def group_sweep():
    plots = subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"], capture_output=True).returncode == 0
    names = ["sweep.json", "sweep.md"] + (["sweep.png", ".sweep.partial.png"] if plots else [])
    for name in names:
        refused_case("sweep " + name, name, sweep_command)
    for name in ["sweep.json"] + (["sweep.png"] if plots else []):
        refused_case("shard " + name, name, lambda f: sweep_command(f, "--shard", "1/2"))
    # merge: two real shards, then a link at each output merge writes.
    shards = []
    for index in (1, 2):
        folder = fresh("cases/shard-%d" % index)
        result = cloudbench(*sweep_command(folder, "--shard", "%d/2" % index))
        if result.returncode != 0:
            fail("sweep --shard %d/2 exited %d: %s" % (index, result.returncode, result.stderr))
        shards.append(os.path.join(folder, "sweep.json"))
    for name in ["sweep.json", "sweep.md"] + (["sweep.png"] if plots else []):
        refused_case("merge " + name, name, lambda f: ["merge"] + shards + ["--out", f])
    history = write_history()
    refused_case("merge history.jsonl", "history.jsonl", lambda f: ["merge", history, "--out", f])
    if not plots:
        print("note: no python3 with matplotlib: sweep.png not checked")


def results_file():
    folder = os.path.join(WORK, "inputs", "run")
    if not os.path.exists(os.path.join(folder, "results.json")):
        result = cloudbench(*run_command(folder))
        if result.returncode != 0:
            fail("run (an input) exited %d: %s" % (result.returncode, result.stderr))
    return os.path.join(folder, "results.json")


def write_history():
    """A perf history of one record, made by perf record."""
    path = os.path.join(WORK, "inputs", "history.jsonl")
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        suite = os.path.join(WORK, "inputs", "suite.json")
        with open(suite, "w") as f:
            json.dump({"scenes": [{"scene": "ci-small", "set": ["steps=2", "warmup_steps=0"]}]}, f)
        result = cloudbench("perf", "record", "--suite", suite, "--history", path, "--backend", "cpu", "--quiet")
        if result.returncode != 0:
            fail("perf record (an input) exited %d: %s" % (result.returncode, result.stderr))
    return path


def group_named():
    results = results_file()
    history = write_history()
    refused_case("report -o", "report.html", lambda f: ["report", results, "-o", os.path.join(f, "report.html")])
    refused_case("report -o temporary", ".report.partial.html",
                 lambda f: ["report", results, "-o", os.path.join(f, "report.html")])
    refused_case("perf compare --json", "compare.json",
                 lambda f: ["perf", "compare", results, results, "--json", os.path.join(f, "compare.json")])
    refused_case("perf export --gbench", "gbench.json",
                 lambda f: ["perf", "export", "--gbench", os.path.join(f, "gbench.json"), results])
    refused_case("perf history --json", "changes.json",
                 lambda f: ["perf", "history", history, "--json", os.path.join(f, "changes.json")])
    keep = lambda f: ["perf", "compare", "--interleave", CLI, CLI, "ci-small", "--backend", "cpu", "--rounds", "1",  # noqa: E731
                      "--steps", "3", "--set", "warmup_steps=0", "--quiet", "--keep", f]
    refused_case("perf compare --keep manifest", "interleave.json", keep)
    refused_case("perf compare --keep side folder", "base", keep, folder_link=True)
    suite = os.path.join(WORK, "inputs", "suite.json")
    refused_case("perf record --history", "history.jsonl",
                 lambda f: ["perf", "record", "--suite", suite, "--history", os.path.join(f, "history.jsonl"),
                            "--backend", "cpu", "--quiet"])


def group_count():
    count = lambda f: ["count", "ci-small", "--steps", "2", "--set", "warmup_steps=1", "--quiet",  # noqa: E731
                       "--out", os.path.join(f, "count.json")]
    refused_case("count --out", "count.json", count)
    refused_case("count --out temporary", ".count.partial.json", count)


def group_followed():
    # --out DIR given as a link: followed (the user named it); the outputs and the lock are in its target.
    real = fresh("cases/followed-real")
    parent = fresh("cases/followed-links")
    os.symlink(real, os.path.join(parent, "out"))
    for out, where in [(os.path.join(parent, "out"), real), (os.path.join(parent, "out", "sub"),
                                                              os.path.join(real, "sub"))]:
        result = cloudbench(*run_command(out))
        placed = [n for n in ("results.json", ".cloudbench.lock", "topview-cpu.png")
                  if os.path.isfile(os.path.join(where, n)) and not os.path.islink(os.path.join(where, n))]
        if result.returncode != 0 or len(placed) != 3:
            fail("--out %s: exit %d, files in %s: %s; %s" % (out, result.returncode, where, placed, result.stderr))
        else:
            print("followed: --out %s wrote into %s" % (out, where))
    results = os.path.join(real, "results.json")
    report = os.path.join(parent, "out", "report.html")
    result = cloudbench("report", results, "-o", report)
    if result.returncode != 0 or not os.path.isfile(os.path.join(real, "report.html")):
        fail("report -o %s: exit %d, no report.html in %s: %s" % (report, result.returncode, real, result.stderr))
    else:
        print("followed: report -o %s wrote into %s" % (report, real))


def main():
    global CLI, WORK
    groups = {"run": group_run, "dump": group_dump, "commands": group_commands, "sweep": group_sweep,
              "named": group_named, "count": group_count, "followed": group_followed}
    if len(sys.argv) != 4 or sys.argv[3] not in groups:
        sys.exit(__doc__)
    CLI, WORK = os.path.abspath(sys.argv[1]), os.path.join(os.path.abspath(sys.argv[2]), sys.argv[3])
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    groups[sys.argv[3]]()
    if failures:
        print("%d case(s) failed" % len(failures))
        sys.exit(1)
    print("ok")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Kills `cloudbench run` at random points and checks, after every kill, that
the output folder is coherent (docs/results.md#output-folders):

- results.json is absent or valid JSON whose "files" all exist whole
  (PNG decoded, OpenEXR chunks within the file, sizes as the scene says);
- no output of the run before the killed one survives next to a results.json
  the killed run wrote (compared by inode, times and size, and by name: consecutive runs use
  different camera names, so their frames have different names);
- a results.json of the run before survives only with every file it names;
- temporary files (".*.partial*") may be left by the kill, but the next run
  removes them: after each run that completes, the folder holds exactly one
  complete run and no temporary file.

Each trial runs into the same folder, killed with SIGKILL after a random delay
in [0, the time a whole run takes] (odd trials: from the time the first output
appears, to aim at the writes). The trials' seed is printed; pass --seed
to replay. Prints one line per phase count at the end.

usage: check_output_kills.py CLOUDBENCH DIR [--trials N] [--seed S] [--steps N]
"""
import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import output_checks  # noqa: E402

CAMERA = '{"name":"%s","eye":[-400,-400,1800],"target":[1600,1600,300],"up":[0,0,1],"fov_deg":60,"near":1,"far":20000}'


def command(cli, folder, steps, camera):
    return [cli, "run", "ci-small", "--backend", "cpu", "--steps", str(steps), "--threads", "2", "--quiet",
            "--out", folder, "--set", "render.cameras=[%s]" % (CAMERA % camera)]


def results_identity(folder):
    return output_checks.visible_files(folder).get("results.json")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("cli")
    parser.add_argument("folder")
    parser.add_argument("--trials", type=int, default=50)
    parser.add_argument("--seed", type=int, default=None)
    parser.add_argument("--steps", type=int, default=12)
    args = parser.parse_args()
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(1 << 30)
    print("seed %d (replay with --seed %d)" % (seed, seed), flush=True)
    rng = random.Random(seed)
    shutil.rmtree(args.folder, ignore_errors=True)
    os.makedirs(args.folder)

    # A whole run, timed, with the time its first output (results.json) appears: the kill delays
    # are drawn from [0, the whole time] for even trials and from [first output, whole] for odd ones,
    # where the writes are (most of a run into a small folder is starting up).
    start = time.monotonic()
    process = subprocess.Popen(command(args.cli, args.folder, args.steps, "cam0"), stdout=subprocess.DEVNULL)
    first_output = None
    while process.poll() is None:
        if first_output is None and os.path.exists(os.path.join(args.folder, "results.json")):
            first_output = time.monotonic() - start
        time.sleep(0.002)
    whole = time.monotonic() - start
    if process.returncode != 0:
        sys.exit("the first run exited %d" % process.returncode)
    first_output = min(first_output or 0.0, whole)
    print("a whole run takes %.2f s, its first output appears after %.2f s" % (whole, first_output), flush=True)
    problems = output_checks.complete_run_problems(args.folder)
    if problems:
        sys.exit("after the first run: " + "; ".join(problems))

    phases = {}
    failures = []
    for trial in range(args.trials):
        before = output_checks.visible_files(args.folder)
        before_results = results_identity(args.folder)
        delay = rng.uniform(0.0 if trial % 2 == 0 else first_output, whole)
        camera = "cam%d" % ((trial + 1) % 2)
        process = subprocess.Popen(command(args.cli, args.folder, args.steps, camera),
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(delay)
        process.send_signal(signal.SIGKILL)
        _, stderr = process.communicate()
        rc = process.returncode
        after = output_checks.visible_files(args.folder)
        now_results = results_identity(args.folder)
        problems = output_checks.results_problems(args.folder)
        survivors = sorted(name for name, inode in after.items() if before.get(name) == inode)
        # The phase the kill hit, as seen from the folder.
        if rc == 0:
            phase = "finished"
            problems += output_checks.complete_run_problems(args.folder)
        elif rc != -signal.SIGKILL:
            phase = "failed"
            problems.append("exit %d: %s" % (rc, stderr.decode(errors="replace").strip()))
        elif now_results is not None and now_results == before_results:
            # The killed run wrote nothing yet; the previous run's files may be partly removed
            # (a kill during the removal), but then results.json, removed first, is gone too.
            phase = "before any output"
            if set(after) != set(before):
                problems.append("previous results.json kept, but the files changed: %s -> %s"
                                % (sorted(before), sorted(after)))
        elif now_results is None:
            phase = "removing the previous outputs" if survivors else "before results.json"
            new = sorted(set(after) - set(survivors))
            if new:
                problems.append("files written without a results.json: %s" % ", ".join(new))
        else:
            complete = json.load(open(os.path.join(args.folder, "results.json"))).get("complete")
            phase = "finished, unreported" if complete else "backend running"
            if survivors:
                problems.append("the previous run's files survive beside the new results.json: %s"
                                % ", ".join(survivors))
        phases[phase] = phases.get(phase, 0) + 1
        temporaries = output_checks.temporary_files(args.folder)
        print("trial %2d: killed after %.3f s, %s%s" % (trial, delay, phase,
              ", temporary files left: " + ", ".join(temporaries) if temporaries else ""), flush=True)
        if problems:
            failures.append("trial %d (%s): %s" % (trial, phase, "; ".join(problems)))
            print("  INCOHERENT: " + "; ".join(problems), flush=True)

    # The folder after the last kill is taken over by a whole run, which leaves exactly its own outputs.
    subprocess.run(command(args.cli, args.folder, args.steps, "final"), check=True, stdout=subprocess.DEVNULL)
    problems = output_checks.complete_run_problems(args.folder)
    if problems:
        failures.append("the rerun after the last kill: " + "; ".join(problems))
    for phase, count in sorted(phases.items()):
        print("phase %s: %d" % (phase, count))
    if failures:
        print("%d of %d trials incoherent (seed %d)" % (len(failures), args.trials, seed))
        for f in failures:
            print(f)
        sys.exit(1)
    print("all %d kills left a coherent folder (seed %d)" % (args.trials, seed))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Mutation testing for cloudbench: plant each bug of tools/mutants.json in turn, rebuild, run the
oracles cheapest first, and report which bugs the project's tests catch. docs/testing.md, "Mutation testing".

Standard library only. It never edits the caller's checkout: it works in a separate git worktree (--tree DIR, or by
default a worktree of HEAD under the temporary folder, kept between runs so that --resume and later runs only rebuild
incrementally) with its own build folder.

  tools/mutate.py --list                      the mutant set
  tools/mutate.py --check [--tree DIR]        every `find` occurs exactly once (no build; CTest Tools.MutantsApply)
  tools/mutate.py --list-ctest-oracle --build-dir DIR
                                              the tests the CTest oracle runs in a configured build folder
  tools/mutate.py [--only ID,ID] [--resume]   the run: results.json and summary.md under --out

Oracles, cheapest first (a mutant stops at the first that catches it unless --all-oracles):
  conform   `cloudbench conform ci-small` on every built backend
  ctest     the CTest suite less the tests labelled --ctest-exclude-label (default `slow`: the sanitized build, the
            fuzzer, exact mode's counts, the benchmarks) and less --ctest-exclude's names, with --stop-on-failure
  medium    `cloudbench conform thesis-medium`
A run past an oracle's timeout counts as caught (a hang), and is marked so. A mutant whose build fails is
"build-broken": a bad mutant, reported and never counted as caught.
"""

import argparse
import datetime
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

LAYERS = ("core", "glsl", "cpu", "vk", "gl", "harness")
ORACLES = ("conform", "ctest", "medium")
FIELDS = ("id", "layer", "file", "find", "replace", "bug")
DONE = ("caught", "survived", "build-broken")
# Tools.MutantsApply checks the find texts, so it fails in every mutated tree by construction.
ALWAYS_EXCLUDED = r"^Tools\.MutantsApply$"
SCRIPT_DIR = os.path.dirname(os.path.abspath(__file__))
CALLER_ROOT = os.path.dirname(SCRIPT_DIR)


SCENES = {"conform": "ci-small", "medium": "thesis-medium"}


def timeout_of(args, oracle, baseline=None):
    """The oracle's timeout: its option, or three times its time on the unmutated tree when that is longer."""
    limit = {"conform": args.conform_timeout, "ctest": args.ctest_timeout, "medium": args.medium_timeout}[oracle]
    seconds = ((baseline or {}).get("oracles", {}).get(oracle) or {}).get("seconds")
    return max(limit, 3 * seconds + 30) if seconds else limit


def log(msg):
    print(f"mutate: {msg}", flush=True)


class Interrupted(Exception):
    pass


def _on_sigterm(signum, frame):
    raise Interrupted(f"signal {signum}")


# ---- the mutant set -------------------------------------------------------------------------------------------------

def load_mutants(path):
    with open(path, encoding="utf-8") as f:
        mutants = json.load(f)
    problems, seen = [], set()
    for n, m in enumerate(mutants):
        name = m.get("id", f"#{n}")
        for field in FIELDS:
            if not isinstance(m.get(field), str) or not m[field]:
                problems.append(f"{name}: field '{field}' missing or empty")
        if m.get("layer") not in LAYERS:
            problems.append(f"{name}: layer '{m.get('layer')}' is not one of {', '.join(LAYERS)}")
        if m.get("find") == m.get("replace"):
            problems.append(f"{name}: replace equals find")
        if name in seen:
            problems.append(f"{name}: id used twice")
        seen.add(name)
    return mutants, problems


def check_applies(mutants, tree):
    """Problems with applying each mutant to `tree`: a find text must occur exactly once in its file."""
    problems = []
    for m in mutants:
        path = os.path.join(tree, m["file"])
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            problems.append(f"{m['id']}: {m['file']}: {e.strerror}")
            continue
        count = text.count(m["find"])
        if count != 1:
            problems.append(f"{m['id']}: {m['file']}: find text occurs {count} times (must be exactly once)")
    return problems


# ---- processes ------------------------------------------------------------------------------------------------------

def run(cmd, cwd, log_path, timeout, env=None):
    """Runs cmd in its own process group, output to log_path. Returns (exit code or None on timeout, seconds)."""
    start = time.monotonic()
    with open(log_path, "ab") as out:
        out.write(("$ " + " ".join(cmd) + "\n").encode())
        out.flush()
        proc = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env,
                                start_new_session=True)
        try:
            rc = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            rc = None
        finally:
            if proc.poll() is None:  # timeout, Ctrl-C or SIGTERM: end the whole group, then reap it
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                proc.wait()
        out.write(f"\n[exit {rc} after {time.monotonic() - start:.1f} s]\n".encode())
    return rc, time.monotonic() - start


def tail(path, lines=15):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            return "".join(f.readlines()[-lines:])
    except OSError:
        return ""


def git(tree, *args):
    return subprocess.run(["git", "-C", tree, *args], capture_output=True, text=True)


# ---- the worktree and build -----------------------------------------------------------------------------------------

def prepare_tree(args):
    caller_top = git(CALLER_ROOT, "rev-parse", "--show-toplevel").stdout.strip() or CALLER_ROOT
    if args.tree:
        tree = os.path.abspath(args.tree)
    else:
        head = git(CALLER_ROOT, "rev-parse", "--short=10", "HEAD").stdout.strip()
        tree = os.path.join(tempfile.gettempdir(), f"cloudbench-mutate-{head}")
    if os.path.realpath(tree) == os.path.realpath(caller_top):
        sys.exit("mutate: --tree is the checkout this script runs from; give a separate worktree")
    if not os.path.exists(tree):
        rev = args.rev or "HEAD"
        log(f"creating worktree {tree} at {rev}")
        r = git(CALLER_ROOT, "worktree", "add", "--detach", tree, rev)
        if r.returncode != 0:
            sys.exit(f"mutate: git worktree add failed: {r.stderr.strip()}")
    top = git(tree, "rev-parse", "--show-toplevel")
    if top.returncode != 0 or os.path.realpath(top.stdout.strip()) != os.path.realpath(tree):
        sys.exit(f"mutate: {tree} is not the top of a git worktree")
    dirty = git(tree, "status", "--porcelain", "--untracked-files=no").stdout.strip()
    if dirty:
        sys.exit(f"mutate: {tree} has changes to tracked files (an interrupted run?); commit or "
                 f"`git -C {tree} checkout -- .` first:\n{dirty}")
    return tree


def build_env(tree):
    env = dict(os.environ)
    env.setdefault("CCACHE_BASEDIR", os.path.dirname(tree))
    return env


def configure(tree, build, logs, env):
    if os.path.exists(os.path.join(build, "build.ninja")):
        return
    cmd = ["cmake", "--preset", "release", "-DCLOUDBENCH_SANITIZED=OFF", f"-B{build}"]
    if shutil.which("ccache"):
        cmd.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
    rc, _ = run(cmd, tree, os.path.join(logs, "configure.log"), None, env)
    if rc != 0:
        sys.exit(f"mutate: configure failed; see {logs}/configure.log\n{tail(os.path.join(logs, 'configure.log'))}")


def build(build_dir, targets, jobs, log_path, env, timeout):
    return run(["cmake", "--build", build_dir, f"-j{jobs}", "--target", *targets], None, log_path, timeout, env)


# ---- oracles --------------------------------------------------------------------------------------------------------

def failing_rows(log_path):
    """conform's failing rows: table lines whose result column says fail or failed, and `backend X failed` lines."""
    rows = []
    for line in tail(log_path, 400).splitlines():
        if re.search(r"\b(fail|failed|crashed|timeout)\b", line) and not line.startswith("$ "):
            rows.append(line.strip())
    return rows[:20]


def oracle_conform(scene, tree, build, out, logs, mid, timeout, env):
    log_path = os.path.join(logs, f"{mid}.{'conform' if scene == 'ci-small' else 'medium'}.log")
    cli = os.path.join(build, "cloudbench")
    folder = os.path.join(out, "conform", mid, scene)
    shutil.rmtree(folder, ignore_errors=True)
    rc, secs = run([cli, "conform", scene, "--out", folder], tree, log_path, timeout, env)
    result = {"seconds": round(secs, 1), "exit": rc}
    if rc is None:
        result.update(caught=True, timeout=True, failed=[f"timeout after {timeout} s (a hang counts as caught)"])
    elif rc == 0:
        result.update(caught=False)
    else:
        result.update(caught=True, failed=failing_rows(log_path) or [f"exit {rc}"])
    return result


def ctest_selection(exclude, label_exclude=""):
    """The CTest oracle's choice of tests: every test less `exclude`'s names and `label_exclude`'s labels."""
    return ["-E", exclude] + (["-LE", label_exclude] if label_exclude else [])


def ctest_cmd(build, exclude, jobs, junit, timeout_each, stop, label_exclude=""):
    cmd = ["ctest", "--test-dir", build, "-j", str(jobs), "--output-on-failure", "--output-junit", junit,
           "--timeout", str(timeout_each)] + ctest_selection(exclude, label_exclude)
    if stop:
        cmd.append("--stop-on-failure")
    return cmd


def ctest_failures(junit, log_path):
    names = []
    try:
        for case in ET.parse(junit).getroot().iter("testcase"):
            if case.get("status") == "fail" or case.find("failure") is not None:
                names.append(case.get("name"))
    except (OSError, ET.ParseError):
        pass
    if not names:  # fall back on ctest's summary
        names = re.findall(r"^\s*\d+ - (\S+) \((?:Failed|Timeout|SEGFAULT|Subprocess aborted|Child aborted|"
                           r"Exception|Not Run)[^)]*\)", tail(log_path, 400), re.M)
    return names


def oracle_ctest(args, build, logs, mid, exclude, env):
    log_path = os.path.join(logs, f"{mid}.ctest.log")
    junit = os.path.join(logs, f"{mid}.ctest.xml")
    if os.path.exists(junit):
        os.remove(junit)
    cmd = ctest_cmd(build, exclude, args.jobs, junit, args.test_timeout, not args.all_oracles,
                    args.ctest_exclude_label)
    # Without cost data CTest runs the tests in their declared order, unit tests before the long CLI runs, so a
    # stop at the first failure comes sooner; the data of the last run would put the longest tests first.
    cost = os.path.join(build, "Testing", "Temporary", "CTestCostData.txt")
    if os.path.exists(cost):
        os.remove(cost)
    limit = timeout_of(args, "ctest", getattr(args, "baseline", None))
    rc, secs = run(cmd, None, log_path, limit, env)
    result = {"seconds": round(secs, 1), "exit": rc}
    if rc is None:
        result.update(caught=True, timeout=True, failed=[f"ctest ran past {limit:.0f} s (a hang counts as caught)"])
    elif rc == 0:
        result.update(caught=False)
    else:
        failed = ctest_failures(junit, log_path)
        timeouts = re.findall(r"^\s*\d+ - (\S+) \(Timeout\)", tail(log_path, 400), re.M)
        result.update(caught=True, failed=failed or [f"ctest exit {rc}"])
        if timeouts:
            result["timeout"] = True
            result["timed_out_tests"] = timeouts
    return result


# ---- results --------------------------------------------------------------------------------------------------------

def write_json(path, data):
    tmp = path + ".partial"
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    os.replace(tmp, path)


def summarize(results, mutants, path):
    by_id = {m["id"]: m for m in mutants}
    rows = [r for r in results["mutants"].values() if r.get("status") in DONE]
    lines = [f"# Mutation testing: {results.get('commit', '?')}", "",
             f"{len(rows)} mutants run with tools/mutate.py ({results.get('started', '')}); "
             f"oracles in order: {', '.join(results.get('oracles', ORACLES))}.", "",
             "| layer | mutants | caught | survived | build-broken | catch rate |",
             "|---|---:|---:|---:|---:|---:|"]

    def line(name, group):
        c = sum(r["status"] == "caught" for r in group)
        s = sum(r["status"] == "survived" for r in group)
        b = sum(r["status"] == "build-broken" for r in group)
        rate = f"{100.0 * c / (c + s):.0f} %" if c + s else "-"
        return f"| {name} | {len(group)} | {c} | {s} | {b} | {rate} |"

    for layer in LAYERS:
        group = [r for r in rows if r["layer"] == layer]
        if group:
            lines.append(line(layer, group))
    lines.append(line("**all**", rows))
    lines += ["", "First catch per oracle (a later oracle runs only on what the earlier ones missed, unless "
              "--all-oracles):", "", "| oracle | first catches | of which timeouts | median seconds |",
              "|---|---:|---:|---:|"]
    for o in ORACLES:
        caught = [r for r in rows if r.get("caught_by") == o]
        secs = sorted(r["oracles"][o]["seconds"] for r in rows if o in r.get("oracles", {}))
        med = f"{secs[len(secs) // 2]:.0f}" if secs else "-"
        lines.append(f"| {o} | {len(caught)} | {sum(bool(r['oracles'][o].get('timeout')) for r in caught)} | {med} |")
    builds = sorted(r["build_seconds"] for r in rows if "build_seconds" in r)
    if builds:
        lines += ["", f"Build per mutant: median {builds[len(builds) // 2]:.0f} s, "
                  f"range {builds[0]:.0f}-{builds[-1]:.0f} s."]
    lines += ["", "| mutant | layer | status | oracle | failed (first) | seconds |", "|---|---|---|---|---|---:|"]
    for r in rows:
        first = (r.get("failed") or [""])[0].replace("|", "\\|")[:80]
        lines.append(f"| {r['id']} | {r['layer']} | {r['status']} | {r.get('caught_by', '')} | {first} | "
                     f"{r.get('seconds', 0):.0f} |")
    survivors = [r for r in rows if r["status"] == "survived"]
    if survivors:
        lines += ["", "Survivors (each must get a reason: equivalent, or a named gap):", ""]
        for r in survivors:
            m = by_id.get(r["id"], {})
            lines.append(f"- **{r['id']}** ({m.get('file', '')}): {m.get('bug', '')}. Input that changes the output: "
                         f"{m.get('witness', '?')}.")
    broken = [r for r in rows if r["status"] == "build-broken"]
    if broken:
        lines += ["", "Build-broken (bad mutants, not counted):", ""]
        lines += [f"- {r['id']}: {r.get('build_error', '').strip().splitlines()[-1:]}" for r in broken]
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


# ---- one mutant -----------------------------------------------------------------------------------------------------

def apply_and_test(m, args, tree, build_dir, out, logs, exclude, env):
    path = os.path.join(tree, m["file"])
    with open(path, encoding="utf-8") as f:
        original = f.read()
    if original.count(m["find"]) != 1:
        return {"status": "stale", "failed": [f"find text occurs {original.count(m['find'])} times"]}
    result = {"oracles": {}}
    start = time.monotonic()
    try:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original.replace(m["find"], m["replace"], 1))
        # Oracle 1 needs only the CLI; the suite needs every target its tests run.
        build_secs = 0.0
        for stage, targets in (("cli", ["cloudbench"]), ("all", ["all"])):
            if stage == "all" and ("ctest" not in args.oracles or ("caught_by" in result and not args.all_oracles)):
                break
            rc, secs = build(build_dir, targets, args.jobs, os.path.join(logs, f"{m['id']}.build.log"), env,
                             args.build_timeout)
            build_secs += secs
            result["build_seconds"] = round(build_secs, 1)
            result[f"build_{stage}_seconds"] = round(secs, 1)
            if rc != 0:
                result.update(status="build-broken", build_error=tail(os.path.join(logs, f"{m['id']}.build.log"), 25))
                return result
            if stage == "cli":
                for oracle in ("conform",):
                    if oracle not in args.oracles:
                        continue
                    o = oracle_conform("ci-small", tree, build_dir, out, logs, m["id"],
                                       timeout_of(args, "conform", args.baseline), env)
                    result["oracles"][oracle] = o
                    if o["caught"] and "caught_by" not in result:
                        result.update(caught_by=oracle, failed=o["failed"])
        for oracle in ("ctest", "medium"):
            if oracle not in args.oracles or ("caught_by" in result and not args.all_oracles):
                continue
            if oracle == "ctest":
                o = oracle_ctest(args, build_dir, logs, m["id"], exclude, env)
            else:
                o = oracle_conform("thesis-medium", tree, build_dir, out, logs, m["id"],
                                   timeout_of(args, "medium", args.baseline), env)
            result["oracles"][oracle] = o
            if o["caught"] and "caught_by" not in result:
                result.update(caught_by=oracle, failed=o["failed"])
        result["status"] = "caught" if "caught_by" in result else "survived"
        return result
    finally:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original)
        result["seconds"] = round(time.monotonic() - start, 1)
        if git(tree, "diff", "--quiet", "--", m["file"]).returncode != 0:
            sys.exit(f"mutate: {path} differs from the commit after reverting {m['id']}; stopping")


# ---- main -----------------------------------------------------------------------------------------------------------

def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--mutants", default=os.path.join(SCRIPT_DIR, "mutants.json"), help="the mutant set")
    p.add_argument("--tree", help="the worktree to mutate (default: a worktree of HEAD under the temporary folder)")
    p.add_argument("--rev", help="commit for a new default worktree (default HEAD)")
    p.add_argument("--build-dir", help="build folder (default TREE/build/mutate)")
    p.add_argument("--out", help="results folder (default TREE/build/mutate-results)")
    p.add_argument("--list", action="store_true", help="list the mutants and exit")
    p.add_argument("--check", action="store_true",
                   help="no build: every find text occurs exactly once in --tree (default: this checkout)")
    p.add_argument("--list-ctest-oracle", action="store_true",
                   help="print the tests the CTest oracle runs in --build-dir, one a line, and exit (no build)")
    p.add_argument("--only", help="comma-separated mutant ids")
    p.add_argument("--layer", help="comma-separated layers")
    p.add_argument("--resume", action="store_true", help="keep results.json's finished mutants and skip them")
    p.add_argument("--all-oracles", action="store_true", help="run every oracle on every mutant")
    p.add_argument("--oracles", default=",".join(ORACLES), help="which oracles, in order (default all three)")
    p.add_argument("-j", "--jobs", type=int, default=2, help="build and ctest parallelism (default 2)")
    p.add_argument("--ctest-exclude-label", default="slow",
                   help="CTest leaves out the tests with a label matching this regex (ctest -LE; default slow: "
                        "the sanitized build, the fuzzer, exact mode's counts, the benchmarks; '' for none)")
    p.add_argument("--ctest-exclude", default="",
                   help="tests CTest also leaves out by name, a regex (Tools.MutantsApply is always left out)")
    p.add_argument("--conform-timeout", type=float, default=300, help="seconds for conform ci-small")
    p.add_argument("--ctest-timeout", type=float, default=2400, help="seconds for the whole CTest oracle")
    p.add_argument("--test-timeout", type=int, default=300, help="seconds for one CTest test")
    p.add_argument("--medium-timeout", type=float, default=1200, help="seconds for conform thesis-medium")
    p.add_argument("--build-timeout", type=float, default=3600, help="seconds for one build")
    p.add_argument("--skip-baseline", action="store_true", help="do not run the oracles on the unmutated tree")
    args = p.parse_args()

    mutants, problems = load_mutants(args.mutants)
    if args.list:
        for m in mutants:
            print(f"{m['id']:34} {m['layer']:8} {m['file']:34} {m['bug']}")
        print(f"{len(mutants)} mutants: " + ", ".join(f"{l} {sum(m['layer'] == l for m in mutants)}" for l in LAYERS))
        return 0
    if args.check:
        problems += check_applies(mutants, os.path.abspath(args.tree or CALLER_ROOT))
        for line in problems:
            print(f"mutate: {line}")
        if problems:
            print(f"mutate: {len(problems)} problem(s) in {len(mutants)} mutants")
            return 1
        counts = ", ".join(f"{l} {sum(m['layer'] == l for m in mutants)}" for l in LAYERS)
        print(f"mutate: all {len(mutants)} mutants apply ({counts})")
        return 0
    if args.list_ctest_oracle:
        if not args.build_dir:
            sys.exit("mutate: --list-ctest-oracle: needs --build-dir, a configured build folder")
        exclude = "|".join(x for x in [args.ctest_exclude, ALWAYS_EXCLUDED] if x)
        listed = subprocess.run(["ctest", "--test-dir", os.path.abspath(args.build_dir), "--show-only=json-v1"] +
                                ctest_selection(exclude, args.ctest_exclude_label), capture_output=True, text=True)
        if listed.returncode != 0:
            sys.exit(f"mutate: --list-ctest-oracle: ctest --show-only failed: {listed.stderr.strip()}")
        for test in json.loads(listed.stdout).get("tests", []):
            print(test["name"])
        return 0
    if problems:
        for line in problems:
            print(f"mutate: {line}")
        return 2
    args.oracles = [o for o in args.oracles.split(",") if o]
    if any(o not in ORACLES for o in args.oracles):
        sys.exit(f"mutate: --oracles: known oracles are {', '.join(ORACLES)}")
    selected = mutants
    if args.only:
        ids = args.only.split(",")
        unknown = [i for i in ids if i not in {m["id"] for m in mutants}]
        if unknown:
            sys.exit(f"mutate: --only: unknown mutant(s) {', '.join(unknown)}")
        selected = [m for m in mutants if m["id"] in ids]
    if args.layer:
        selected = [m for m in selected if m["layer"] in args.layer.split(",")]

    signal.signal(signal.SIGTERM, _on_sigterm)
    tree = prepare_tree(args)
    stale = check_applies(selected, tree)
    if stale:
        sys.exit("mutate: mutants that do not apply to " + tree + ":\n  " + "\n  ".join(stale))
    build_dir = os.path.abspath(args.build_dir or os.path.join(tree, "build", "mutate"))
    out = os.path.abspath(args.out or os.path.join(tree, "build", "mutate-results"))
    logs = os.path.join(out, "logs")
    os.makedirs(logs, exist_ok=True)
    env = build_env(tree)
    results_path = os.path.join(out, "results.json")
    commit = git(tree, "rev-parse", "HEAD").stdout.strip()
    results = {"format": "cloudbench-mutate/1", "commit": commit, "tree": tree, "build": build_dir,
               "started": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "oracles": args.oracles, "ctest_exclude": args.ctest_exclude,
               "ctest_exclude_label": args.ctest_exclude_label, "mutants": {}}
    if args.resume and os.path.exists(results_path):
        with open(results_path, encoding="utf-8") as f:
            old = json.load(f)
        if old.get("commit") != commit:
            log(f"note: results.json is from commit {old.get('commit', '?')[:10]}, the tree is at {commit[:10]}")
        results["mutants"] = {k: v for k, v in old.get("mutants", {}).items() if v.get("status") in DONE}
        results["baseline"] = old.get("baseline")

    try:
        configure(tree, build_dir, logs, env)
        log(f"tree {tree} at {commit[:10]}, build {build_dir}")
        # Always rebuild the unmutated tree first: the build folder still holds the objects of the last mutant of an
        # earlier run (its source was restored, so this rebuild is incremental), and the baseline must not see them.
        baseline = results.get("baseline") or {}
        log("baseline build (all targets)")
        rc, secs = build(build_dir, ["all"], args.jobs, os.path.join(logs, "baseline.build.log"), env,
                         args.build_timeout)
        if rc != 0:
            sys.exit(f"mutate: the unmutated tree does not build; see {logs}/baseline.build.log")
        if "build_seconds" not in baseline:
            baseline = {"build_seconds": round(secs, 1), "oracles": {}, "ctest_baseline_failures": []}
        results["baseline"] = baseline
        for oracle in ([] if args.skip_baseline else args.oracles):
            if oracle in baseline["oracles"]:
                continue
            limit = timeout_of(args, oracle)
            if oracle == "ctest":
                # The whole suite, not stopping at a failure, to learn which tests fail without any mutant.
                o = oracle_ctest(argparse.Namespace(**{**vars(args), "all_oracles": True}), build_dir, logs,
                                 "baseline", f"{args.ctest_exclude}|{ALWAYS_EXCLUDED}" if args.ctest_exclude
                                 else ALWAYS_EXCLUDED, env)
                baseline["ctest_baseline_failures"] = o.get("failed", []) if o["caught"] else []
            else:
                o = oracle_conform(SCENES[oracle], tree, build_dir, out, logs, "baseline", limit, env)
            if o.get("timeout") and oracle != "ctest" or (oracle == "ctest" and o["exit"] is None):
                sys.exit(f"mutate: {oracle} ran past its {limit:.0f} s on the unmutated tree: raise "
                         f"--{oracle}-timeout or leave it out with --oracles")
            if o["caught"] and oracle != "ctest":
                sys.exit(f"mutate: {oracle} fails on the unmutated tree: {o['failed'][:3]}; see {logs}/baseline.*.log")
            baseline["oracles"][oracle] = o
            write_json(results_path, results)
            log(f"baseline {oracle}: {o['seconds']} s" + (f", failing {o.get('failed')}" if o["caught"] else ""))
        write_json(results_path, results)
        args.baseline = results["baseline"]
        # Tests that fail on the unmutated tree cannot tell us anything: leave them out, by exact name.
        known = [re.escape(n) for n in results["baseline"].get("ctest_baseline_failures", []) if not n.startswith("ctest ")]
        exclude = "|".join(x for x in [args.ctest_exclude, ALWAYS_EXCLUDED] + [f"^{n}$" for n in known] if x)
        if known:
            log(f"left out of the ctest oracle (fail on the unmutated tree): {', '.join(known)}")

        todo = [m for m in selected if m["id"] not in results["mutants"]]
        log(f"{len(todo)} mutants to run ({len(selected) - len(todo)} already done)")
        for n, m in enumerate(todo, 1):
            log(f"[{n}/{len(todo)}] {m['id']} ({m['layer']}, {m['file']})")
            r = apply_and_test(m, args, tree, build_dir, out, logs, exclude, env)
            r.update(id=m["id"], layer=m["layer"], file=m["file"])
            results["mutants"][m["id"]] = r
            write_json(results_path, results)
            summarize(results, mutants, os.path.join(out, "summary.md"))
            detail = f" by {r['caught_by']}: {(r.get('failed') or [''])[0][:100]}" if r["status"] == "caught" else ""
            log(f"    {r['status']}{detail} ({r['seconds']} s, build {r.get('build_seconds', 0)} s)")
    except (KeyboardInterrupt, Interrupted) as e:
        log(f"interrupted ({e or 'Ctrl-C'}); the tree is reverted, finished mutants are in {results_path} (--resume)")
        return 130
    finally:
        dirty = git(tree, "status", "--porcelain", "--untracked-files=no").stdout.strip()
        if dirty:
            log(f"WARNING: {tree} is not clean:\n{dirty}")
    summarize(results, mutants, os.path.join(out, "summary.md"))
    log(f"results: {results_path} and {os.path.join(out, 'summary.md')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

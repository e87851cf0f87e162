#!/usr/bin/env python3
"""Runs the bad-input corpus (tests/bad_inputs/*.json) through a cloudbench CLI.

Each case file holds one input and its expected outcome:

  kind       group for the outcome table ("malformed JSON", "out of range", ...)
  about      one line: what the case is
  -- the input, one of --
  patch      {"dotted.path": value, ...} applied to the base scene (scenes/ci-small.json, cut to 3 steps);
             a value of null removes the field
  scene      a whole scene object
  text       the scene file's exact text (malformed JSON, control characters as \\u escapes)
  generate   {"what": "nested", "depth": N} | {"what": "huge_key", "bytes": N} | {"what": "fifo"} |
             {"what": "repeat", "before": TEXT, "unit": TEXT, "count": N, "after": TEXT}
  scene_path a path used as is (e.g. /dev/zero); no file is written
  args       a whole command line (after the program), for command-line cases; placeholders {scene} (the case's
             scene file, or scenes/ci-small.json when the case has none), {out} (a fresh output folder),
             {repeat:C:N} (the character C N times), {FIXTURE} (a pristine fixture, see below) and {NAME} for
             each of the case's `inputs`
  inputs     {NAME: spec, ...}: input files for the other commands, written into the case's folder as NAME; a
             spec is one of
               {"from": FIXTURE, "patch": {POINTER: value, ...}}  the fixture with JSON pointer (RFC 6901) edits
                   (null removes the field; "line": N picks the line of a JSON Lines fixture, default the last),
                   and optionally "replace": [OLD, NEW] on the text, "append": TEXT, and "truncate": N (keep
                   the first N bytes; negative: drop the last -N), in that order
               {"text": TEXT}, {"fifo": true}, {"folder": true}, {"link": TARGET} (a symbolic link; placeholders
               allowed), {"sparse_bytes": N} (a regular file of N zero bytes, sparse)
  FIXTURES   made once per run by the CLI under test, only those the selected cases use: results (run
             ci-small, 3 steps, cpu), history (perf record of ci-small), conform (conform ci-small, cpu: exit 4, nothing compared), shard1
             and shard2 (sweep ci-small --shard 1/2 and 2/2), suite (a perf suite), baseline (a conform
             baseline), count (a count output: `count` needs the exact build, so this one is written here in the
             count format)
  -- optional --
  file_name  the written scene's file name (default: the case's stem + ".json")
  commands   for scene cases, the commands run (default ["run", "dump"]), each as
             COMMAND {scene} --backend cpu --quiet --out {out}
  rlimit_as  RLIMIT_AS in bytes for the child (skipped with --skip-rlimit, e.g. under AddressSanitizer)
  timeout    seconds (default 60)
  -- expected --
  exit       the exit code
  message    a regex that stderr must contain ({scene} stands for the escaped scene path)

Every invocation must also: finish within its timeout, write no raw control byte to stderr (C0 other than
newline and tab, DEL, C1), write less than 64 KiB to stderr, and, when it exits 0, leave only finite numbers
in every .npy array and in results.json. A case passes when every command meets all of it.

Usage: check_bad_inputs.py --cli PATH [--filter RE] [--jobs N] [--skip-rlimit] [--write-scenes DIR]
Prints the outcome table and a summary; on failure, each failing invocation with its stderr.
Exit status 0 when every case passed.
"""
import argparse
import concurrent.futures
import copy
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASES = HERE / "bad_inputs"
SCENES = HERE.parent / "scenes"
MAX_STDERR = 64 * 1024
# C0 controls except tab and newline, DEL, and C1 controls in their UTF-8 form (and raw, for non-UTF-8 output).
RAW_CONTROL = re.compile(rb"[\x00-\x08\x0b-\x1f\x7f]|\xc2[\x80-\x9f]")


def base_scene():
    scene = json.loads((SCENES / "ci-small.json").read_text())
    scene["steps"] = 3
    scene["warmup_steps"] = 1
    return scene


def apply_patch(scene, patch):
    for path, value in patch.items():
        keys = path.split(".")
        node = scene
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        if value is None:
            node.pop(keys[-1], None)
        else:
            node[keys[-1]] = value
    return scene


FIXTURE_NAMES = ("results", "history", "conform", "shard1", "shard2", "suite", "baseline", "count")


class Fixtures:
    """Pristine inputs for the other commands, each made on first use by the CLI under test (thread-safe)."""

    def __init__(self, cli, folder):
        import threading
        self.cli, self.folder, self.made, self.lock = cli, Path(folder), {}, threading.Lock()

    def run(self, *args, codes=(0,)):
        proc = subprocess.run([self.cli, *args], stdin=subprocess.DEVNULL, capture_output=True, timeout=600)
        if proc.returncode not in codes:
            raise RuntimeError(f"fixture: cloudbench {' '.join(args)} exited {proc.returncode}: "
                               f"{proc.stderr[-2000:].decode('utf-8', 'replace')}")

    def path(self, name):
        with self.lock:
            if name not in self.made:
                self.made[name] = self.make(name)
            return self.made[name]

    def make(self, name):
        f = self.folder
        quick = ["--backend", "cpu", "--quiet", "--set", "warmup_steps=0"]
        if name == "results":
            self.run("run", "ci-small", "--steps", "3", *quick, "--out", str(f / "run"))
            return f / "run" / "results.json"
        if name == "history":
            suite = f / "history-suite.json"
            suite.write_text(json.dumps({"scenes": [{"scene": "ci-small", "set": ["steps=12", "warmup_steps=2"]}]}))
            for _ in range(2):
                self.run("perf", "record", "--suite", str(suite), "--history", str(f / "history.jsonl"),
                         "--backend", "cpu", "--quiet")
            return f / "history.jsonl"
        if name == "conform":
            # With the CPU alone there is nothing to compare (exit 4), but conform.json is written all the same:
            # the sanitized CLI is built without GPU backends.
            self.run("conform", "ci-small", "--steps", "2", *quick, "--out", str(f / "conform"), codes=(0, 4))
            return f / "conform" / "conform.json"
        if name in ("shard1", "shard2"):
            index = name[-1]
            out = f / name
            self.run("sweep", "ci-small", "--steps", "2", "--vary", "shade.resolution=1,2", "--repeat", "1",
                     "--shard", f"{index}/2", *quick, "--out", str(out))
            return out / "sweep.json"
        if name == "suite":
            path = f / "suite.json"
            path.write_text(json.dumps({"scenes": [{"scene": "ci-small", "set": ["steps=3"]}]}))
            return path
        if name == "baseline":
            path = f / "baseline.csv"
            path.write_text("stage,backend,status\nshade,vk,fail\n")
            return path
        if name == "count":
            path = f / "count.json"
            path.write_text(json.dumps({"format": "cloudbench-count/1", "scene": "ci-small", "steps": 3,
                                        "warmup_steps": 1, "counted_steps": [1, 2],
                                        "instructions": {"ci-small": {"cpu": {"region": 1000, "ca": 2000}}}}))
            return path
        raise ValueError(f"unknown fixture {name}")


def json_pointer_set(doc, pointer, value):
    """Sets (or, for None, removes) the field `pointer` (RFC 6901) of `doc`, creating objects on the way."""
    parts = [p.replace("~1", "/").replace("~0", "~") for p in pointer.split("/")[1:]]
    node = doc
    for part in parts[:-1]:
        node = node[int(part)] if isinstance(node, list) else node.setdefault(part, {})
    last = parts[-1]
    if isinstance(node, list):
        if value is None:
            del node[int(last)]
        else:
            node[int(last)] = value
    elif value is None:
        node.pop(last, None)
    else:
        node[last] = value


def expand(text, names):
    for key, value in names.items():
        text = text.replace("{" + key + "}", str(value))
    return text


def write_inputs(case, folder, fixtures):
    """Writes the case's `inputs` into `folder`; returns the placeholder values (inputs and fixtures used)."""
    names = {}
    used = set(re.findall(r"\{(\w+)\}", json.dumps(case.get("args", [])) + json.dumps(case.get("inputs", {}))))
    for fixture in FIXTURE_NAMES:
        if fixture in used or any(spec.get("from") == fixture for spec in case.get("inputs", {}).values()):
            names[fixture] = fixtures.path(fixture)
    for name, spec in case.get("inputs", {}).items():
        path = folder / name
        if "from" in spec:
            text = Path(names[spec["from"]]).read_text()
            if "patch" in spec:
                lines = text.splitlines(keepends=False)
                jsonl = spec["from"] == "history"
                index = (spec.get("line", len(lines)) - 1) if jsonl else None
                doc = json.loads(lines[index] if jsonl else text)
                for pointer, value in spec["patch"].items():
                    json_pointer_set(doc, pointer, value)
                if jsonl:
                    lines[index] = json.dumps(doc)
                    text = "\n".join(lines) + "\n"
                else:
                    text = json.dumps(doc, indent=1)
            if "replace" in spec:
                old, new = spec["replace"]
                if old not in text:
                    raise ValueError(f"{case['name']}: {old!r} is not in fixture {spec['from']}")
                text = text.replace(old, new)
            text += spec.get("append", "")
            data = text.encode("utf-8", "surrogateescape")
            if "truncate" in spec:
                data = data[:spec["truncate"]]
            path.write_bytes(data)
        elif "text" in spec:
            path.write_bytes(spec["text"].encode("utf-8", "surrogateescape"))
        elif spec.get("fifo"):
            os.mkfifo(path)
        elif spec.get("folder"):
            path.mkdir()
        elif "link" in spec:
            os.symlink(expand(spec["link"], names), path)
        elif "sparse_bytes" in spec:
            with open(path, "wb") as f:
                f.truncate(spec["sparse_bytes"])
        else:
            raise ValueError(f"{case['name']}: input {name} has no known spec")
        names[name] = path
    return names


def write_scene(case, folder):
    """The scene path for `case`, writing the file (or FIFO) under `folder`; None for command-line-only cases."""
    if "scene_path" in case:
        return case["scene_path"]
    path = folder / case.get("file_name", case["name"] + ".json")
    if "patch" in case:
        path.write_text(json.dumps(apply_patch(base_scene(), case["patch"]), indent=1))
    elif "scene" in case:
        path.write_text(json.dumps(case["scene"], indent=1))
    elif "text" in case:
        path.write_bytes(case["text"].encode("utf-8", "surrogateescape"))
    elif "generate" in case:
        what = case["generate"]["what"]
        if what == "nested":
            depth = case["generate"]["depth"]
            path.write_text('{"grid": ' + "[" * depth + "]" * depth + "}")
        elif what == "huge_key":
            key = "k" * case["generate"]["bytes"]
            path.write_text('{"grid": {"size": [8, 8, 8]}, "' + key + '": 1}')
        elif what == "repeat":
            g = case["generate"]
            path.write_text(g["before"] + g["unit"] * g["count"] + g["after"])
        elif what == "fifo":
            os.mkfifo(path)
        else:
            raise ValueError(f"{case['name']}: unknown generator {what}")
    else:
        return None
    return str(path)


def command_lines(case, scene):
    if "args" in case:
        return [case["args"]]
    return [[cmd, "{scene}", "--backend", "cpu", "--quiet", "--out", "{out}"] for cmd in case.get("commands",
                                                                                                  ["run", "dump"])]


def run_every_backend(cli, scene, steps, out, sets):
    """`cli run SCENE` on cpu, gl and vk for `steps` steps with no warm-up, each of `sets` a --set; exit 4 (no backend
    besides the CPU could start) is fine, any other failure ends the calling check."""
    command = [cli, "run", scene, "--backend", "cpu,gl,vk", "--steps", str(steps), "--set", "warmup_steps=0",
               "--quiet", "--out", str(out)]
    for s in sets:
        command += ["--set", s]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode not in (0, 4):
        sys.exit(f"{' '.join(command)} exited {done.returncode}: {done.stderr[-2000:]}")


def exr_floats(path):
    """Every pixel value of an OpenEXR file whose channels are all 32-bit floats, uncompressed or ZIP-compressed
    (what the harness writes), as one flat array; the layout does not matter for a finiteness check."""
    import numpy as np
    import zlib
    data = path.read_bytes()
    pos, attrs = 8, {}
    while data[pos] != 0:  # attributes: name\0 type\0 size value
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        size = int.from_bytes(data[type_end + 1:type_end + 5], "little")
        attrs[data[pos:name_end].decode()] = data[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
    pos += 1
    channels = attrs["channels"]
    types, c = [], 0
    while channels[c] != 0:
        c = channels.index(b"\0", c) + 1
        types.append(int.from_bytes(channels[c:c + 4], "little"))
        c += 16
    compression = attrs["compression"][0]
    if set(types) != {2} or compression not in (0, 2, 3):
        raise ValueError(f"{path}: channel types {types}, compression {compression} not read here")
    x0, y0, x1, y1 = map(int, np.frombuffer(attrs["dataWindow"], "<i4"))
    lines_per_chunk = {0: 1, 2: 1, 3: 16}[compression]
    chunks = -(-(y1 - y0 + 1) // lines_per_chunk)
    offsets = np.frombuffer(data, "<u8", count=chunks, offset=pos)
    values = []
    for offset in map(int, offsets):
        size = int.from_bytes(data[offset + 4:offset + 8], "little")
        block = data[offset + 8:offset + 8 + size]
        y = int.from_bytes(data[offset:offset + 4], "little", signed=True)
        expected = 4 * len(types) * (x1 - x0 + 1) * min(lines_per_chunk, y1 + 1 - y)
        if size < expected:  # zlib, then the byte predictor and the split into two halves undone
            t = np.frombuffer(zlib.decompress(block), np.uint8).astype(np.int64)
            t = (np.cumsum(np.concatenate(([t[0]], t[1:] - 128))) & 0xFF).astype(np.uint8)
            half = (len(t) + 1) // 2
            raw = np.empty_like(t)
            raw[0::2], raw[1::2] = t[:half], t[half:]
            block = raw.tobytes()
        values.append(np.frombuffer(block, "<f4"))
    return np.concatenate(values)


def non_finite_in_outputs(out):
    """Names of output files under `out` that hold NaN or Inf (numpy arrays, EXR frames and JSON files)."""
    import numpy as np
    bad = []
    for npy in sorted(Path(out).rglob("*.npy")):
        a = np.load(npy)
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            bad.append(f"{npy.relative_to(out)} ({int((~np.isfinite(a)).sum())} non-finite)")
    for exr in sorted(Path(out).rglob("*.exr")):
        a = exr_floats(exr)
        if not np.isfinite(a).all():
            bad.append(f"{exr.relative_to(out)} ({int((~np.isfinite(a)).sum())} non-finite)")
    for js in sorted(Path(out).rglob("*.json")):
        found = []

        def constant(token):
            found.append(token)
            return float(token.replace("Infinity", "inf"))

        try:
            json.loads(js.read_text(), parse_constant=constant)
        except ValueError as e:
            bad.append(f"{js.relative_to(out)} (not JSON: {e})")
        if found:
            bad.append(f"{js.relative_to(out)} ({', '.join(sorted(set(found)))})")
    return bad


def run_case(cli, case, skip_rlimit, fixtures):
    """(outcome, problems, invocations) for one case; outcome is 'refused', 'finite' or 'failed'."""
    if skip_rlimit and "rlimit_as" in case:
        return "skipped", [], 0
    problems = []
    exits = []
    with tempfile.TemporaryDirectory(prefix="badinput-") as tmp:
        tmp = Path(tmp)
        scene = write_scene(case, tmp) or str(SCENES / "ci-small.json")
        try:
            names = write_inputs(case, tmp, fixtures)
        except (RuntimeError, ValueError, OSError) as e:
            return "failed", [f"cannot make the case's inputs: {e}"], 0
        lines = command_lines(case, scene)
        for n, line in enumerate(lines):
            out = tmp / f"out{n}"
            argv = [cli] + [expand(re.sub(r"\{repeat:(.):(\d+)\}", lambda m: m[1] * int(m[2]),
                                          a.replace("{scene}", scene).replace("{out}", str(out))), names)
                            for a in line]
            limit = case.get("rlimit_as")

            def preexec():
                if limit:
                    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

            start = time.monotonic()
            timeout = case.get("timeout", 60)
            try:
                proc = subprocess.run(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                      timeout=timeout, preexec_fn=preexec)
            except subprocess.TimeoutExpired:
                problems.append(f"{line[0]}: no exit within {timeout} s")
                continue
            seconds = time.monotonic() - start
            err = proc.stderr
            shown = " ".join(argv[1:])[:200]
            text = err[:4000].decode("utf-8", "backslashreplace")
            exits.append(proc.returncode)

            def fail(what):
                problems.append(f"{shown}\n      {what}\n      exit {proc.returncode}, {seconds:.1f} s, stderr: "
                                f"{text!r}")

            if proc.returncode != case["exit"]:
                fail(f"expected exit {case['exit']}")
            if len(err) >= MAX_STDERR:
                fail(f"stderr has {len(err)} bytes (limit {MAX_STDERR})")
            if m := RAW_CONTROL.search(err):
                fail(f"raw control byte {m.group(0)!r} in stderr")
            if "message" in case:
                pattern = case["message"].replace("{scene}", re.escape(scene))
                for key, value in names.items():
                    pattern = pattern.replace("{" + key + "}", re.escape(str(value)))
                if not re.search(pattern, err.decode("utf-8", "replace"), re.MULTILINE):
                    fail(f"stderr does not match {pattern!r}")
            if proc.returncode == 0:
                if bad := non_finite_in_outputs(out):
                    fail("non-finite values: " + "; ".join(bad))
            shutil.rmtree(out, ignore_errors=True)
    if problems:
        return "failed", problems, len(lines)
    return ("finite" if exits and all(e == 0 for e in exits) else "refused"), [], len(lines)


def load_cases(filter_re):
    cases = []
    for path in sorted(CASES.glob("*.json")):
        case = json.loads(path.read_text())
        case["name"] = path.stem
        for key in ("kind", "about", "exit"):
            if key not in case:
                raise ValueError(f"{path}: missing '{key}'")
        if case["exit"] != 0 and "message" not in case:
            raise ValueError(f"{path}: a refusal needs a 'message'")
        if filter_re and not re.search(filter_re, case["name"]) and not re.search(filter_re, case["kind"]):
            continue
        cases.append(case)
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cli", required=True, help="the cloudbench executable")
    parser.add_argument("--filter", help="only cases whose name or kind matches this regex")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--skip-rlimit", action="store_true",
                        help="skip cases that set RLIMIT_AS (AddressSanitizer reserves more address space)")
    parser.add_argument("--write-scenes", metavar="DIR",
                        help="only write each case's scene file into DIR (e.g. to seed a fuzzer), run nothing")
    args = parser.parse_args()
    cases = load_cases(args.filter)
    if not cases:
        print("no case matches", file=sys.stderr)
        return 1

    if args.write_scenes:
        folder = Path(args.write_scenes)
        folder.mkdir(parents=True, exist_ok=True)
        written = 0
        for case in cases:
            if any(k in case for k in ("patch", "scene", "text")) or case.get("generate", {}).get("what") == "repeat":
                write_scene(dict(case, file_name=case["name"] + ".json"), folder)
                written += 1
        print(f"{written} scene files written to {folder}")
        return 0

    cli = str(Path(args.cli).resolve())
    results = {}
    with tempfile.TemporaryDirectory(prefix="badinput-fixtures-") as fixture_dir:
        fixtures = Fixtures(cli, fixture_dir)
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            futures = {pool.submit(run_case, cli, case, args.skip_rlimit, fixtures): case["name"] for case in cases}
            for future in concurrent.futures.as_completed(futures):
                results[futures[future]] = future.result()

    by_kind = {}
    invocations = 0
    for case in cases:
        outcome, _, count = results[case["name"]]
        invocations += count
        row = by_kind.setdefault(case["kind"], {"refused": 0, "finite": 0, "failed": 0, "skipped": 0})
        row[outcome] += 1
    width = max(len(k) for k in by_kind)
    print(f"{'kind':<{width}}  refused  finite  failed  skipped")
    for kind, row in sorted(by_kind.items()):
        print(f"{kind:<{width}}  {row['refused']:7}  {row['finite']:6}  {row['failed']:6}  {row['skipped']:7}")
    totals = {k: sum(r[k] for r in by_kind.values()) for k in ("refused", "finite", "failed", "skipped")}
    print(f"{len(cases)} cases, {invocations} invocations: {totals['refused']} refused clearly, "
          f"{totals['finite']} computed finite, {totals['failed']} failed, {totals['skipped']} skipped")
    for case in cases:
        outcome, problems, _ = results[case["name"]]
        if problems:
            print(f"\nFAILED {case['name']} ({case['kind']}): {case['about']}")
            for p in problems:
                print("  - " + p)
    return 1 if totals["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())

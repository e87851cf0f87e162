#!/usr/bin/env python3
"""Runs every command that writes JSON (run, conform, accuracy, sweep) on a
short ci-small and checks that each output carries a complete "provenance"
block (docs/results.md): every key present, every value non-empty.
Usage: check_provenance.py CLOUDBENCH OUT_DIR"""
import json
import os
import subprocess
import sys

COMMANDS = {
    "results.json": ["run", "ci-small", "--steps", "12", "--backend", "cpu"],
    "conform.json": ["conform", "ci-small", "--steps", "2", "--backend", "cpu"],
    "accuracy.json": ["accuracy", "ci-small", "--steps", "2", "--repeat", "1", "--backend", "cpu"],
    "sweep.json": ["sweep", "ci-small", "--steps", "2", "--repeat", "1", "--backend", "cpu",
                   "--vary", "shade.resolution=1,2"],
}
KEYS = {
    "git": ["commit", "dirty"],
    "build": ["type", "flags", "compiler"],
    "machine": ["cpu", "threads", "os"],
    "scene": ["path", "name", "overrides", "resolved"],
}


def problems(doc, name):
    p = doc.get("provenance")
    if not isinstance(p, dict):
        return [f"{name}: no provenance object"]
    out = []
    for key in ["git", "build", "machine", "date", "backends", "scene", "command_line"]:
        if key not in p or p[key] in ("", None, [], {}):
            out.append(f"{name}: provenance.{key}: missing or empty")
    for section, keys in KEYS.items():
        for key in keys:
            value = p.get(section, {}).get(key)
            if value is None or value == "":
                out.append(f"{name}: provenance.{section}.{key}: missing or empty")
    for n, backend in enumerate(p.get("backends", [])):
        for key in ["name", "status", "device"]:
            if not backend.get(key):
                out.append(f"{name}: provenance.backends[{n}].{key}: missing or empty")
    if p.get("command_line", [None])[1:2] != [COMMANDS[name][0]]:
        out.append(f"{name}: provenance.command_line: does not name the command: {p.get('command_line')}")
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: check_provenance.py CLOUDBENCH OUT_DIR")
    cli, out = sys.argv[1], sys.argv[2]
    failures = []
    for name, args in COMMANDS.items():
        folder = os.path.join(out, name.split(".")[0])
        run = subprocess.run([cli, *args, "--quiet", "--out", folder], capture_output=True, text=True)
        # conform with the CPU alone compares nothing and exits 4; it still writes its JSON.
        if run.returncode not in (0, 4):
            failures.append(f"{' '.join(args)}: exit {run.returncode}\n{run.stderr}")
            continue
        with open(os.path.join(folder, name)) as f:
            failures += problems(json.load(f), name)
    for f in failures:
        print(f)
    if failures:
        sys.exit(1)
    print(f"provenance complete in {', '.join(COMMANDS)}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Checks the source tree's layers (docs/architecture.md, "Layers").

A module is a header and its .cpp (core/scene/Scene.h with core/scene/Scene.cpp);
a wing is the folder it sits in (core/scene), except in a stage's home,
core/stages/<stage>/, which is two wings: its types header (<Stage>Types.h, the
settings and parameters the scene and the backend interface hold) is
"core/stages/*/types", the rest of it (reader, parameters, descriptor, call)
"core/stages/*". Three rules, each a failure:

  1. no include cycle between modules;
  2. a wing includes only itself and the wings WINGS lists for it (the table
     below is the layering; a new wing must be added to it);
  3. no source file over MAX_LINES lines.

Usage: check_layers.py [ROOT]   (ROOT: the repository; default: this script's parent's parent)
Exit 0 when the tree keeps every rule, 1 with one line per break otherwise.
"""
import collections
import os
import re
import sys

MAX_LINES = 600

# Each wing and the wings it may include besides itself. Transitive: a wing may
# include whatever the wings it names may include.
WINGS = {
    "core/base": [],
    "core/math": ["core/base"],
    "core/stages/*/types": ["core/math"],
    "core/scene": ["core/stages/*/types"],
    "core/pipeline": ["core/scene"],
    "core/stages/*": ["core/pipeline"],
    "core/plan": ["core/stages/*"],
    "reference": ["core/pipeline"],
    "registry": ["impl_cpu", "impl_gl", "impl_vk"],
    "impl_cpu": ["core/pipeline"],
    "impl_gl": ["core/pipeline"],
    "impl_vk": ["core/pipeline"],
    "harness/platform": ["registry", "core/plan"],
    "harness/run": ["harness/platform"],
    "harness/report": ["harness/run", "harness/report/images"],
    "harness/report/html": ["harness/report", "harness/perf"],
    "harness/report/images": ["core/base"],
    "harness/conform": ["harness/report"],
    "harness/accuracy": ["harness/report", "reference"],
    "harness/perf": ["harness/report"],
    "harness/commands": ["harness/conform", "harness/accuracy", "harness/perf", "harness/report/html",
                         "harness/report/images"],
    "harness": ["harness/commands"],
}
SOURCES = ("core", "harness", "impl_cpu", "impl_gl", "impl_vk", "reference", "registry")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
STAGE_HOME = re.compile(r"^core/stages/[^/]+/([^/]+)$")


def wing(path):
    home = STAGE_HOME.match(path)
    if home:
        return "core/stages/*/types" if home.group(1).endswith("Types.h") else "core/stages/*"
    return os.path.dirname(path)


def allowed(wing):
    seen, todo = {wing}, [wing]
    while todo:
        for below in WINGS.get(todo.pop(), []):
            if below not in seen:
                seen.add(below)
                todo.append(below)
    return seen


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    files = {}
    for top in SOURCES:
        for folder, _, names in os.walk(os.path.join(root, top)):
            for name in names:
                if name.endswith((".h", ".cpp")):
                    path = os.path.relpath(os.path.join(folder, name), root)
                    with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
                        files[path] = f.read()
    failures = []
    module = lambda path: os.path.splitext(path)[0]
    graph = collections.defaultdict(set)
    for path, text in sorted(files.items()):
        lines = text.count("\n")
        if lines > MAX_LINES:
            failures.append(f"{path}: {lines} lines, more than {MAX_LINES}")
        if wing(path) not in WINGS:
            failures.append(f"{path}: the wing {wing(path)} is not in tools/check_layers.py's WINGS")
            continue
        for included in INCLUDE.findall(text):
            if included not in files:
                continue  # a system, generated or shader header
            if module(included) != module(path):
                graph[module(path)].add(module(included))
            if wing(included) not in allowed(wing(path)):
                failures.append(f"{path}: includes {included}, but {wing(path)} may not include {wing(included)}")

    # Tarjan's strongly connected components; each of more than one module is a cycle.
    index, low, stack, on_stack, counter = {}, {}, [], set(), [0]
    sys.setrecursionlimit(100000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                failures.append("include cycle: " + " -> ".join(sorted(component)))

    for v in sorted({module(p) for p in files}):
        if v not in index:
            visit(v)
    for line in failures:
        print(line)
    print(f"check_layers: {len(files)} files, {len({module(p) for p in files})} modules, {len(failures)} breaks")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

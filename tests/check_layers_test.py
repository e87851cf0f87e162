#!/usr/bin/env python3
"""tools/check_layers.py finds each kind of break it promises on a tiny tree, and passes a clean one."""
import os
import subprocess
import sys
import tempfile

CHECKER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools", "check_layers.py")


def run(files):
    with tempfile.TemporaryDirectory() as root:
        for path, text in files.items():
            os.makedirs(os.path.join(root, os.path.dirname(path)), exist_ok=True)
            with open(os.path.join(root, path), "w") as f:
                f.write(text)
        done = subprocess.run([sys.executable, CHECKER, root], capture_output=True, text=True)
        return done.returncode, done.stdout


def expect(name, files, code, *lines):
    got, out = run(files)
    missing = [line for line in lines if line not in out]
    if got != code or missing:
        print(f"FAIL {name}: exit {got} (expected {code}), missing {missing}\n{out}")
        return False
    print(f"ok {name}")
    return True


clean = {
    "core/base/Error.h": "#pragma once\n",
    "core/math/Grid.h": '#include "core/base/Error.h"\n',
    "core/math/Grid.cpp": '#include "core/math/Grid.h"\n#include <vector>\n#include "shading.glsl"\n',
}
results = [
    expect("clean tree", clean, 0, "0 breaks"),
    expect("a wing includes one above it",
           {**clean, "core/base/Error.h": '#include "core/math/Grid.h"\n'}, 1,
           "core/base/Error.h: includes core/math/Grid.h, but core/base may not include core/math"),
    expect("a cycle within a wing",
           {**clean, "core/math/Camera.h": '#include "core/math/Grid.h"\n',
            "core/math/Grid.cpp": '#include "core/math/Grid.h"\n#include "core/math/Camera.h"\n',
            "core/math/Grid.h": '#include "core/math/Camera.h"\n'}, 1,
           "include cycle: core/math/Camera -> core/math/Grid"),
    expect("a header and its .cpp are one module", {**clean, "core/math/Grid.h": "#pragma once\n"}, 0, "0 breaks"),
    expect("a file over 600 lines", {**clean, "core/math/Long.cpp": "//\n" * 601}, 1,
           "core/math/Long.cpp: 601 lines, more than 600"),
    expect("a stage's types header stands below the scene, its module above the pipeline",
           {**clean, "core/stages/shade/ShadeTypes.h": '#include "core/math/Grid.h"\n',
            "core/scene/Scene.h": '#include "core/stages/shade/ShadeTypes.h"\n',
            "core/pipeline/Backend.h": '#include "core/scene/Scene.h"\n',
            "core/stages/shade/Shade.h": '#include "core/pipeline/Backend.h"\n'}, 0, "0 breaks"),
    expect("a stage's types header includes its module",
           {**clean, "core/stages/shade/ShadeTypes.h": '#include "core/stages/shade/Shade.h"\n',
            "core/stages/shade/Shade.h": "#pragma once\n"}, 1,
           "core/stages/shade/ShadeTypes.h: includes core/stages/shade/Shade.h, "
           "but core/stages/*/types may not include core/stages/*"),
    expect("a wing not in the table", {**clean, "core/extra/New.h": "#pragma once\n"}, 1,
           "core/extra/New.h: the wing core/extra is not in tools/check_layers.py's WINGS"),
]
sys.exit(0 if all(results) else 1)

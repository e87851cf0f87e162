#!/usr/bin/python3
"""Every file cloudbench opens goes through its path policy (core/base/PathPolicy.h).

usage: check_path_calls.py SOURCE_ROOT

Scans the C++ sources of the tool (core, harness, impl_*, reference, registry,
tools) for the calls that open a file by other means: open/openat/openat2,
fopen/freopen, creat, the iostream file classes, posix_spawn's addopen, and
OpenImageIO opening by name. Each use must be in the policy's modules (PathPolicy.cpp, SystemFile.cpp) or on the
allowlist below, which says why it is not a reader or writer of the user's
paths. A new reader or writer that opens a file itself fails this test with
"FAIL: FILE:LINE: ...". Exits 1 on any failure.
"""
import os
import re
import sys

# A raw call that opens a file; comments are stripped before matching.
FORBIDDEN = [
    (re.compile(r"(?<![\w.>])(::)?open(at2?)?\s*\("), "open/openat"),
    (re.compile(r"SYS_openat2"), "openat2"),
    (re.compile(r"\b(fopen|freopen|fdopen|popen|creat|mkfifo|mknod)\s*\("), "stdio or creat"),
    (re.compile(r"\b(std::)?(i|o)?fstream\b|<fstream>"), "iostream file"),
    (re.compile(r"posix_spawn_file_actions_addopen"), "posix_spawn addopen"),
    (re.compile(r"ImageInput::(open|create)\s*\(|ImageBuf\s+\w+\s*\(\s*\w*[pP]ath|->open\s*\(|\.write\s*\(\s*path"),
     "OpenImageIO by name"),
]

# (file, what the line must contain, why it may open a file itself)
ALLOWED = [
    ("harness/report/images/OiioImageModule.cpp", "buffer.write(path",
     "writes the temporary file Session::WriteAtomically created, by its /proc/self/fd name"),
    ("harness/report/images/OiioImageModule.cpp", "ImageInput::create(format)",
     "reads back that same temporary file"),
    ("harness/report/images/OiioImageModule.cpp", "in->open(path",
     "reads back that same temporary file"),
    ("harness/report/images/OiioImageModule.cpp", "in->open(memory",
     "decodes bytes already read by the policy, from an anonymous memory file"),
    ("harness/report/images/OiioImageModule.cpp", "out->open(\"image.png\"",
     "encodes into memory"),
    ("harness/commands/SweepOutput.cpp", "\"/dev/null\"",
     "the plotting child's standard input"),
    ("tools/MieTableGen.cpp", "std::fopen(argv[1], \"w\")",
     "a build step writing a generated source file into the build tree"),
]

SOURCE_DIRS = ["core", "harness", "impl_cpu", "impl_gl", "impl_vk", "reference", "registry", "tools"]
# The policy's own modules: the user's paths, and the kernel's files under /proc and /sys.
POLICY = ("core/base/PathPolicy.cpp", "core/base/SystemFile.cpp")


def strip_comments(line, in_block):
    out = ""
    i = 0
    while i < len(line):
        if in_block:
            end = line.find("*/", i)
            if end < 0:
                return out, True
            i = end + 2
            in_block = False
        elif line.startswith("//", i):
            break
        elif line.startswith("/*", i):
            in_block = True
            i += 2
        elif line[i] == '"':
            j = i + 1
            while j < len(line) and line[j] != '"':
                j += 2 if line[j] == "\\" else 1
            out += line[i:j + 1]
            i = j + 1
        else:
            out += line[i]
            i += 1
    return out, in_block


def scan(root):
    failures = []
    used = set()
    for top in SOURCE_DIRS:
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                if not name.endswith((".cpp", ".h", ".cc", ".hpp")):
                    continue
                path = os.path.join(folder, name)
                relative = os.path.relpath(path, root)
                if relative in POLICY:
                    continue
                in_block = False
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, raw in enumerate(f, 1):
                        code, in_block = strip_comments(raw.rstrip("\n"), in_block)
                        bare = re.sub(r'"(\\.|[^"\\])*"', '""', code)  # string literals blanked
                        for pattern, what in FORBIDDEN:
                            if not pattern.search(bare):
                                continue
                            allowed = [a for a in ALLOWED if a[0] == relative and a[1] in code]
                            if allowed:
                                used.update(allowed)
                                continue
                            failures.append("%s:%d: %s outside the path policy (core/base/PathPolicy.h): %s" %
                                            (relative, number, what, code.strip()))
    for entry in ALLOWED:
        if entry not in used:
            failures.append("%s: allowlisted '%s' is no longer there; remove it from the allowlist" %
                            (entry[0], entry[1]))
    return failures


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    failures = scan(sys.argv[1])
    for f in failures:
        print("FAIL: " + f)
    if failures:
        sys.exit(1)
    print("every file is opened through the path policy (%d allowlisted uses)" % len(ALLOWED))


if __name__ == "__main__":
    main()

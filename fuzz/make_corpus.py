#!/usr/bin/python3
"""Writes the scene fuzzer's seed corpus (docs/fuzzing.md) into OUT_DIR, from the project's own inputs:

- every scenes/*.json, alone and with a few `--set` overrides;
- every JSON object written as a raw string literal R"(...)" in tests/*.cpp (the parser and validator cases);
- every `--set` override the tests use ({"path", "value"} pairs in tests/*.cpp, --set PATH=VALUE in tests/*.cmake
  and tests/CMakeLists.txt), applied to the first shipped scene;
- every input that once broke the fuzzer, kept in fuzz/regressions/ (small text files, one per bug);
- every file under tests/bad_inputs/ (the bad-input set), when that folder exists.

An input is the scene text, then, when there are overrides, one NUL byte and PATH=VALUE lines (fuzz/SceneFuzzer.cpp).
Files are named by the SHA-1 of their content, as libFuzzer names its own, so a seed is written once.

usage: make_corpus.py SOURCE_ROOT OUT_DIR
"""
import hashlib
import pathlib
import re
import sys

RAW_STRING = re.compile(r'R"([A-Za-z_]{0,8})\((.*?)\)\1"', re.S)
OVERRIDE_PAIR = re.compile(r'\{"([A-Za-z_][A-Za-z0-9_.\[\]]*)",\s*(?:"((?:[^"\\]|\\.)*)"|R"\((.*?)\)")\}', re.S)
CLI_SET = re.compile(r'--set[; ]+([A-Za-z_][A-Za-z0-9_.\[\]]*=[^; )"]*)')


def with_overrides(scene: bytes, overrides: list[str]) -> bytes:
    return scene + b"\0" + "\n".join(overrides).encode() if overrides else scene


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    root, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    seeds: set[bytes] = set()

    scenes = [p.read_bytes() for p in sorted((root / "scenes").glob("*.json"))]
    if not scenes:
        print(f"make_corpus: no scenes in {root / 'scenes'}", file=sys.stderr)
        return 1
    small = scenes[0]
    for scene in scenes:
        seeds.add(scene)
        seeds.add(with_overrides(scene, ["steps=3", "warmup_steps=0"]))
        seeds.add(with_overrides(scene, ["grid.size=[8,4,8]", "steps=2", "warmup_steps=0", "density.tile=3"]))

    overrides: set[str] = set()
    for source in sorted((root / "tests").glob("*.cpp")):
        text = source.read_text(errors="replace")
        for match in RAW_STRING.finditer(text):
            body = match.group(2)
            if body.lstrip().startswith("{"):
                seeds.add(body.encode())
        for match in OVERRIDE_PAIR.finditer(text):
            value = match.group(2) if match.group(2) is not None else match.group(3)
            if "\n" not in value:
                overrides.add(f"{match.group(1)}={value}")
    for cmake in [root / "tests" / "CMakeLists.txt", *sorted((root / "tests").glob("*.cmake"))]:
        if cmake.exists():
            overrides.update(CLI_SET.findall(cmake.read_text(errors="replace")))
    for item in sorted(overrides):
        seeds.add(with_overrides(small, [item]))

    for folder in [root / "fuzz" / "regressions", root / "tests" / "bad_inputs"]:
        if not folder.is_dir():
            continue
        for path in sorted(folder.rglob("*")):
            if path.is_file() and path.stat().st_size <= (1 << 20):
                seeds.add(path.read_bytes())

    for seed in seeds:
        (out / hashlib.sha1(seed).hexdigest()).write_bytes(seed)
    print(f"make_corpus: {len(seeds)} seeds ({len(scenes)} scenes, {len(overrides)} overrides) in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

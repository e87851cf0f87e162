#!/usr/bin/python3
"""Every shipped scene (scenes/*.json) has a row in the README's scene table and
in docs/scenes.md's "Shipped scenes" table, and every row there names a shipped
scene, so the tables a newcomer reads first list what `cloudbench run NAME` takes.

usage: check_docs_scenes.py SOURCE_ROOT
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
shipped = {p.stem for p in (root / "scenes").glob("*.json")}


def rows(text, heading=None):
    """The names in the first column of a Markdown table's rows (`name` or `a`, `b`), after `heading` if given."""
    if heading is not None:
        text = text[text.index(heading):]
        following = re.search(r"\n## ", text[len(heading):])
        text = text[: len(heading) + following.start()] if following else text
    names = set()
    for line in text.splitlines():
        cell = re.match(r"\| ((?:`[^`]+`(?:, )?)+) \|", line)
        if cell:
            names.update(re.findall(r"`([^`]+)`", cell.group(1)))
    return names


failures = []
for doc, heading in (("README.md", "| scene | grid"), ("docs/scenes.md", "## Shipped scenes")):
    listed = rows((root / doc).read_text(), heading)
    for name in sorted(shipped - listed):
        failures.append(f"{doc}: the scene table has no row for scenes/{name}.json")
    for name in sorted(listed - shipped):
        failures.append(f"{doc}: the scene table lists `{name}`, which is not in scenes/")
if failures:
    print("\n".join(failures))
    sys.exit(1)
print(f"docs list every scene: {len(shipped)} scenes")

#!/usr/bin/python3
"""`cloudbench report` of the regression gate's verdict, and `perf compare --interleave --plant`.

A short real interleave of ci-small (2 rounds, 4 steps, the CPU) run with `--plant region:3 --keep DIR
--json FILE` must record the plant in DIR/interleave.json, in FILE and in DIR/compare.json, which holds the
same verdict as FILE; `perf compare DIR` must show it again. Two rounds cannot judge a stage (every time row
is ?), so the page's flagged stage is planted here in a copy of FILE: the `region` time row made `+` with a
ratio of 2.5, the verdict a regression with exit code 6. The page of that copy must show the row with its
mark, ratio and Holm p, and the verdict "exit code 6"; the page of DIR must show DIR/compare.json's verdict,
its unjudged rows and the plant. Refused: a copy whose row has the mark "*" (exit 3, naming the file and
/comparisons/N/mark), a kept folder without compare.json (exit 3, naming DIR/compare.json), and each bad
--plant value (exit 2, naming --plant).

usage: check_report_compare.py CLOUDBENCH WORKDIR
"""
import html.parser
import json
import os
import shutil
import subprocess
import sys

CLI, WORK = os.path.abspath(sys.argv[1]), sys.argv[2]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def cli(*args):
    return subprocess.run([CLI, *args], capture_output=True, text=True, timeout=300)


class Page(html.parser.HTMLParser):
    """The page's table rows (each a list of cell texts) and paragraphs."""

    def __init__(self, text):
        super().__init__()
        self.rows, self.paragraphs, self.terms = [], [], []
        self._row, self._cell, self._p = None, None, None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self._row = []
        elif tag in ("td", "th"):
            self._cell = ""
        elif tag in ("p", "dd"):
            self._p = ""

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._row is not None:
            self._row.append(self._cell)
            self._cell = None
        elif tag == "tr":
            self.rows.append(self._row)
            self._row = None
        elif tag in ("p", "dd"):
            self.paragraphs.append(self._p)
            self._p = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data
        if self._p is not None:
            self._p += data


def page_of(*inputs):
    out = os.path.join(WORK, "report.html")
    p = cli("report", *inputs, "-o", out)
    if p.returncode != 0:
        fail(f"report {inputs}: exit {p.returncode}\n{p.stderr}")
    return Page(open(out).read())


# --plant's bad values: exit 2, naming the option and the reason.
for value, message in (("region", "--plant: needs STAGE:FACTOR (e.g. region:2), got 'region'"),
                       ("regoin:2", "--plant: unknown stage 'regoin'"),
                       ("region:0.5", "--plant: the factor of 'region:0.5' must be a number in [1, 1000], got '0.5'"),
                       ("region:1001", "must be a number in [1, 1000], got '1001'"),
                       ("region:2x", "must be a number in [1, 1000], got '2x'"),
                       ("region:", "must be a number in [1, 1000], got ''")):
    p = cli("perf", "compare", "--interleave", CLI, CLI, "ci-small", "--plant", value)
    if p.returncode != 2 or message not in p.stderr:
        fail(f"--plant {value}: exit {p.returncode} (expected 2 with '{message}')\n{p.stderr[:400]}")
p = cli("perf", "compare", "a.json", "b.json", "--plant", "region:2")
if p.returncode != 2 or "--plant is for perf compare --interleave" not in p.stderr:
    fail(f"--plant without --interleave: exit {p.returncode}\n{p.stderr[:400]}")

# A short real interleave with the plant.
kept, live_json = os.path.join(WORK, "kept"), os.path.join(WORK, "live.json")
p = cli("perf", "compare", "--interleave", CLI, CLI, "ci-small", "--rounds", "2", "--steps", "4", "--set",
        "warmup_steps=1", "--backend", "cpu", "--quiet", "--plant", "region:3", "--keep", kept, "--json", live_json)
if p.returncode not in (0, 6):
    fail(f"the planted interleave: exit {p.returncode}\n{p.stdout}\n{p.stderr}")
plant = {"stage": "region", "factor": 3}
manifest = json.load(open(os.path.join(kept, "interleave.json")))
live = json.load(open(live_json))
kept_verdict = json.load(open(os.path.join(kept, "compare.json")))
if manifest.get("plant") != plant or live.get("plant") != plant:
    fail(f"--plant region:3: interleave.json's plant {manifest.get('plant')}, the JSON's {live.get('plant')}")
if kept_verdict != live:
    fail("DIR/compare.json must hold the verdict --json wrote")
if "planted" not in p.stdout or "region x3 in HEAD" not in p.stdout:
    fail(f"the live table must name the plant:\n{p.stdout}")
again = cli("perf", "compare", kept)
if again.returncode != p.returncode or "region x3 in HEAD" not in again.stdout:
    fail(f"perf compare DIR: exit {again.returncode} (live {p.returncode}), must name the plant:\n{again.stdout}")

# The page of the kept folder: DIR/compare.json's verdict, its unjudged rows and the plant.
page = page_of(kept)
code = live["exit_code"]
if not any(f"(exit code {code})" in t for t in page.paragraphs):
    fail(f"the kept folder's page must give the verdict's exit code {code}")
unjudged = [c for c in live["comparisons"] if c["mark"] == "?"]
if unjudged and not any(t.startswith("Not judged (?): ") and "ci-small/cpu/region" in t for t in page.paragraphs):
    fail("the kept folder's page must name the unjudged rows")
if not any("region x3 in HEAD" in t for t in page.paragraphs):
    fail("the kept folder's page must name the plant")
kept_file = os.path.join(kept, "compare.json")
verdict_rows = [r for r in page.rows if r and r[0] == kept_file]
if [r[:4] for r in verdict_rows] != [[kept_file, "perf compare", str(code), "pass" if code == 0 else "fail"]]:
    fail(f"the verdict table's row for {kept}: {verdict_rows}")

# A flagged stage, planted in a copy: region's time row a regression at 2.5x, the exit code 6.
flagged = json.loads(json.dumps(live))
row = next(c for c in flagged["comparisons"] if c["stage"] == "region" and c["metric"] == "time")
row.update(mark="+", regression=True, ratio=2.5, ratio_ci=[2.25, 2.75], p_slower_holm=0.0004, note="regression")
flagged.update(exit_code=6, regressions=1, unjudged=[u for u in flagged["unjudged"] if u != "ci-small/cpu/region"])
flagged_path = os.path.join(WORK, "flagged.json")
json.dump(flagged, open(flagged_path, "w"))
page = page_of(flagged_path)
marked = [r for r in page.rows if len(r) == 13 and r[3] == "region" and r[4] == "time"]
if marked != [["+", "ci-small", "cpu", "region", "time", "2 rounds", marked[0][6], marked[0][7], "2.500",
               "2.250-2.750", "0.0004", marked[0][11], "regression"]]:
    fail(f"the comparison table's region row: {marked}")
if not any(t == "Verdict: regression: ci-small/cpu/region (x2.50) (exit code 6)." for t in page.paragraphs):
    fail(f"the page must give the regression and exit code 6: {[t for t in page.paragraphs if 'Verdict' in t]}")
if not any(r[:4] == [flagged_path, "perf compare", "6", "fail"] for r in page.rows):
    fail("the verdict table must list the compare file with exit code 6")
if not any(t == "Verdict: fail (exit code 6)." for t in page.paragraphs):
    fail("the combined verdict must be exit code 6")

# A failed run is listed with its round (1-based) and exit code.
flagged["failed_runs"] = [{"side": "head", "scene": "ci-small", "round": 1, "exit": 1, "compared": False}]
json.dump(flagged, open(flagged_path, "w"))
page = page_of(flagged_path)
if ["1", "head", "ci-small", "2", "1", "no: it wrote no valid results.json"] not in page.rows:
    fail("the failed run must be listed: head, ci-small, round 2, exit 1, not compared")

# Refused: a bad mark, named by file and field; a kept folder with no verdict, named by its compare.json.
flagged["comparisons"][0]["mark"] = "*"
json.dump(flagged, open(flagged_path, "w"))
p = cli("report", flagged_path, "-o", os.path.join(WORK, "bad.html"))
if p.returncode != 3 or f"{flagged_path}: /comparisons/0/mark: must be one of" not in p.stderr:
    fail(f"a bad mark: exit {p.returncode}\n{p.stderr}")
os.remove(os.path.join(kept, "compare.json"))
p = cli("report", kept, "-o", os.path.join(WORK, "bad.html"))
if p.returncode != 3 or f"{kept}/compare.json: missing: this kept interleave has no verdict" not in p.stderr:
    fail(f"a kept folder without compare.json: exit {p.returncode}\n{p.stderr}")
if os.path.exists(os.path.join(WORK, "bad.html")):
    fail("a refused input must leave no page")
print("report compare: ok")

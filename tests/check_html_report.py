#!/usr/bin/env python3
"""Checks `cloudbench report` end to end: makes a small run, a
conformance check and a sweep of SCENE, and a synthetic perf history with two planted
steps (one listed by its record, one in the instruction counts left to the detector)
and a half-written last line; writes the report; then loads the page
in Debian's headless chromium from file:// and checks that

- no console message appears (the page has no script, so any message is an error),
- the page makes no http(s) request (chromium's net log, requests from the file://
  page) and its markup holds no http:// or https:// at all,
- the page holds the plots and tables the inputs call for, counted here from the
  input files: one box plot per results.json, one history plot per scene x stage of
  the history plus one for instruction counts, one Pareto plot per swept stage; the
  verdict, conformance matrix, timing and source documents' tables plus each input's own
  tables; the frames, their differences and top views as data: images; exactly the
  two planted change points.

The checker is first run on a page with a script error and an external image, and
must reject it (so that a broken check cannot pass). Exits 77 (skipped) without
chromium.

usage: check_html_report.py CLOUDBENCH OUT_DIR SCENE [SCREENSHOT.png]
"""
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys

CHROMIUM_FLAGS = [
    "--headless", "--disable-gpu", "--no-sandbox", "--enable-logging=stderr", "--v=0",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--no-first-run", "--disable-default-apps", "--disable-extensions", "--disable-breakpad",
]


def fail(message):
    sys.exit("check_html_report: " + message)


def run(args, ok_codes=(0,)):
    result = subprocess.run(args, capture_output=True, text=True, timeout=300)
    if result.returncode not in ok_codes:
        fail(f"{' '.join(args)} exited {result.returncode}:\n{result.stdout}\n{result.stderr}")
    return result


class PageCounts(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.plots = {}
        self.tables = 0
        self.data_images = 0
        self.other_images = 0
        self.change_points = 0
        self.urls = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "svg" and "data-plot" in a:
            self.plots[a["data-plot"]] = self.plots.get(a["data-plot"], 0) + 1
        if tag == "table":
            self.tables += 1
        if tag == "img":
            if a.get("src", "").startswith("data:image/png;base64,"):
                self.data_images += 1
            else:
                self.other_images += 1
        if "data-change-point" in a:
            self.change_points += 1
        for key in ("src", "href"):
            if key in a and not a[key].startswith(("data:", "#")):
                self.urls.append(a[key])


def page_requests(netlog_path):
    """The http(s) URLs that the file:// page requested, from chromium's net log."""
    if not os.path.exists(netlog_path):
        fail("chromium wrote no net log")
    text = open(netlog_path).read().rstrip().rstrip(",")
    try:
        log = json.loads(text)
    except json.JSONDecodeError:
        log = json.loads(text + ("]}" if not text.endswith("]}") else ""))
    urls = set()
    for event in log.get("events", []):
        params = event.get("params", {})
        url = params.get("url", "")
        # Chromium's own background requests carry other sites; the page's carry file://.
        page = "file://" in params.get("network_isolation_key", "") or "site=file://" in params.get(
            "site_for_cookies", "")
        if url.startswith(("http://", "https://")) and page:
            urls.add(url)
    return sorted(urls)


def load(chromium, page, work):
    """Loads `page` headless: (DOM, console lines, page requests)."""
    netlog = os.path.join(work, "netlog.json")
    if os.path.exists(netlog):
        os.remove(netlog)
    result = subprocess.run([chromium, *CHROMIUM_FLAGS, f"--log-net-log={netlog}", "--dump-dom",
                             "file://" + os.path.abspath(page)], capture_output=True, text=True, timeout=120)
    if result.returncode != 0:
        fail(f"chromium exited {result.returncode}: {result.stderr[-2000:]}")
    console = [line for line in result.stderr.splitlines() if ":CONSOLE" in line]
    return result.stdout, console, page_requests(netlog)


def check_page(chromium, page, work):
    """The problems of a page: console messages, external requests and URLs."""
    dom, console, requests = load(chromium, page, work)
    problems = [f"console: {line}" for line in console]
    problems += [f"requested {url}" for url in requests]
    markup = open(page, encoding="utf-8").read()
    problems += [f"external URL in the markup: {m}" for m in re.findall(r"https?://[^\s\"'<>]*", markup)]
    counts = PageCounts()
    counts.feed(dom)
    problems += [f"link or source outside the page: {url}" for url in counts.urls]
    return problems, counts


def write_history(path):
    """12 records of 2 backends x 2 stages, smooth on cpu 1.5x slower from record 7 (marked there), instruction
    counts, and a half-written last line."""
    with open(path, "w") as out:
        for i in range(12):
            results = {"ci-small": {}}
            for backend in ("cpu", "vk"):
                results["ci-small"][backend] = {}
                for stage, base in (("region", 0.2), ("smooth", 0.5)):
                    factor = 1.5 if (i >= 7 and stage == "smooth" and backend == "cpu") else 1.0
                    samples = [base * factor * (1 + 0.01 * ((i * 7 + k * 3) % 5)) for k in range(5)]
                    results["ci-small"][backend][stage] = {"samples_ms": samples, "median_ms": sorted(samples)[2]}
            del results["ci-small"]["vk"]["region"]["median_ms"]  # a missing field: the samples' median is used
            record = {"format": "cloudbench-perf/1", "id": f"r{i}", "time": f"2025-05-{i + 1:02d}T00:00:00Z",
                      "provenance": {"git": {"commit": f"{i:040x}"}}, "results": results,
                      "instructions": {"ci-small": {"cpu": {"region": 1000000, "smooth": 2000000 + (i >= 7) * 600000}}}}
            if i == 7:
                record["change_points"] = [{"scene": "ci-small", "backend": "cpu", "stage": "smooth"}]
            out.write(json.dumps(record) + "\n")
        out.write('{"format": "cloudbench-perf/1", "id": "half-wri')


def expected_counts(results, conform, sweep, history_path):
    """What the page must hold, from the inputs alone."""
    # A Pareto plot per stage, the renderers sharing one (they make the same image).
    groups = {"images" if r["stage"].startswith("render_") else r["stage"] for r in sweep["rows"] if r["status"] == "ok"}
    plots = {"box": 1, "pareto": len(groups)}
    pairs, instruction_scenes = set(), set()
    for line in open(history_path):
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            continue
        for scene, backends in record.get("results", {}).items():
            for stages in backends.values():
                pairs |= {(scene, stage) for stage in stages}
        instruction_scenes |= set(record.get("instructions", {}))
    plots["history"] = len(pairs) + len(instruction_scenes)
    own_tables = sum(1 for doc in (results, conform, sweep) for section in doc["report"]["sections"]
                     for block in section["blocks"] if "table" in block)
    tables = 1 + 1 + 1 + 1 + own_tables  # verdict, conformance matrix, timing, source documents' figures
    frames = [f for f in results["files"] if f.startswith("frame-") and f.endswith(".png")]
    views = {}
    for f in frames:
        for backend in results["backends"]:
            if f.endswith(f"-{backend}.png"):
                views.setdefault(f[len("frame-"):-len(f"-{backend}.png")], []).append(backend)
    images = len(frames) + sum(len(b) - 1 for b in views.values())
    images += sum(1 for f in results["files"] if f.startswith("topview-") and f.endswith(".png"))
    return plots, tables, images


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__)
    cli, work, scene = sys.argv[1:4]
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("check_html_report: no chromium; skipped")
        sys.exit(77)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)

    # The checker must catch a script error and an external fetch.
    bad = os.path.join(work, "bad.html")
    with open(bad, "w") as out:
        out.write('<!DOCTYPE html><html><body><img src="http://192.0.2.1/x.png">'
                  '<script>notDefined();</script></body></html>')
    problems, _ = check_page(chromium, bad, work)
    if not any(p.startswith("console:") for p in problems) or not any(p.startswith("requested") for p in problems):
        fail(f"the checker missed the planted faults: {problems}")

    # A real small run, conformance check and sweep; a backend that cannot start here is only unavailable.
    run([cli, "run", scene, "--steps", "8", "--set", "warmup_steps=2", "--quiet", "--out", f"{work}/run"], (0, 4))
    run([cli, "conform", scene, "--steps", "3", "--quiet", "--out", f"{work}/conform"], (0, 4))
    run([cli, "sweep", scene, "--steps", "3", "--vary", "shade.resolution=1,2", "--repeat", "2", "--quiet",
         "--out", f"{work}/sweep"], (0, 4))
    history = os.path.join(work, "history.jsonl")
    write_history(history)
    page = os.path.join(work, "report.html")
    result = run([cli, "report", f"{work}/run", f"{work}/conform/conform.json", f"{work}/sweep/sweep.json",
                  "--history", history, "-o", page])
    if f"{history}:13: skipped: not JSON" not in result.stderr:
        fail(f"no warning for the half-written history line: {result.stderr}")

    problems, counts = check_page(chromium, page, work)
    if problems:
        fail("\n".join(problems))
    load_json = lambda p: json.load(open(p))  # noqa: E731
    plots, tables, images = expected_counts(load_json(f"{work}/run/results.json"),
                                            load_json(f"{work}/conform/conform.json"),
                                            load_json(f"{work}/sweep/sweep.json"), history)
    if counts.plots != plots:
        fail(f"plots {counts.plots}, expected {plots}")
    if counts.tables != tables:
        fail(f"{counts.tables} tables, expected {tables}")
    if counts.data_images != images or counts.other_images:
        fail(f"{counts.data_images} embedded images and {counts.other_images} others, expected {images} embedded")
    # Two planted steps, both at record 7: cpu smooth 1.5x slower (also listed by the record, marked once) and
    # smooth's instruction count 1.3x; the other series move by under 5 %, below the detector's 10 %.
    if counts.change_points != 2:
        fail(f"{counts.change_points} change points marked, expected the 2 planted")
    if len(sys.argv) == 5:
        subprocess.run([chromium, *CHROMIUM_FLAGS, "--hide-scrollbars", "--window-size=1100,4300",
                        f"--screenshot={os.path.abspath(sys.argv[4])}", "file://" + os.path.abspath(page)],
                       capture_output=True, timeout=120, check=True)
    print(f"html report: ok ({sum(plots.values())} plots {plots}, {tables} tables, {images} images, "
          f"{os.path.getsize(page)} bytes)")


if __name__ == "__main__":
    main()

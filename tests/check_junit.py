#!/usr/bin/python3
"""conform --junit: the JUnit XML a CI system reads, read back by Debian's python3-junitparser.

Usage: check_junit.py CLOUDBENCH OUT_DIR BACKEND
Runs conform ci-small on cpu and BACKEND with a mismatch planted in BACKEND's shade (the test-only
CLOUDBENCH_TEST_CONFORM_MISMATCH switch) and checks that the file holds one test case per row of conform.json
(classname SCENE.BACKEND, name the stage), that the planted row is a failure whose message names the worst
difference, the tolerance and the rule, and that every other row passes; then that a clean run has no failure.
Exit 77 (a skip) without junitparser.
"""
import json
import os
import shutil
import subprocess
import sys

try:
    from junitparser import Error, Failure, JUnitXml, Skipped
except ImportError as e:
    print("junit: unsupported here: %s (apt-get install python3-junitparser)" % e)
    sys.exit(77)

cli, out, backend = sys.argv[1:4]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)


def fail(message):
    sys.exit("junit: " + message)


def conform(name, mismatch):
    env = dict(os.environ, CLOUDBENCH_TEST_CONFORM_MISMATCH=mismatch)
    folder, xml = os.path.join(out, name), os.path.join(out, name + ".xml")
    p = subprocess.run([cli, "conform", "ci-small", "--backend", "cpu," + backend, "--steps", "2", "--quiet",
                        "--out", folder, "--junit", xml], env=env, capture_output=True, text=True, timeout=300)
    with open(os.path.join(folder, "conform.json")) as f:
        return p.returncode, json.load(f)["results"], JUnitXml.fromfile(xml)


code, rows, xml = conform("planted", backend + ":shade")
if code != 5:
    fail("the planted run exits %d, not 5" % code)
suites = list(xml)
if len(suites) != 1 or suites[0].name != "conform ci-small":
    fail("suites %s" % [s.name for s in suites])
suite = suites[0]
cases = list(suite)
if len(cases) != len(rows) or suite.tests != len(rows):
    fail("%d test cases (tests=%d) for %d rows" % (len(cases), suite.tests, len(rows)))
for case, row in zip(cases, rows):
    if case.classname != "ci-small." + row["backend"] or case.name != row["stage"]:
        fail("case %s.%s for row %s on %s" % (case.classname, case.name, row["stage"], row["backend"]))
    results = list(case.result)
    if row["stage"] == "shade":
        if len(results) != 1 or not isinstance(results[0], Failure):
            fail("the planted shade row is %s, not a failure" % results)
        message = results[0].message
        if "worst" not in message or "tolerance" not in message or row["rule"] not in message:
            fail("the failure's message %r lacks the worst difference, the tolerance or the rule %r" %
                 (message, row["rule"]))
    elif row["status"] == "pass" and results:
        fail("the passing row %s has %s" % (row["stage"], results))
if suite.failures != 1 or suite.errors != 0:
    fail("failures=%s errors=%s, expected 1 and 0" % (suite.failures, suite.errors))
code, rows, xml = conform("clean", "")
if code != 0 or any(case.result for suite in xml for case in suite if any(
        isinstance(r, (Failure, Error)) for r in case.result)):
    fail("a clean run (exit %d) has a failure or an error in its JUnit file" % code)
print("junit: ok (%d test cases, the planted one a failure)" % len(rows))

#!/usr/bin/python3
"""Runs the project's oracles again and again on an unchanged tree and counts false alarms.

Every run of every oracle on an unchanged, passing tree must pass, so any failure
here is a false alarm: a test or a conformance row that depends on timing, load,
scheduling or the machine rather than on the code. docs/testing.md records 20
runs on the noisy development machine.

Usage:
  /usr/bin/python3 tools/repeat_runs.py --runs 20 --build build/release \
      --conform ci-small --conform thesis-medium:steps=40 \
      --ctest-exclude 'Fuzz|Exact' --out reports/false-alarms.json

Each run does the oracles in the order given (conform scenes, then CTest), so a
slow drift of the machine's load falls on all of them. The JSON is rewritten
after every oracle, so an interrupted measurement keeps what it has.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ElementTree


def parse_conform_spec(text):
    """'scene' or 'scene:steps=N' -> (scene, steps or None)."""
    scene, _, options = text.partition(':')
    steps = None
    if options:
        key, _, value = options.partition('=')
        if key != 'steps' or not value.isdigit():
            sys.exit(f"--conform {text}: expected SCENE or SCENE:steps=N")
        steps = int(value)
    return scene, steps


def run_conform(cloudbench, scene, steps, backends, workdir):
    """One `cloudbench conform`; returns (exit code, rows that did not pass, seconds)."""
    out = os.path.join(workdir, 'conform-' + scene)
    command = [cloudbench, 'conform', scene, '--backend', backends, '--out', out]
    if steps is not None:
        command += ['--steps', str(steps)]
    start = time.monotonic()
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    seconds = time.monotonic() - start
    failures = []
    try:
        with open(os.path.join(out, 'conform.json')) as file:
            for row in json.load(file).get('results', []):
                if row.get('status') != 'pass':
                    failures.append(f"{row.get('stage')}/{row.get('backend')}: {row.get('status')} "
                                    f"worst {row.get('worst')}")
    except (OSError, ValueError) as error:
        failures.append(f"conform.json unreadable: {error}")
    if done.returncode != 0 and not failures:
        failures.append('exit ' + str(done.returncode) + ': ' + done.stdout[-400:])
    return done.returncode, failures, seconds


def run_ctest(build, regex, exclude, jobs, workdir):
    """One CTest pass; returns (exit code, failed test names, test count, seconds)."""
    junit = os.path.join(workdir, 'ctest.xml')
    command = ['ctest', '--test-dir', build, '-j', str(jobs), '--output-junit', junit]
    if regex:
        command += ['-R', regex]
    if exclude:
        command += ['-E', exclude]
    start = time.monotonic()
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    seconds = time.monotonic() - start
    failed, count = [], 0
    try:
        for case in ElementTree.parse(junit).getroot().iter('testcase'):
            count += 1
            # CTest's JUnit statuses: run, fail, disabled (DISABLED_ tests) and notrun (skipped).
            if case.get('status') == 'fail' or case.find('failure') is not None:
                failed.append(case.get('name'))
    except (OSError, ElementTree.ParseError) as error:
        failed.append(f"junit unreadable: {error}")
    if done.returncode != 0 and not failed:
        failed.append('exit ' + str(done.returncode) + ': ' + done.stdout[-400:])
    return done.returncode, failed, count, seconds


def write_atomically(path, value):
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    with tempfile.NamedTemporaryFile('w', dir=folder, delete=False, suffix='.tmp') as file:
        json.dump(value, file, indent=1)
        temporary = file.name
    os.replace(temporary, path)


def summarise(record):
    lines = []
    for name, runs in record['oracles'].items():
        alarms = [run for run in runs if run['failures']]
        seconds = sorted(run['seconds'] for run in runs)
        median = seconds[len(seconds) // 2] if seconds else 0.0
        lines.append(f"{name}: {len(runs)} runs, {len(alarms)} with a failure, "
                     f"median {median:.1f} s [{seconds[0] if seconds else 0:.1f}, "
                     f"{seconds[-1] if seconds else 0:.1f}]")
        for run in alarms:
            lines.append(f"  run {run['run']}: " + '; '.join(run['failures'][:5]))
    return '\n'.join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--runs', type=int, default=20)
    parser.add_argument('--build', default='build/release')
    parser.add_argument('--backend', default='cpu,vk,gl')
    parser.add_argument('--conform', action='append', default=[], metavar='SCENE[:steps=N]')
    parser.add_argument('--ctest', action='store_true', help='also run CTest each run')
    parser.add_argument('--ctest-regex', default='')
    parser.add_argument('--ctest-exclude', default='')
    parser.add_argument('-j', '--jobs', type=int, default=2)
    parser.add_argument('--out', default='reports/false-alarms.json')
    arguments = parser.parse_args()

    cloudbench = os.path.join(arguments.build, 'cloudbench')
    if not os.access(cloudbench, os.X_OK):
        sys.exit(f"{cloudbench}: not built (cmake --build {arguments.build} --target cloudbench)")
    conform = [parse_conform_spec(text) for text in arguments.conform]
    record = {'format': 'cloudbench-false-alarms/1', 'runs': arguments.runs, 'backend': arguments.backend,
              'ctest_regex': arguments.ctest_regex, 'ctest_exclude': arguments.ctest_exclude,
              'started': time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime()), 'oracles': {}}
    with tempfile.TemporaryDirectory(prefix='cloudbench-repeat-') as workdir:
        for run in range(arguments.runs):
            for scene, steps in conform:
                name = 'conform ' + scene + (f' --steps {steps}' if steps else '')
                code, failures, seconds = run_conform(cloudbench, scene, steps, arguments.backend, workdir)
                record['oracles'].setdefault(name, []).append(
                    {'run': run, 'exit': code, 'failures': failures, 'seconds': round(seconds, 2)})
                write_atomically(arguments.out, record)
                print(f"run {run + 1}/{arguments.runs} {name}: exit {code} ({seconds:.1f} s)", flush=True)
            if arguments.ctest:
                code, failed, count, seconds = run_ctest(arguments.build, arguments.ctest_regex,
                                                         arguments.ctest_exclude, arguments.jobs, workdir)
                record['oracles'].setdefault('ctest', []).append(
                    {'run': run, 'exit': code, 'tests': count, 'failures': failed, 'seconds': round(seconds, 2)})
                write_atomically(arguments.out, record)
                print(f"run {run + 1}/{arguments.runs} ctest: {count} tests, {len(failed)} failed "
                      f"({seconds:.1f} s)", flush=True)
    record['finished'] = time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())
    write_atomically(arguments.out, record)
    print(summarise(record))
    return 1 if any(run['failures'] for runs in record['oracles'].values() for run in runs) else 0


if __name__ == '__main__':
    sys.exit(main())

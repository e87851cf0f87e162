#!/usr/bin/python3
"""A real Slurm cluster runs a sharded sweep: tools/slurm/sweep-shard.sh as a job array, then tools/slurm/merge.sh
as a job that depends on it (afterok), and the merged sweep equals the unsharded one but for the times; and
`perf record` on each of its two nodes, then `merge` of the two histories, keeps both records once.

Usage: check_slurm.py CLOUDBENCH SOURCE_DIR OUT_DIR

Starts a cluster of its own on this machine from Debian's slurm-wlm and munge in a fresh folder: munged with a new
key and its own socket, slurmctld, and a slurmd for each of two nodes (slurmd -N, a port each) with a generated
slurm.conf (ports of their own, proctrack/linuxproc, task/none) and cgroup.conf (cgroup/v1, IgnoreSystemd), every
path and pid file in that folder. Every daemon it
started is stopped by its pid when it ends, failed or not; it never talks to another cluster (SLURM_CONF and
the munge socket are its own). Exit 77 (a skip) where the daemons are not installed.
"""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

cli, source, out = sys.argv[1:4]
DAEMONS = ("munged", "slurmctld", "slurmd", "sbatch")
SWEEP = ["ci-small", "--backend", "cpu", "--steps", "2", "--repeat", "1", "--vary", "shade.sigma=0.5,1,2"]
TASKS = 3

missing = [d for d in DAEMONS if not shutil.which(d) and not os.path.exists("/usr/sbin/" + d)]
if missing:
    print("slurm: unsupported here: %s not installed (apt-get install slurm-wlm munge)" % ", ".join(missing))
    sys.exit(77)


def fail(message):
    raise SystemExit("slurm: " + message)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def deterministic(row):
    """What a rerun reproduces: not the times, nor the Pareto marks that follow from them."""
    return {k: v for k, v in row.items() if k not in ("time", "pareto", "pareto_tie")}


shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
# Socket paths are limited to 108 bytes: the cluster's folder is a short one of its own.
home = tempfile.mkdtemp(prefix="cb-slurm-")
for d in ("state", "spool", "log"):
    os.makedirs(os.path.join(home, d))
host = socket.gethostname().split(".")[0]
key, sock = os.path.join(home, "munge.key"), os.path.join(home, "munge.socket")
with open(key, "wb") as f:
    f.write(os.urandom(1024))
os.chmod(key, 0o600)
conf = os.path.join(home, "slurm.conf")
with open(conf, "w") as f:
    f.write(f"""ClusterName=cloudbench-test
SlurmctldHost={host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
SlurmctldPort={free_port()}
StateSaveLocation={home}/state
SlurmdSpoolDir={home}/spool/%n
SlurmctldPidFile={home}/slurmctld.pid
SlurmdPidFile={home}/slurmd-%n.pid
SlurmctldLogFile={home}/log/slurmctld.log
SlurmdLogFile={home}/log/slurmd-%n.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=cb-node1 NodeHostname={host} NodeAddr=127.0.0.1 Port={free_port()} CPUs={os.cpu_count()} State=UNKNOWN
NodeName=cb-node2 NodeHostname={host} NodeAddr=127.0.0.1 Port={free_port()} CPUs={os.cpu_count()} State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
""")
with open(os.path.join(home, "cgroup.conf"), "w") as f:
    f.write("CgroupPlugin=cgroup/v1\nIgnoreSystemd=yes\n")
env = dict(os.environ, SLURM_CONF=conf, CLOUDBENCH=os.path.abspath(cli))
pids = {}  # daemon -> pid, read from the pid file each writes


def start(name, command, pid_file):
    p = subprocess.run(command, env=env, capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        fail("%s did not start (exit %d): %s%s" % (name, p.returncode, p.stdout, p.stderr))
    for _ in range(100):
        if os.path.exists(pid_file) and open(pid_file).read().strip():
            pids[name] = int(open(pid_file).read())
            return
        time.sleep(0.1)
    fail("%s wrote no pid file %s" % (name, pid_file))


def stop_all():
    for name in ("slurmd-cb-node2", "slurmd-cb-node1", "slurmctld", "munged"):  # the reverse of the start
        pid = pids.pop(name, None)
        if pid is None:
            continue
        try:
            os.kill(pid, signal.SIGTERM)
        except ProcessLookupError:
            continue
        for _ in range(100):
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                break
            time.sleep(0.1)
        else:
            os.kill(pid, signal.SIGKILL)


def slurm(*args):
    p = subprocess.run(list(args), env=env, capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        fail("%s: exit %d: %s%s" % (" ".join(args), p.returncode, p.stdout, p.stderr))
    return p.stdout.strip()


try:
    start("munged", ["munged", "--key-file", key, "--socket", sock, "--pid-file", home + "/munged.pid",
                     "--log-file", home + "/log/munged.log", "--seed-file", home + "/munge.seed", "--force"],
          home + "/munged.pid")
    start("slurmctld", ["slurmctld", "-f", conf], home + "/slurmctld.pid")
    for node in ("cb-node1", "cb-node2"):
        os.makedirs(os.path.join(home, "spool", node))
        start("slurmd-" + node, ["slurmd", "-f", conf, "-N", node], home + "/slurmd-%s.pid" % node)
    for _ in range(300):
        if slurm("sinfo", "-h", "-o", "%t").split() == ["idle"] and "2" in slurm("sinfo", "-h", "-o", "%D"):
            break
        time.sleep(0.1)
    else:
        fail("the nodes never became idle: " + slurm("sinfo"))

    # The unsharded sweep, here; the sharded one through the cluster, with the scripts users submit.
    whole = subprocess.run([cli, "sweep"] + SWEEP + ["--quiet", "--out", os.path.join(out, "whole")],
                           capture_output=True, text=True, timeout=600)
    if whole.returncode != 0:
        fail("the unsharded sweep failed: " + whole.stderr)
    shards = os.path.join(out, "cluster")
    array = slurm("sbatch", "--parsable", "--array=1-%d" % TASKS, "-o", os.path.join(home, "log", "shard-%a.txt"),
                  os.path.join(source, "tools/slurm/sweep-shard.sh"), shards, *SWEEP)
    merge = slurm("sbatch", "--parsable", "--dependency=afterok:" + array, "-o",
                  os.path.join(home, "log", "merge.txt"), os.path.join(source, "tools/slurm/merge.sh"), shards)
    merged = os.path.join(shards, "merged", "sweep.json")
    deadline = time.time() + 300
    while time.time() < deadline and slurm("squeue", "-h", "-j", "%s,%s" % (array, merge)):
        time.sleep(0.5)
    if not os.path.exists(merged):
        logs = "".join(open(os.path.join(home, "log", n)).read() for n in sorted(os.listdir(os.path.join(home, "log")))
                       if n.endswith(".txt"))
        fail("no merged sweep.json after the jobs ended (%s)\n%s" % (slurm("sinfo"), logs))
    for task in range(1, TASKS + 1):
        if not os.path.exists(os.path.join(shards, "shard-%d" % task, "sweep.json")):
            fail("task %d wrote no shard" % task)
    with open(os.path.join(out, "whole", "sweep.json")) as f:
        want = [deterministic(r) for r in json.load(f)["rows"]]
    with open(merged) as f:
        got = [deterministic(r) for r in json.load(f)["rows"]]
    if got != want:
        fail("the merged sweep differs from the unsharded one:\n%s\n%s" % (got, want))

    # perf record on each node into a history of its own, then merge: both records, once each.
    suite = os.path.join(out, "suite.json")
    with open(suite, "w") as f:
        json.dump({"scenes": [{"scene": "ci-small", "set": ["steps=6", "warmup_steps=2"]}]}, f)
    records = []
    for node in ("cb-node1", "cb-node2"):
        history = os.path.join(out, "history-%s.jsonl" % node)
        records.append((history, slurm("sbatch", "--parsable", "-w", node, "-o", os.path.join(home, "log", node + ".txt"),
                                       "--wrap", '"$CLOUDBENCH" perf record --suite %s --history %s --backend cpu '
                                       '--quiet' % (suite, history))))
    deadline = time.time() + 300
    while time.time() < deadline and slurm("squeue", "-h", "-j", ",".join(job for _, job in records)):
        time.sleep(0.5)
    ids = []
    for history, job in records:
        if not os.path.exists(history):
            fail("perf record wrote no %s (job %s)" % (history, job))
        with open(history) as f:
            ids += [json.loads(line)["id"] for line in f if line.strip()]
    if len(ids) != 2 or ids[0] == ids[1]:
        fail("expected one record from each node, got %s" % ids)
    p = subprocess.run([cli, "merge", records[0][0], records[1][0], records[0][0], "--out", os.path.join(out, "all")],
                       capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        fail("merge of the histories failed: " + p.stderr)
    with open(os.path.join(out, "all", "history.jsonl")) as f:
        merged_ids = [json.loads(line)["id"] for line in f if line.strip()]
    if sorted(merged_ids) != sorted(ids):
        fail("the merged history holds %s, not each node's record once (%s)" % (merged_ids, ids))
    print("slurm: ok (%d array tasks and a dependent merge: %d rows equal the unsharded sweep's; perf record on "
          "two nodes, merged once each)" % (TASKS, len(got)))
finally:
    stop_all()
    shutil.rmtree(home, ignore_errors=True)

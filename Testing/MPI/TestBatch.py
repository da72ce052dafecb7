"""SDFCage batch (Plugin/sdfcage_batch.py) on 2 MPI ranks: a generated folder with a bad file,
the summary tables and the collection, then a real interruption and a resume.

Run: /usr/bin/python3 TestBatch.py --mpiexec MPIEXEC [--mpiexec-arg A ...] --pvbatch PVBATCH
       --script sdfcage_batch.py --sdfcage SDFCAGE --scratch DIR
"""
import argparse
import csv
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mpi_compare import Checker  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--mpiexec", required=True)
ap.add_argument("--mpiexec-arg", action="append", default=[])
ap.add_argument("--pvbatch", required=True)
ap.add_argument("--script", required=True)
ap.add_argument("--sdfcage", required=True)
ap.add_argument("--scratch", required=True)
a = ap.parse_args()
chk = Checker()
N = 60


def write_off(path, points, triangles):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(points), len(triangles)))
        for p in points:
            f.write("%.17g %.17g %.17g\n" % p)
        for t in triangles:
            f.write("3 %d %d %d\n" % t)


def torus(u, v, ring, tube, shift=(0.0, 0.0, 0.0)):
    pts = []
    for i in range(u):
        al = 2 * math.pi * i / u
        for j in range(v):
            be = 2 * math.pi * j / v
            r = ring + tube * math.cos(be)
            pts.append((r * math.cos(al) + shift[0], r * math.sin(al) + shift[1], tube * math.sin(be) + shift[2]))
    tris = []
    for i in range(u):
        for j in range(v):
            p00, p10 = i * v + j, ((i + 1) % u) * v + j
            p01, p11 = i * v + (j + 1) % v, ((i + 1) % u) * v + (j + 1) % v
            tris += [(p00, p10, p11), (p00, p11, p01)]
    return pts, tris


def uv_sphere(n_lat, n_lon, radius=1.0):
    pts = [(0.0, 0.0, radius), (0.0, 0.0, -radius)]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            pts.append((radius * math.sin(th) * math.cos(ph), radius * math.sin(th) * math.sin(ph), radius * math.cos(th)))
    ring = lambda i, j: 2 + (i - 1) * n_lon + (j % n_lon)  # noqa: E731
    tris = []
    for j in range(n_lon):
        tris.append((0, ring(1, j), ring(1, j + 1)))
        tris.append((1, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)))
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            tris += [(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)), (ring(i, j), ring(i + 1, j + 1), ring(i, j + 1))]
    return pts, tris


# --- the folder: four good meshes of different sizes and one bad file ------------------------------
folder = os.path.join(a.scratch, "batch_meshes")
shutil.rmtree(folder, ignore_errors=True)
os.makedirs(folder)
write_off(os.path.join(folder, "torus_big.off"), *torus(64, 32, 1.0, 0.35))
write_off(os.path.join(folder, "sphere.off"), *uv_sphere(24, 32))
write_off(os.path.join(folder, "torus_small.off"), *torus(24, 12, 1.0, 0.4))
write_off(os.path.join(folder, "blob.off"), *uv_sphere(10, 12, 2.0))
with open(os.path.join(folder, "bad.off"), "w") as f:
    f.write("OFF\n4 2 0\n0 0 0\n1 0 0\n")  # ends after 2 of its 4 vertices
with open(os.path.join(folder, "readme.txt"), "w") as f:
    f.write("not a mesh: ignored\n")
sizes = {os.path.splitext(n)[0]: os.path.getsize(os.path.join(folder, n)) for n in os.listdir(folder) if n.endswith(".off")}
good = sorted(n for n in sizes if n != "bad")


def batch_cmd(out, ranks=2):
    return [a.mpiexec] + a.mpiexec_arg + ["-np", str(ranks), a.pvbatch, "--symmetric", a.script, folder, "-o", out,
                                          "-n", str(N), "--sdfcage", a.sdfcage, "--cli-arg=--iso=0.04"]


def run(cmd, timeout=400):
    print("run:", " ".join(cmd), flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    print(p.stdout[-4000:])
    print(p.stderr[-2000:])
    return p


def summary(out):
    with open(os.path.join(out, "summary.csv")) as f:
        return {r["mesh"]: r for r in csv.DictReader(f)}


def records(out):
    d = os.path.join(out, "reports")
    return {n[:-len(".batch.json")]: os.stat(os.path.join(d, n)).st_mtime_ns
            for n in os.listdir(d) if n.endswith(".batch.json")} if os.path.isdir(d) else {}


# --- 1. one batch on 2 ranks ---------------------------------------------------------------------
out = os.path.join(a.scratch, "batch_out")
shutil.rmtree(out, ignore_errors=True)
p = run(batch_cmd(out))
chk.check(p.returncode == 0, "the batch ends with exit code 0 although one mesh is bad (%d)" % p.returncode)
rows = summary(out) if os.path.exists(os.path.join(out, "summary.csv")) else {}
chk.check(sorted(rows) == sorted(sizes), "summary.csv has one row per mesh file (%s)" % sorted(rows))
for name in good:
    r = rows.get(name, {})
    chk.check(r.get("verdict") == "verified" and r.get("vertices") == str(N) and float(r.get("time_s") or 0) > 0,
              "%s: verified, %d vertices, timed (%s)" % (name, N, {k: r.get(k) for k in ("verdict", "vertices", "time_s")}))
    chk.check(os.path.exists(os.path.join(out, "cages", name + ".vtp")), "%s: cage written" % name)
    chk.check(int(r.get("faces") or 0) > 0, "%s: faces counted (%s)" % (name, r.get("faces")))
bad = rows.get("bad", {})
chk.check(bad.get("verdict") == "bad input" and "vertices" in bad.get("error", ""),
          "bad.off: verdict 'bad input', the reason recorded (%r)" % bad.get("error"))
chk.check({r.get("rank") for r in rows.values()} == {"0", "1"}, "both ranks caged meshes (%s)"
          % sorted({r.get("rank") for r in rows.values()}))
with open(os.path.join(out, "summary.md")) as f:
    md = f.read()
chk.check(all("| %s |" % n in md for n in sizes) and "bad input" in md, "summary.md lists every mesh and the verdicts")
# largest first: the two meshes started first (one per rank) are the two largest files
starts = {}
for n in sizes:
    with open(os.path.join(out, "reports", n + ".batch.json")) as f:
        starts[n] = json.load(f)["started"]
first_two = sorted(starts, key=lambda n: starts[n])[:2]
largest_two = sorted(sizes, key=lambda n: -sizes[n])[:2]
chk.check(sorted(first_two) == sorted(largest_two), "largest first: %s started first, the largest are %s"
          % (first_two, largest_two))
# the collection for ParaView
from vtkmodules.vtkIOXML import vtkXMLPartitionedDataSetCollectionReader  # noqa: E402
reader = vtkXMLPartitionedDataSetCollectionReader()
reader.SetFileName(os.path.join(out, "cages.vtpc"))
reader.Update()
coll = reader.GetOutput()
names = sorted(coll.GetMetaData(i).Get(coll.NAME()) for i in range(coll.GetNumberOfPartitionedDataSets()))
chk.check(names == good, "cages.vtpc: one partitioned data set per caged mesh, named after it (%s)" % names)
chk.check(all(coll.GetPartition(i, 0).GetNumberOfPoints() == N for i in range(coll.GetNumberOfPartitionedDataSets())),
          "cages.vtpc: every cage has %d points" % N)

# --- 1b. a cage that cannot be read (one an older sdfcage wrote with appended data, which VTK 9.1
# cannot read with an up-to-date Debian 12's expat; here a truncated file): --summary-only leaves it
# out of cages.vtpc with a message, never an empty block
victim = good[0]
with open(os.path.join(out, "cages", victim + ".vtp"), "r+b") as f:
    f.truncate(200)
p = run(batch_cmd(out) + ["--summary-only"])
chk.check(p.returncode == 0 and ("%s: cannot read its cage" % victim) in p.stdout,
          "--summary-only with an unreadable cage: exit 0 and a message naming %s (%d)" % (victim, p.returncode))
reader = vtkXMLPartitionedDataSetCollectionReader()
reader.SetFileName(os.path.join(out, "cages.vtpc"))
reader.Update()
coll = reader.GetOutput()
names = sorted(coll.GetMetaData(i).Get(coll.NAME()) for i in range(coll.GetNumberOfPartitionedDataSets()))
chk.check(names == [n for n in good if n != victim], "cages.vtpc leaves the unreadable cage out (%s)" % names)
chk.check(all(coll.GetPartition(i, 0).GetNumberOfPoints() == N for i in range(coll.GetNumberOfPartitionedDataSets())),
          "cages.vtpc: no empty block")

# --- 2. resume after a real interruption ---------------------------------------------------------
out2 = os.path.join(a.scratch, "batch_interrupted")
shutil.rmtree(out2, ignore_errors=True)
# the interruption must come while meshes are left: on an idle machine the whole batch takes about
# a second, faster than any polling. So the run to interrupt calls sdfcage through a wrapper that
# holds the largest mesh (the first handed out) for a minute the first time it is asked for it.
held = os.path.join(a.scratch, "batch_held_once")
if os.path.exists(held):
    os.remove(held)
wrapper = os.path.join(a.scratch, "sdfcage_slow_once.sh")
largest = max(sizes, key=lambda n: sizes[n])
with open(wrapper, "w") as f:
    f.write("#!/bin/sh\ncase \"$*\" in *%s.off*) [ -e '%s' ] || { touch '%s'; sleep 60; } ;; esac\nexec '%s' \"$@\"\n"
            % (largest, held, held, a.sdfcage))
os.chmod(wrapper, 0o755)
cmd2 = batch_cmd(out2)
cmd2[cmd2.index("--sdfcage") + 1] = wrapper
print("run (to interrupt):", " ".join(cmd2), flush=True)
proc = subprocess.Popen(cmd2, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                        start_new_session=True)
deadline = time.time() + 300
while time.time() < deadline and proc.poll() is None and len(records(out2)) < len(sizes) - 1:
    time.sleep(0.1)
os.killpg(proc.pid, signal.SIGTERM)
try:
    proc.wait(timeout=30)
except subprocess.TimeoutExpired:
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
print((proc.stdout.read() or "")[-3000:])
done_before = records(out2)
chk.check(1 <= len(done_before) < len(sizes), "interrupted with %d of %d meshes recorded" % (len(done_before), len(sizes)))
p = run(batch_cmd(out2))
chk.check(p.returncode == 0, "the resumed batch ends with exit code 0")
chk.check("%d to do (%d already done)" % (len(sizes) - len(done_before), len(done_before)) in p.stdout,
          "the resumed batch does only the %d meshes not done" % (len(sizes) - len(done_before)))
after = records(out2)
chk.check(all(after.get(n) == t for n, t in done_before.items()), "meshes finished before the interruption are not redone")
chk.check(sorted(after) == sorted(sizes), "every mesh has its record after the resume")
rows2 = summary(out2)
chk.check(all(rows2[n]["verdict"] == "verified" for n in good) and rows2["bad"]["verdict"] == "bad input",
          "the resumed batch's summary has every verdict")
# a third run has nothing to do
p = run(batch_cmd(out2, ranks=2))
chk.check("0 to do (%d already done)" % len(sizes) in p.stdout and records(out2) == after,
          "a finished batch run again does nothing")

# --- 4. hand-out by an earlier run's times (--costs): the slowest of that run first ------------
# a made-up earlier summary that calls the smallest file the slowest, and knows nothing of "blob":
# on one rank the meshes start in the order blob (unknown: first), then by falling cost
costs_csv = os.path.join(a.scratch, "batch_costs.csv")
by_size = sorted((n for n in good if n != "blob"), key=lambda n: sizes[n])
with open(costs_csv, "w") as f:
    f.write("mesh,file,time_s\n")
    for i, n in enumerate(by_size):
        f.write("%s,%s,%d\n" % (n, os.path.join(folder, n + ".off"), 100 - i))
out3 = os.path.join(a.scratch, "batch_out_costs")
shutil.rmtree(out3, ignore_errors=True)
p = run(batch_cmd(out3, ranks=1) + ["--costs", costs_csv])
chk.check(p.returncode == 0, "the batch with --costs ends with exit code 0")
starts3 = {}
for n in sizes:
    try:
        with open(os.path.join(out3, "reports", n + ".batch.json")) as f:
            starts3[n] = json.load(f)["started"]
    except (OSError, ValueError, KeyError):
        pass
order3 = [n for n in sorted(starts3, key=lambda n: starts3[n]) if n != "bad"]
chk.check(order3 == ["blob"] + by_size, "--costs: unknown mesh first, then the slowest of the earlier run (%s)"
          % order3)
chk.finish()

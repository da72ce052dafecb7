#!/usr/bin/env python3
"""SDFCage: the "any mesh in" speed figures (issue 12), measured with the program itself.

Run (after the build):  /usr/bin/python3 Testing/Benchmarks/anymesh_benchmark.py [--repeat K]

It times `sdfcage MESH -n 500` (whole process, wall clock, peak memory from /usr/bin/time) on
- ../shared/data/dragon_vrip.ply (871k faces, a raw scan: split seams, zero-area faces),
- a 100k-face soup made here from ../shared/data/armadillo.obj: 2% of its faces removed (holes), plus
  an inside-out copy of 15,000 of its faces moved by (0.15, 0.1, 0.05) so that it crosses the rest
  (open, self-intersecting, inconsistently oriented), written to a temporary folder,
- every mesh of ../shared/data/raw/,
and prints one Markdown row per run: mesh, faces, inside rule, vertices reached, verified, pipeline
total, wall, peak MB. Meshes that are absent are skipped with a note.
"""
import json
import os
import random
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
DATA = os.path.normpath(os.path.join(ROOT, "..", "shared", "data"))
CLI = os.path.join(ROOT, "build", "bin", "sdfcage")


def make_soup(folder):
    source = os.path.join(DATA, "armadillo.obj")
    if not os.path.exists(source):
        return None
    rng = random.Random(1)
    points, faces = [], []
    with open(source) as f:
        for line in f:
            if line.startswith("v "):
                points.append(tuple(map(float, line.split()[1:4])))
            elif line.startswith("f "):
                faces.append(tuple(int(x.split("/")[0]) for x in line.split()[1:4]))
    kept = [f for f in faces if rng.random() > 0.02]
    n = len(points)
    extra = [(c + n, b + n, a + n) for (a, b, c) in faces[:15000]]
    path = os.path.join(folder, "armadillo_soup100k.obj")
    with open(path, "w") as out:
        for p in points:
            out.write("v %r %r %r\n" % p)
        for p in points:
            out.write("v %r %r %r\n" % (p[0] + 0.15, p[1] + 0.1, p[2] + 0.05))
        for f in kept + extra:
            out.write("f %d %d %d\n" % f)
    return path


def run(mesh, folder):
    report = os.path.join(folder, "r.json")
    timing = os.path.join(folder, "time.txt")
    cmd = ["/usr/bin/time", "-f", "%e %M", "-o", timing, CLI, mesh, "-n", "500",
           "-o", os.path.join(folder, "cage.vtp"), "--report", report, "--quiet"]
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall, peak = open(timing).read().split()[-2:]
    r = json.load(open(report))
    return r, float(wall), int(peak) / 1024.0


def main():
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 1
    if not os.path.exists(CLI):
        sys.exit("build the program first (%s is missing)" % CLI)
    with tempfile.TemporaryDirectory() as folder:
        meshes = [os.path.join(DATA, "dragon_vrip.ply"), make_soup(folder)]
        raw = os.path.join(DATA, "raw")
        if os.path.isdir(raw):
            meshes += [os.path.join(raw, m) for m in sorted(os.listdir(raw))]
        print("| mesh | faces | inside rule | vertices | verified | pipeline s | wall s | peak MB |")
        print("|---|---|---|---|---|---|---|---|")
        for mesh in meshes:
            if not mesh or not os.path.exists(mesh):
                print("| %s | absent: skipped |" % mesh)
                continue
            best = None
            for _ in range(repeat):
                r, wall, peak = run(mesh, folder)
                if best is None or wall < best[1]:
                    best = (r, wall, peak)
            r, wall, peak = best
            print("| %s | %d | %s | %d | %s | %.2f | %.2f | %.0f |" % (
                os.path.basename(mesh), r.get("InputCells", 0), r.get("SignMode", "?"),
                r.get("VerticesReached", 0), "yes" if r.get("EnclosureVerified") else "NO",
                r.get("TotalTime", 0.0), wall, peak))
            sys.stdout.flush()


if __name__ == "__main__":
    main()

"""SDFCage side by side with CGAL's 3D Alpha Wrapping, whole processes, in one run (issue #13).

    /usr/bin/python3 Testing/Benchmarks/peer_benchmark.py [MESH|FOLDER ...] [--vertices 500]
        [--repeat 3] [--sdfcage build/bin/sdfcage] [--alphawrap build/bin/sdfcage_alphawrap]
        [--alpha-ratio 20] [--offset-ratio 600] [--out peer_benchmark] [--timeout SECONDS]

Default meshes: every mesh at the top of ../shared/data. For each mesh it runs, --repeat times
each, alternately (so that a machine's load weighs on both alike):
  - `sdfcage MESH -n N -o ours.off` (defaults otherwise),
  - `sdfcage_alphawrap MESH -o wrap.off` (CGAL::alpha_wrap_3, alpha = diag/20, offset = diag/600),
keeps the fastest wall-clock time of each (process start, reading and writing included), then
judges both outputs with the same independent judge, `sdfcage --check MESH CAGE`: strict
enclosure, clearance, Hausdorff cage->input (relative to the input's bounding-box diagonal),
genus. It prints one table row per mesh with the time ratio ours / alpha wrap and writes the table
to OUT/peer.md and OUT/peer.csv.
"""
import argparse
import csv
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from cage_benchmark import SOURCE, fmt, meshes_from, read_json, run_measured  # noqa: E402

COLUMNS = [
    ("mesh", "mesh"), ("faces", "input faces"),
    ("ours_s", "ours s"), ("wrap_s", "alpha wrap s"), ("ratio", "ours / wrap"),
    ("ours_vertices", "ours vertices"), ("wrap_vertices", "wrap vertices"),
    ("ours_h", "ours H cage→input"), ("wrap_h", "wrap H cage→input"),
    ("ours_clearance", "ours clearance"), ("wrap_clearance", "wrap clearance"),
    ("input_genus", "input genus"), ("ours_genus", "ours genus"), ("wrap_genus", "wrap genus"),
    ("ours_encloses", "ours encloses"), ("wrap_encloses", "wrap encloses"),
]


def judge(sdfcage, mesh, cage, report, timeout):
    subprocess.run([sdfcage, "--check", mesh, cage, "--report", report, "--quiet"],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=timeout)
    return read_json(report)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("meshes", nargs="*")
    parser.add_argument("--vertices", type=int, default=500)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--sdfcage", default=os.path.join(SOURCE, "build", "bin", "sdfcage"))
    parser.add_argument("--alphawrap", default=os.path.join(SOURCE, "build", "bin", "sdfcage_alphawrap"))
    parser.add_argument("--alpha-ratio", type=float, default=20.0)
    parser.add_argument("--offset-ratio", type=float, default=600.0)
    parser.add_argument("--out", default="peer_benchmark")
    parser.add_argument("--timeout", type=float, default=600.0)
    args = parser.parse_args()

    meshes = meshes_from(args.meshes or [os.path.join(SOURCE, "..", "shared", "data")])
    if not meshes:
        print("no mesh to benchmark (give files, or put ../shared/data beside the source)", file=sys.stderr)
        return 2
    for tool in (args.sdfcage, args.alphawrap):
        if not os.access(tool, os.X_OK):
            print("%s: not an executable (build with SDFCAGE_BUILD_TESTING=ON)" % tool, file=sys.stderr)
            return 2
    work = os.path.join(args.out, "outputs")
    os.makedirs(work, exist_ok=True)
    rows = []
    for mesh in meshes:
        stem = os.path.splitext(os.path.basename(mesh))[0]
        ours = os.path.join(work, stem + "_sdfcage.off")
        wrap = os.path.join(work, stem + "_alphawrap.off")
        ours_cmd = [args.sdfcage, mesh, "-n", str(args.vertices), "-o", ours, "--quiet"]
        wrap_cmd = [args.alphawrap, mesh, "-o", wrap, "--alpha-ratio", str(args.alpha_ratio),
                    "--offset-ratio", str(args.offset_ratio)]
        times = {"ours": None, "wrap": None}
        failed = {}
        for _ in range(args.repeat):
            for key, command in (("ours", ours_cmd), ("wrap", wrap_cmd)):
                if key in failed:
                    continue
                code, _, seconds, err = run_measured(command, args.timeout)
                if code != 0:
                    failed[key] = "exit %d %s" % (code, err.strip().splitlines()[-1] if err.strip() else "")
                    continue
                times[key] = seconds if times[key] is None else min(times[key], seconds)
        q_ours = judge(args.sdfcage, mesh, ours, os.path.join(work, stem + "_sdfcage.json"), args.timeout) \
            if "ours" not in failed else {}
        q_wrap = judge(args.sdfcage, mesh, wrap, os.path.join(work, stem + "_alphawrap.json"), args.timeout) \
            if "wrap" not in failed else {}
        row = {"mesh": stem, "faces": (q_ours or q_wrap).get("InputTriangles"),
               "ours_s": times["ours"], "wrap_s": times["wrap"],
               "ratio": times["ours"] / times["wrap"] if times["ours"] and times["wrap"] else None,
               "ours_vertices": q_ours.get("CagePoints"), "wrap_vertices": q_wrap.get("CagePoints"),
               "ours_h": q_ours.get("HausdorffCageToInputRelative"),
               "wrap_h": q_wrap.get("HausdorffCageToInputRelative"),
               "ours_clearance": q_ours.get("MinimumClearanceRelative"),
               "wrap_clearance": q_wrap.get("MinimumClearanceRelative"),
               "input_genus": (q_ours or q_wrap).get("InputGenus"),
               "ours_genus": q_ours.get("CageGenus"), "wrap_genus": q_wrap.get("CageGenus"),
               "ours_encloses": q_ours.get("Encloses") if q_ours else failed.get("ours"),
               "wrap_encloses": q_wrap.get("Encloses") if q_wrap else failed.get("wrap")}
        rows.append(row)
        print("%-24s ours %7s s  alpha wrap %7s s  ratio %6s  H %7s / %7s  encloses %s / %s" % (
            stem, fmt(row["ours_s"], 3), fmt(row["wrap_s"], 3), fmt(row["ratio"], 3), fmt(row["ours_h"], 3),
            fmt(row["wrap_h"], 3), fmt(row["ours_encloses"]), fmt(row["wrap_encloses"])), flush=True)

    with open(os.path.join(args.out, "peer.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=[k for k, _ in COLUMNS])
        writer.writeheader()
        writer.writerows(rows)
    with open(os.path.join(args.out, "peer.md"), "w") as f:
        f.write("| " + " | ".join(h for _, h in COLUMNS) + " |\n")
        f.write("|" + "---|" * len(COLUMNS) + "\n")
        for r in rows:
            f.write("| " + " | ".join(fmt(r[k], 3) for k, _ in COLUMNS) + " |\n")
    print("table: %s" % os.path.join(args.out, "peer.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())

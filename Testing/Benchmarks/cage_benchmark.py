"""SDFCage benchmark: cages of many meshes at several sizes, judged by the quality filter.

    /usr/bin/python3 Testing/Benchmarks/cage_benchmark.py [MESH|FOLDER ...] [--builtin]
        [--vertices 200 500 1000] [--optimize none mips] [--out benchmark] [--sdfcage build/bin/sdfcage]
        [--timeout SECONDS] [--no-plots] [--no-gallery] [--replot]

Default: every mesh of ../shared/data (next to the source tree). For each mesh and each vertex
count it runs `sdfcage MESH -n N` (its own process: peak memory is per run), then
`sdfcage --check MESH CAGE` (vtkCageQualityFilter), and writes into the output folder:

- results.csv and results.md: input faces, time per stage, total time, peak memory, vertices
  reached, clearance, Hausdorff both ways, mean distance (relative to the input's bounding-box
  diagonal), genus kept, verdict;
- plots/<mesh>_distances.png: the cage-vertex distances to the input sorted in descending order
  (paper Fig. 2 style), one curve per vertex count; plots/time_vs_faces.png: total time against
  input faces on log-log axes with the fitted exponent (matplotlib);
- gallery/<mesh>.png: the input and its largest cage (VTK offscreen; needs an X server, e.g.
  run the script under `xvfb-run -a`).

--replot redraws the plots and the gallery from an earlier run's output folder (results.csv and
cages/) without computing anything. Meshes the program rejects (open, non-manifold, ...) appear
with their exit code and status. `--optimize none mips` (the default) runs every cage without and
with the optimization (paper section 3.3); the table has one row per variant.
"""
import argparse
import csv
import datetime
import json
import os
import platform
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.normpath(os.path.join(HERE, "..", ".."))
MESH_EXTENSIONS = (".off", ".obj", ".ply", ".stl", ".vtp", ".vtk")

COLUMNS = [
    ("mesh", "mesh"), ("faces", "input faces"), ("target", "N"), ("optimize", "optimize"),
    ("reached", "vertices"), ("exit", "exit"), ("status", "status"),
    ("active_points", "active points"), ("t_active_points", "active points s"),
    ("t_validation", "validation s"), ("t_distance_field", "SDF s"), ("t_isosurface", "isosurface s"),
    ("t_verification", "verification s"), ("t_simplification", "simplification s"),
    ("t_cage_verification", "cage check s"), ("t_optimization", "optimization s"),
    ("energy_before", "energy before"), ("energy_after", "energy after"),
    ("t_total", "total s"), ("peak_mb", "peak MB"),
    ("clearance_rel", "clearance"), ("hausdorff_cage_input_rel", "H cage→input"),
    ("hausdorff_input_cage_rel", "H input→cage"), ("mean_distance_rel", "mean dist."),
    ("input_genus", "input genus"), ("cage_genus", "cage genus"), ("genus_kept", "genus kept"),
    ("encloses", "encloses"), ("t_quality", "quality s"),
]


def run_measured(command, timeout):
    """Runs command; returns (exit code, peak resident memory in MB, seconds, stderr).

    Waits for the process itself (wait4 blocks until it ends; a timer kills it at the timeout):
    polling every 50 ms rounded each time up to the next poll, half the time of a 0.1 s run."""
    start = time.monotonic()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    killed = threading.Event()

    def kill():
        killed.set()
        process.kill()

    timer = threading.Timer(timeout, kill)
    timer.start()
    # stderr is read on a thread: a chatty process must not block on a full pipe
    chunks = []
    reader = threading.Thread(target=lambda: chunks.append(process.stderr.read()))
    reader.start()
    try:
        _, status, usage = os.wait4(process.pid, 0)
        seconds = time.monotonic() - start
    finally:
        timer.cancel()
    reader.join()
    err = b"".join(chunks).decode(errors="replace")
    if killed.is_set():
        return -1, usage.ru_maxrss / 1024.0, seconds, "timeout"
    process.returncode = os.waitstatus_to_exitcode(status)
    return process.returncode, usage.ru_maxrss / 1024.0, seconds, err


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def meshes_from(arguments):
    found = []
    for item in arguments:
        if os.path.isdir(item):
            for name in sorted(os.listdir(item)):
                if name.lower().endswith(MESH_EXTENSIONS):
                    found.append(os.path.join(item, name))
        elif os.path.isfile(item):
            found.append(item)
        else:
            print("warning: %s: no such file or folder" % item, file=sys.stderr)
    return found


def fmt(value, digits=4):
    if value is None or value == "":
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "%.*g" % (digits, value)
    return str(value)


def cage_distances(path):
    """DistanceToInput of the points of a .vtp cage, or [] (needs ParaView's VTK)."""
    try:
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    except ImportError:
        return []
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    array = reader.GetOutput().GetPointData().GetArray("DistanceToInput")
    if array is None:
        return []
    return [array.GetValue(i) for i in range(array.GetNumberOfTuples())]


def make_plots(rows, distances, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy
    except ImportError:
        print("no matplotlib: no plots", file=sys.stderr)
        return []
    os.makedirs(os.path.join(out, "plots"), exist_ok=True)
    written = []
    for mesh in sorted({r["mesh"] for r in rows}):
        curves = [(n, d) for (m, n), d in sorted(distances.items()) if m == mesh and d]
        if not curves:
            continue
        fig, ax = plt.subplots(figsize=(6, 4))
        for n, d in curves:
            ax.plot(range(len(d)), sorted(d, reverse=True), label="%d vertices" % n)
        ax.set_xlabel("cage vertex (sorted)")
        ax.set_ylabel("distance to the input (input units)")
        ax.set_title("%s: cage-vertex distances" % mesh)
        ax.legend()
        fig.tight_layout()
        path = os.path.join(out, "plots", "%s_distances.png" % mesh)
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written.append(path)
    ok = [r for r in rows if r.get("exit") == 0 and r.get("t_total")]
    if ok:
        fig, ax = plt.subplots(figsize=(6, 4))
        title = []
        for n in sorted({r["target"] for r in ok}):
            sel = [r for r in ok if r["target"] == n]
            x = numpy.array([r["faces"] for r in sel], dtype=float)
            y = numpy.array([r["t_total"] for r in sel], dtype=float)
            points, = ax.loglog(x, y, "o", label="N = %d" % n)
            if len(sel) >= 2 and len(set(x)) >= 2:
                slope, intercept = numpy.polyfit(numpy.log(x), numpy.log(y), 1)
                xs = numpy.linspace(x.min(), x.max(), 20)
                ax.loglog(xs, numpy.exp(intercept) * xs ** slope, "-", alpha=0.5,
                          color=points.get_color())
                title.append("N=%d: t ~ F^%.2f" % (n, slope))
        ax.set_xlabel("input faces F")
        ax.set_ylabel("total time (s)")
        ax.set_title("; ".join(title) if title else "total time")
        ax.legend()
        fig.tight_layout()
        path = os.path.join(out, "plots", "time_vs_faces.png")
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written.append(path)
    return written


def gallery(mesh_path, cage_path, png):
    """Input (grey) and cage coloured by DistanceToInput, translucent, offscreen."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkRenderingCore import (vtkActor, vtkPolyDataMapper, vtkRenderer,
                                             vtkRenderWindow, vtkWindowToImageFilter)
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
    sys.path.insert(0, os.path.join(SOURCE, "build", "lib", "python3", "dist-packages"))
    import vtk  # noqa: F401
    import sdfcage
    from vtkmodules.vtkIOGeometry import vtkOBJReader, vtkSTLReader
    from vtkmodules.vtkIOPLY import vtkPLYReader
    readers = {".off": sdfcage.vtkOFFReader, ".obj": vtkOBJReader, ".ply": vtkPLYReader,
               ".stl": vtkSTLReader, ".vtp": vtkXMLPolyDataReader}
    ext = os.path.splitext(mesh_path)[1].lower()
    if ext not in readers:
        return False
    mesh = readers[ext]()
    mesh.SetFileName(mesh_path)
    cage = vtkXMLPolyDataReader()
    cage.SetFileName(cage_path)
    cage.Update()
    renderer = vtkRenderer()
    renderer.SetBackground(1, 1, 1)
    mm = vtkPolyDataMapper()
    mm.SetInputConnection(mesh.GetOutputPort())
    mm.ScalarVisibilityOff()
    ma = vtkActor()
    ma.SetMapper(mm)
    ma.GetProperty().SetColor(0.75, 0.75, 0.75)
    renderer.AddActor(ma)
    cm = vtkPolyDataMapper()
    cm.SetInputConnection(cage.GetOutputPort())
    cm.SetScalarModeToUsePointFieldData()
    cm.SelectColorArray("DistanceToInput")
    array = cage.GetOutput().GetPointData().GetArray("DistanceToInput")
    if array is not None:
        cm.SetScalarRange(array.GetRange())
    cm.GetLookupTable().SetHueRange(0.667, 0.0)
    ca = vtkActor()
    ca.SetMapper(cm)
    ca.GetProperty().SetOpacity(0.4)
    ca.GetProperty().EdgeVisibilityOn()
    renderer.AddActor(ca)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(800, 600)
    window.AddRenderer(renderer)
    renderer.ResetCamera()
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    writer = vtkPNGWriter()
    writer.SetFileName(png)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    window.Finalize()
    return True


def write_tables(rows, out):
    with open(os.path.join(out, "results.csv"), "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow([key for key, _ in COLUMNS])
        for row in rows:
            writer.writerow([row.get(key, "") if row.get(key) is not None else "" for key, _ in COLUMNS])
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    with open(os.path.join(out, "results.md"), "w") as f:
        f.write("Machine: %s, %d cores, %s; %s. Distances relative to the input's bounding-box "
                "diagonal; times in seconds.\n\n" % (cpu, os.cpu_count() or 0, platform.platform(),
                                                      datetime.date.today().isoformat()))
        f.write("| " + " | ".join(title for _, title in COLUMNS) + " |\n")
        f.write("|" + "---|" * len(COLUMNS) + "\n")
        for row in rows:
            f.write("| " + " | ".join(fmt(row.get(key)) for key, _ in COLUMNS) + " |\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="*", help="meshes or folders (default: ../shared/data)")
    parser.add_argument("--builtin", action="store_true", help="also the built-in shape")
    parser.add_argument("--vertices", type=int, nargs="+", default=[200, 500, 1000])
    parser.add_argument("--optimize", nargs="+", default=["none", "mips"], choices=["none", "mips", "spacing"],
                        help="variants: without optimization and with each energy (none mips)")
    parser.add_argument("--out", default="benchmark", help="output folder (benchmark)")
    parser.add_argument("--sdfcage", default=os.path.join(SOURCE, "build", "bin", "sdfcage"))
    parser.add_argument("--timeout", type=float, default=1800, help="seconds per cage run")
    parser.add_argument("--no-plots", action="store_true")
    parser.add_argument("--no-gallery", action="store_true")
    parser.add_argument("--replot", action="store_true", help="only redraw plots and gallery")
    args = parser.parse_args()

    inputs = args.inputs
    if not inputs and not args.builtin:
        inputs = [os.path.normpath(os.path.join(SOURCE, "..", "shared", "data"))]
    meshes = meshes_from(inputs) + (["builtin"] if args.builtin else [])
    if not meshes:
        print("no meshes", file=sys.stderr)
        return 2
    for sub in ("cages", "reports"):
        os.makedirs(os.path.join(args.out, sub), exist_ok=True)

    rows, distances = [], {}
    if args.replot:
        with open(os.path.join(args.out, "results.csv")) as f:
            for row in csv.DictReader(f):
                for key in row:
                    try:
                        row[key] = int(row[key])
                    except ValueError:
                        try:
                            row[key] = float(row[key])
                        except ValueError:
                            pass
                rows.append(row)
        for row in rows:
            cage = os.path.join(args.out, "cages", "%s_%d.vtp" % (row["mesh"], row["target"]))
            if row.get("exit") == 0 and os.path.isfile(cage):
                distances[(row["mesh"], row["target"])] = cage_distances(cage)
        meshes = [m for m in meshes if m == "builtin" or
                  os.path.splitext(os.path.basename(m))[0] in {r["mesh"] for r in rows}]
    for mesh in ([] if args.replot else meshes):
        stem = "builtin" if mesh == "builtin" else os.path.splitext(os.path.basename(mesh))[0]
        for n, variant in [(n, v) for n in args.vertices for v in args.optimize]:
            suffix = "" if variant == "none" else "_" + variant
            cage = os.path.join(args.out, "cages", "%s_%d%s.vtp" % (stem, n, suffix))
            report = os.path.join(args.out, "reports", "%s_%d%s.json" % (stem, n, suffix))
            check = os.path.join(args.out, "reports", "%s_%d%s_check.json" % (stem, n, suffix))
            command = [args.sdfcage] + ([] if mesh == "builtin" else [mesh]) + [
                "-n", str(n), "-o", cage, "--report", report, "--quiet", "--optimize", variant]
            code, peak, seconds, err = run_measured(command, args.timeout)
            r = read_json(report)
            row = {"mesh": stem, "faces": r.get("InputTriangles"), "target": n, "optimize": variant,
                   "active_points": r.get("NumberOfActivePoints"), "t_active_points": r.get("ActivePointTime"),
                   "t_optimization": r.get("OptimizationTime") if variant != "none" else None,
                   "energy_before": r.get("EnergyBefore") if variant != "none" else None,
                   "energy_after": r.get("EnergyAfter") if variant != "none" else None,
                   "reached": r.get("VerticesReached"), "exit": code, "status": r.get("Status", err.strip()[:60]),
                   "t_validation": r.get("ValidationTime"), "t_distance_field": r.get("DistanceFieldTime"),
                   "t_isosurface": r.get("IsosurfaceTime"), "t_verification": r.get("VerificationTime"),
                   "t_simplification": r.get("SimplificationTime"),
                   "t_cage_verification": r.get("CageVerificationTime"), "t_total": r.get("TotalTime"),
                   "peak_mb": round(peak, 1)}
            if code == 0 and mesh != "builtin":
                subprocess.run([args.sdfcage, "--check", mesh, cage, "--report", check, "--quiet"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=args.timeout)
            elif code == 0:
                # the built-in shape has no file: judge the cage against the program's own report
                check = None
            q = read_json(check) if check else {}
            row.update({"clearance_rel": q.get("MinimumClearanceRelative"),
                        "hausdorff_cage_input_rel": q.get("HausdorffCageToInputRelative"),
                        "hausdorff_input_cage_rel": q.get("HausdorffInputToCageRelative"),
                        "mean_distance_rel": q.get("MeanDistanceCageToInputRelative"),
                        "input_genus": q.get("InputGenus"), "cage_genus": q.get("CageGenus"),
                        "genus_kept": (q.get("InputGenus") == q.get("CageGenus")) if q else None,
                        "encloses": q.get("Encloses") if q else (r.get("EnclosureVerified") if code == 0 else False),
                        "t_quality": q.get("QualityTime")})
            rows.append(row)
            if code == 0 and variant == "none":
                distances[(stem, n)] = cage_distances(cage)
            print("%-22s N=%-5d %-8s exit %d  %6.1f s  %7.1f MB  encloses %s" % (
                stem, n, variant, code, seconds, peak, fmt(row["encloses"])), flush=True)

    if not args.replot:
        write_tables(rows, args.out)

    written = [] if args.no_plots else make_plots(rows, distances, args.out)
    if not args.no_gallery:
        os.makedirs(os.path.join(args.out, "gallery"), exist_ok=True)
        for mesh in meshes:
            if mesh == "builtin":
                continue
            stem = os.path.splitext(os.path.basename(mesh))[0]
            sizes = [n for n in args.vertices if (stem, n) in distances]
            if sizes:
                png = os.path.join(args.out, "gallery", "%s.png" % stem)
                cage = os.path.join(args.out, "cages", "%s_%d.vtp" % (stem, max(sizes)))
                if gallery(mesh, cage, png):
                    written.append(png)
    print("wrote %s, %s%s" % (os.path.join(args.out, "results.csv"), os.path.join(args.out, "results.md"),
                              "".join(", " + w for w in written)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

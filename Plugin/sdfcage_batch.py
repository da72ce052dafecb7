"""sdfcage_batch.py: cages of many meshes, spread over the MPI ranks of a pvbatch run.

    mpiexec -np K pvbatch --symmetric sdfcage_batch.py FOLDER|LIST.txt [...] -o OUTDIR [options]
    pvbatch sdfcage_batch.py FOLDER -o OUTDIR            (one rank)
    /usr/bin/python3 sdfcage_batch.py FOLDER -o OUTDIR   (one process, no ParaView needed)

Every rank runs this script (pvbatch --symmetric). Rank 0 lists the meshes (the files of the
folders with a mesh extension, or the paths of a list file, one per line), orders them largest
file first and hands them out one at a time, on request, to every rank including itself: a slow
mesh keeps one rank busy while the others go on. Each mesh is caged by the `sdfcage` program in a
child process (a crash or a time-out costs that mesh only), which writes
OUTDIR/cages/<mesh>.vtp and the JSON report OUTDIR/reports/<mesh>.json; the rank then writes the
mesh's record OUTDIR/reports/<mesh>.batch.json. A bad mesh never stops the batch: its error is
recorded. When every mesh is done, rank 0 writes the summary OUTDIR/summary.csv and
OUTDIR/summary.md (mesh, faces, target, vertices reached, time, verdict, error, rank) and
OUTDIR/cages.vtpc, a vtkPartitionedDataSetCollection of every cage made (one partitioned data set
per mesh, named after it) to open in ParaView.

Resume: run the same command again. A mesh whose record exists (and, when it was caged, whose
cage exists) is not redone; meshes interrupted on the way have no record and are redone.
--retry-failed redoes the meshes whose verdict was not "verified"; --summary-only rebuilds the
tables and the collection from the records.

OUTDIR must be visible to every rank (one file system, as on a cluster's shared storage).
Communication: ParaView's vtkMultiProcessController (MPI) - requests and answers between rank 0
and the others, and barriers.
"""
import argparse
import csv
import json
import os
import signal
import subprocess
import sys
import time

MESH_EXTENSIONS = (".off", ".obj", ".ply", ".stl", ".vtp", ".vtk")
TAG_REQUEST, TAG_ANSWER = 8801, 8802
RECORD_FIELDS = ["mesh", "file", "faces", "target", "vertices", "time_s", "verdict", "error", "rank", "cage"]


# --- MPI through ParaView's controller (a single process without it) -------------------------------
class Ranks:
    def __init__(self):
        self.controller = None
        try:
            from vtkmodules.vtkParallelCore import vtkMultiProcessController
            try:
                # before the controller is first wrapped: then it is a vtkMPIController (Iprobe)
                from vtkmodules import vtkParallelMPI  # noqa: F401
            except ImportError:
                pass
            c = vtkMultiProcessController.GetGlobalController()
            if c is not None and c.GetNumberOfProcesses() > 1:
                self.controller = c
                self.any_source = vtkMultiProcessController.ANY_SOURCE
        except ImportError:
            pass
        self.rank = self.controller.GetLocalProcessId() if self.controller else 0
        self.size = self.controller.GetNumberOfProcesses() if self.controller else 1

    def barrier(self):
        if self.controller:
            self.controller.Barrier()

    def send(self, values, dest, tag):
        from vtkmodules.vtkCommonCore import vtkIntArray
        a = vtkIntArray()
        for v in values:
            a.InsertNextValue(int(v))
        self.controller.Send(a, dest, tag)

    def receive(self, source, tag):
        from vtkmodules.vtkCommonCore import vtkIntArray
        a = vtkIntArray()
        self.controller.Receive(a, source, tag)
        return [a.GetValue(i) for i in range(a.GetNumberOfValues())]

    def pending(self, tag):
        """Whether a message with `tag` waits (from any rank)."""
        import array
        flag, source = array.array("i", [0]), array.array("i", [0])
        self.controller.Iprobe(self.any_source, tag, flag, source)
        return bool(flag[0])

    def broadcast_int(self, value):
        if not self.controller:
            return value
        from vtkmodules.vtkCommonCore import vtkIntArray
        a = vtkIntArray()
        a.SetNumberOfValues(1)
        a.SetValue(0, int(value))
        self.controller.Broadcast(a, 0)
        return a.GetValue(0)


# --- the meshes --------------------------------------------------------------------------------------
def read_costs(path):
    """Per-mesh times (seconds) from an earlier run's summary.csv, keyed by file path and by name."""
    costs = {}
    if not path:
        return costs
    base = os.path.dirname(os.path.abspath(path))
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            try:
                t = float(row.get("time_s") or "")
            except ValueError:
                continue
            if row.get("mesh"):
                costs[row["mesh"]] = t
            if row.get("file"):
                costs[os.path.abspath(row["file"])] = t
                costs[os.path.abspath(os.path.join(base, row["file"]))] = t
    return costs


def list_meshes(inputs, recursive, order="size", costs=None):
    paths = []
    for item in inputs:
        if os.path.isdir(item):
            if recursive:
                for root, _, files in os.walk(item):
                    paths += [os.path.join(root, f) for f in sorted(files)]
            else:
                paths += [os.path.join(item, f) for f in sorted(os.listdir(item))]
        elif item.lower().endswith(".txt") or item.lower().endswith(".list"):
            base = os.path.dirname(os.path.abspath(item))
            with open(item) as f:
                for line in f:
                    line = line.strip()
                    if line and not line.startswith("#"):
                        paths.append(line if os.path.isabs(line) else os.path.join(base, line))
        else:
            paths.append(item)
    meshes = [os.path.abspath(p) for p in paths if p.lower().endswith(MESH_EXTENSIONS)]
    # one output name per mesh: the stem, with the extension when two meshes share a stem
    stems = {}
    for p in meshes:
        stems.setdefault(os.path.splitext(os.path.basename(p))[0], []).append(p)
    names = {}
    for stem, ps in stems.items():
        for i, p in enumerate(ps):
            name = stem if len(ps) == 1 else "%s_%s" % (stem, os.path.splitext(p)[1][1:].lower())
            if name in names.values():
                name = "%s_%d" % (name, i)
            names[p] = name
    size = lambda p: os.path.getsize(p) if os.path.exists(p) else 0  # noqa: E731
    if order == "list":  # as given (e.g. the slowest of an earlier run first)
        return [(names[p], p) for p in meshes]
    costs = costs or {}
    if costs:
        # slowest first by an earlier run's times; meshes it does not know go before them, largest file
        # first (a new mesh may be slow: starting it late would leave it alone at the end)
        def cost_key(p):
            t = costs.get(p, costs.get(names[p]))
            return (0, -size(p), p) if t is None else (1, -t, p)
        return [(names[p], p) for p in sorted(meshes, key=cost_key)]
    # largest first (the file size stands for the work: reading it costs nothing)
    return [(names[p], p) for p in sorted(meshes, key=lambda p: (-size(p), p))]


def record_path(out, name):
    return os.path.join(out, "reports", name + ".batch.json")


def finished(out, name, retry_failed):
    path = record_path(out, name)
    if not os.path.exists(path):
        return False
    try:
        with open(path) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return False
    if rec.get("verdict", "").startswith("verified"):
        return os.path.exists(os.path.join(out, rec.get("cage", "")))
    return not retry_failed


# --- one mesh ----------------------------------------------------------------------------------------
CURRENT_CHILD = []


def verdict_of(code, report, timed_out):
    if timed_out:
        return "timeout"
    if code == 0:
        return "verified" if report.get("TargetReached", True) else "verified, target not reached"
    return {1: "not verified", 2: "bad input", 3: "error", 130: "interrupted"}.get(
        code, "crashed (signal %d)" % -code if code < 0 else "error (exit %d)" % code)


def cage_one(name, path, args, rank):
    out = args.output
    cage_rel = os.path.join("cages", name + ".vtp")
    report_path = os.path.join(out, "reports", name + ".json")
    if os.path.exists(report_path):
        os.remove(report_path)
    cmd = [args.sdfcage, path, "-o", os.path.join(out, cage_rel), "-n", str(args.vertices), "--report", report_path,
           "--quiet", "--threads", str(args.threads)] + args.cli_arg
    start = time.time()
    timed_out = False
    with open(os.path.join(out, "logs", name + ".log"), "w") as log:
        child = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
        CURRENT_CHILD[:] = [child]
        try:
            code = child.wait(timeout=args.timeout if args.timeout > 0 else None)
        except subprocess.TimeoutExpired:
            child.kill()
            code = child.wait()
            timed_out = True
        CURRENT_CHILD[:] = []
    seconds = time.time() - start
    if not timed_out and code in (130, 143, -signal.SIGINT, -signal.SIGTERM, -signal.SIGHUP):
        # the child was interrupted with the batch (Ctrl-C, a scheduler's SIGTERM to the job's process
        # group): no record, so that a resumed batch does this mesh again
        print("[rank %d] %-28s interrupted after %.2f s: not recorded, redone on resume" % (rank, name, seconds),
              flush=True)
        return None
    report = {}
    try:
        with open(report_path) as f:
            report = json.load(f)
    except (OSError, ValueError):
        pass
    verdict = verdict_of(code, report, timed_out)
    error = report.get("ErrorMessage", "") or ""
    if not error and not verdict.startswith("verified"):
        try:
            with open(os.path.join(out, "logs", name + ".log"), errors="replace") as f:
                lines = [ln.strip() for ln in f if ln.strip()]
            error = lines[-1] if lines else ""
        except OSError:
            pass
        if timed_out:
            error = "no result within %g s" % args.timeout
    faces = report.get("InputTriangles", report.get("InputCells", ""))
    rec = {
        "mesh": name, "file": path, "faces": faces, "target": args.vertices,
        "vertices": report.get("VerticesReached", report.get("CagePoints", "")) if code == 0 else "",
        "time_s": round(seconds, 3), "verdict": verdict, "error": " ".join(str(error).split()),
        "rank": rank, "cage": cage_rel if code == 0 else "", "exit_code": code,
        "pipeline_s": report.get("TotalTime", ""), "started": start,
    }
    tmp = record_path(out, name) + ".tmp"
    with open(tmp, "w") as f:
        json.dump(rec, f, indent=1)
    os.replace(tmp, record_path(out, name))  # the record appears whole or not at all
    print("[rank %d] %-28s %-10s %7.2f s  %s" % (rank, name, verdict, seconds, rec["error"][:80]), flush=True)
    return rec


# --- hand-out ----------------------------------------------------------------------------------------
def run_root(todo, args, ranks):
    """Rank 0: hands out `todo` (largest first) on request, and cages its own share meanwhile.

    Its own mesh is caged by a child process that a helper thread waits for, so that this (main)
    thread keeps answering the other ranks' requests (only this thread calls MPI)."""
    import threading
    queue = list(range(len(todo)))
    workers_done = 0

    def answer_requests():
        nonlocal workers_done
        while ranks.controller and ranks.pending(TAG_REQUEST):
            (worker,) = ranks.receive(ranks.any_source, TAG_REQUEST)
            nxt = queue.pop(0) if queue else -1
            if nxt < 0:
                workers_done += 1
            ranks.send([nxt], worker, TAG_ANSWER)

    while queue or (ranks.controller and workers_done < ranks.size - 1):
        answer_requests()
        if not queue:
            time.sleep(0.05)
            continue
        name, path = todo[queue.pop(0)]
        t = threading.Thread(target=cage_one, args=(name, path, args, 0))
        t.start()
        while t.is_alive():
            answer_requests()
            t.join(0.05)


def run_worker(todo, args, ranks):
    while True:
        ranks.send([ranks.rank], 0, TAG_REQUEST)
        (index,) = ranks.receive(0, TAG_ANSWER)
        if index < 0:
            return
        name, path = todo[index]
        cage_one(name, path, args, ranks.rank)


# --- summary -----------------------------------------------------------------------------------------
def write_summary(meshes, args, wall, ranks_used):
    out = args.output
    rows = []
    for name, path in meshes:
        try:
            with open(record_path(out, name)) as f:
                rows.append(json.load(f))
        except (OSError, ValueError):
            rows.append({"mesh": name, "file": path, "verdict": "not done", "error": "no record (interrupted?)"})
    rows.sort(key=lambda r: r["mesh"])
    with open(os.path.join(out, "summary.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=RECORD_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in RECORD_FIELDS})
    verified = sum(1 for r in rows if str(r.get("verdict", "")).startswith("verified"))
    busy = sum(float(r.get("time_s") or 0) for r in rows)
    with open(os.path.join(out, "summary.md"), "w") as f:
        f.write("# SDFCage batch\n\n")
        run = ("rebuilt from the records" if args.summary_only
               else "this run: %d rank(s), wall %.1f s" % (ranks_used, wall))
        f.write("%d meshes, %d caged and verified, %d not; target %d vertices; %s; "
                "sum of the per-mesh times (this and earlier runs) %.1f s.\n\n"
                % (len(rows), verified, len(rows) - verified, args.vertices, run, busy))
        f.write("| mesh | faces | target | vertices | time s | verdict | error | rank |\n")
        f.write("|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            err = str(r.get("error", "")).replace("|", "/")
            f.write("| %s | %s | %s | %s | %s | %s | %s | %s |\n" % (
                r["mesh"], r.get("faces", ""), r.get("target", ""), r.get("vertices", ""), r.get("time_s", ""),
                r.get("verdict", ""), err[:160], r.get("rank", "")))
    write_collection(rows, out)
    return rows


def write_collection(rows, out):
    """cages.vtpc: one partitioned data set per caged mesh, named after it, with its record as
    field data."""
    try:
        from vtkmodules.vtkCommonCore import vtkStringArray, vtkDoubleArray
        from vtkmodules.vtkCommonDataModel import vtkPartitionedDataSet, vtkPartitionedDataSetCollection, \
            vtkCompositeDataSet
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
        try:
            from vtkmodules.vtkIOXML import vtkXMLPartitionedDataSetCollectionWriter
        except ImportError:  # VTK 9.2 (ParaView 5.11) has it in IOParallelXML
            from vtkmodules.vtkIOParallelXML import vtkXMLPartitionedDataSetCollectionWriter
    except ImportError as e:
        print("no VTK (%s): cages.vtpc not written" % e)
        return
    collection = vtkPartitionedDataSetCollection()
    caged = [r for r in rows if r.get("cage") and os.path.exists(os.path.join(out, r["cage"]))]
    cages = []
    for r in caged:
        reader = vtkXMLPolyDataReader()
        reader.SetFileName(os.path.join(out, r["cage"]))
        reader.Update()
        cage = reader.GetOutput()
        if cage.GetNumberOfPoints() == 0:
            # e.g. a cage an older sdfcage wrote with appended data into this folder, which VTK 9.1
            # cannot read with an up-to-date Debian 12's expat: left out, never an empty block
            print("%s: cannot read its cage %s: left out of cages.vtpc (delete %s and run again to "
                  "cage it again)" % (r["mesh"], r["cage"], os.path.relpath(record_path(out, r["mesh"]), out)))
            continue
        cages.append((r, cage))
    for i, (r, cage) in enumerate(cages):
        for key in ("mesh", "file", "verdict"):
            a = vtkStringArray()
            a.SetName("Batch" + key.capitalize())
            a.InsertNextValue(str(r.get(key, "")))
            cage.GetFieldData().AddArray(a)
        t = vtkDoubleArray()
        t.SetName("BatchTime")
        t.InsertNextValue(float(r.get("time_s") or 0))
        cage.GetFieldData().AddArray(t)
        pds = vtkPartitionedDataSet()
        pds.SetPartition(0, cage)
        collection.SetPartitionedDataSet(i, pds)
        collection.GetMetaData(i).Set(vtkCompositeDataSet.NAME(), r["mesh"])
    writer = vtkXMLPartitionedDataSetCollectionWriter()
    if hasattr(writer, "SetController"):
        # this writer is collective under MPI; here rank 0 alone writes the whole collection
        from vtkmodules.vtkParallelCore import vtkDummyController
        writer.SetController(vtkDummyController())
    # inline arrays, not appended ones: VTK 9.1 cannot read appended data back with the expat of
    # an up-to-date Debian 12 (Examples/CLI/CLIVTP.cxx)
    writer.SetDataModeToBinary()
    writer.SetInputData(collection)
    writer.SetFileName(os.path.join(out, "cages.vtpc"))
    writer.Write()


# --- main --------------------------------------------------------------------------------------------
def find_sdfcage(explicit):
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [explicit] if explicit else []
    candidates += [os.path.join(here, "..", "..", "..", "..", "bin", "sdfcage"),  # <prefix>/lib/paraview-5.11/plugins/SDFCage
                   os.path.join(here, "..", "build", "bin", "sdfcage")]  # the source tree's Plugin/
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return os.path.abspath(c)
    from shutil import which
    return which("sdfcage")


def parse(argv):
    ap = argparse.ArgumentParser(prog="sdfcage_batch.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("inputs", nargs="*", help="folders of meshes and/or list files (.txt: one mesh path per line)")
    ap.add_argument("-o", "--output", required=True, help="output folder (shared by every rank)")
    ap.add_argument("-n", "--vertices", type=int, default=500, help="cage vertices (default 500)")
    ap.add_argument("--threads", type=int, default=0,
                    help="threads per mesh (default: the cores of the node divided by its ranks)")
    ap.add_argument("--timeout", type=float, default=0, help="seconds per mesh before it is given up (0: none)")
    ap.add_argument("--recursive", action="store_true", help="also the meshes in sub-folders")
    ap.add_argument("--order", choices=("size", "list"), default="size",
                    help="hand-out order: largest file first (default) or as listed")
    ap.add_argument("--costs", default="",
                    help="an earlier run's summary.csv: hand out the slowest meshes of that run first "
                         "(a small file can be a slow mesh); meshes it lacks go first, largest first")
    ap.add_argument("--retry-failed", action="store_true", help="redo the meshes whose verdict was not verified")
    ap.add_argument("--summary-only", action="store_true", help="only rebuild the summary and cages.vtpc")
    ap.add_argument("--sdfcage", default="", help="the sdfcage program (default: found beside the plugin or on PATH)")
    ap.add_argument("--cli-arg", action="append", default=[],
                    help="an option passed on to sdfcage (repeat; e.g. --cli-arg=--iso=0.02)")
    return ap.parse_args(argv)


def main(argv):
    args = parse(argv)
    ranks = Ranks()
    args.output = os.path.abspath(args.output)
    args.sdfcage = find_sdfcage(args.sdfcage)
    if args.threads <= 0:
        per_node = int(os.environ.get("OMPI_COMM_WORLD_LOCAL_SIZE", os.environ.get("SLURM_NTASKS_PER_NODE", "0"))
                       .split("(")[0] or 0) or ranks.size
        args.threads = max(1, (os.cpu_count() or 1) // max(1, per_node))
    ok = 1
    if ranks.rank == 0:
        for sub in ("cages", "reports", "logs"):
            os.makedirs(os.path.join(args.output, sub), exist_ok=True)
        if not args.sdfcage and not args.summary_only:
            print("sdfcage_batch: the sdfcage program was not found (pass --sdfcage)", file=sys.stderr)
            ok = 0
    if not ranks.broadcast_int(ok):
        return 2
    try:
        costs = read_costs(args.costs) if args.order == "size" else {}
    except (OSError, csv.Error) as e:
        if ranks.rank == 0:
            print("sdfcage_batch: cannot read --costs %s: %s" % (args.costs, e), file=sys.stderr)
        return 2
    meshes = list_meshes(args.inputs, args.recursive, args.order, costs)  # every rank lists the same, in the same order
    todo = [] if args.summary_only else [m for m in meshes if not finished(args.output, m[0], args.retry_failed)]
    if ranks.rank == 0:
        print("sdfcage_batch: %d meshes, %d to do (%d already done), %d rank(s), %d thread(s) per mesh, program %s"
              % (len(meshes), len(todo), len(meshes) - len(todo), ranks.size, args.threads, args.sdfcage), flush=True)
    ranks.barrier()
    start = time.time()
    if ranks.rank == 0:
        run_root(todo, args, ranks)
    else:
        run_worker(todo, args, ranks)
    ranks.barrier()
    wall = time.time() - start
    if ranks.rank == 0:
        rows = write_summary(meshes, args, wall, ranks.size)
        verified = sum(1 for r in rows if str(r.get("verdict", "")).startswith("verified"))
        print("sdfcage_batch: done in %.1f s wall on %d rank(s): %d of %d meshes caged and verified; %s"
              % (wall, ranks.size, verified, len(rows), os.path.join(args.output, "summary.md")), flush=True)
    return 0


def on_term(signum, frame):
    for child in CURRENT_CHILD:
        child.kill()
    sys.exit(128 + signum)


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, on_term)
    # pvbatch passes its own options before the script's: keep those after the script name
    try:
        code = main(sys.argv[1:])
    except SystemExit as e:  # argparse: --help, a bad option (every rank parses the same)
        code = e.code if isinstance(e.code, int) else 2
    except BaseException:
        # one rank failing must not leave the others waiting for it: end the whole job
        import traceback
        traceback.print_exc()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(3)
    sys.stdout.flush()
    if code:
        sys.exit(code)

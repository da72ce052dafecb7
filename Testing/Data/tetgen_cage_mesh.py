"""SDFCage: our cages are ready for a tet mesher (issue 15, part 4).

For one mesh: build its 500-vertex cage with `sdfcage` (plain, and with --optimize mips), write
cage and input as one piecewise linear complex (TetGen's .smesh: the cage's triangles, the
input's triangles, and one hole point inside each closed component of the input, so that only
the space between them is meshed), run `tetgen -pQ` and assert that it succeeds: exit code 0, a
.ele file with tetrahedra, and (where every hole point was found) tetrahedra whose volumes add up
to the cage's volume minus the input's.

Run: python3 tetgen_cage_mesh.py --sdfcage build/bin/sdfcage --tetgen /usr/bin/tetgen \
         --out WORKDIR MESH.off
Exit code 0 passed, 1 failed, 125 skipped (no mesh file, no tetgen).
"""
import argparse
import os
import shutil
import subprocess
import sys
import time

import numpy as np


def read_off(path):
    with open(path) as f:
        words = []
        for line in f:
            line = line.split("#")[0]
            words.extend(line.split())
    if not words[0].upper().endswith("OFF"):
        raise ValueError("%s: not an OFF file" % path)
    nv, nf = int(words[1]), int(words[2])
    at = 4
    points = np.array(words[at:at + 3 * nv], dtype=float).reshape(nv, 3)
    at += 3 * nv
    triangles = []
    for _ in range(nf):
        k = int(words[at])
        ids = [int(w) for w in words[at + 1:at + 1 + k]]
        at += 1 + k
        for i in range(1, k - 1):  # fan
            triangles.append((ids[0], ids[i], ids[i + 1]))
    return points, np.array(triangles, dtype=np.int64)


def winding_number(points, triangles, q):
    """Generalized winding number of a triangle mesh at q (Van Oosterom-Strackee solid angles)."""
    a = points[triangles[:, 0]] - q
    b = points[triangles[:, 1]] - q
    c = points[triangles[:, 2]] - q
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la + \
        np.einsum("ij,ij->i", c, a) * lb
    return np.sum(2.0 * np.arctan2(det, den)) / (4.0 * np.pi)


def components(n, triangles):
    parent = list(range(n))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for t in triangles:
        ra = find(t[0])
        for v in t[1:]:
            rb = find(v)
            if ra != rb:
                parent[rb] = ra
    labels = np.array([find(t[0]) for t in triangles])
    return [np.nonzero(labels == r)[0] for r in np.unique(labels)]


def hole_points(points, triangles):
    """One point strictly inside each component of the input (a component alone winds once
    around it), from a triangle's centroid stepped inward; components where none is found get
    none (TetGen then meshes their inside too, which is still a valid test)."""
    diag = np.linalg.norm(points.max(axis=0) - points.min(axis=0))
    holes = []
    for faces in components(len(points), triangles):
        tri = triangles[faces]
        p0, p1, p2 = points[tri[:, 0]], points[tri[:, 1]], points[tri[:, 2]]
        normals = np.cross(p1 - p0, p2 - p0)
        areas = np.linalg.norm(normals, axis=1)
        order = np.argsort(-areas)[:20]
        for j in order:
            centroid = (p0[j] + p1[j] + p2[j]) / 3.0
            n = normals[j] / areas[j]
            for step in (1e-3, 1e-4, 1e-5):
                q = centroid - step * diag * n
                w = winding_number(points, tri, q)
                if abs(w - 1.0) < 1e-3 and abs(winding_number(points, triangles, q) - 1.0) < 1e-3:
                    holes.append(q)
                    break
            else:
                continue
            break
    return holes


def signed_volume(points, triangles):
    a, b, c = points[triangles[:, 0]], points[triangles[:, 1]], points[triangles[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def read_table(path):
    with open(path) as f:
        rows = [line.split() for line in f if line.strip() and not line.lstrip().startswith("#")]
    return rows[1:1 + int(rows[0][0])]


def tet_volume(node_path, ele_path):
    nodes = {int(r[0]): np.array([float(v) for v in r[1:4]]) for r in read_table(node_path)}
    total = 0.0
    for r in read_table(ele_path):
        p = [nodes[int(v)] for v in r[1:5]]
        total += abs(np.dot(p[1] - p[0], np.cross(p[2] - p[0], p[3] - p[0]))) / 6.0
    return total


def flat_wedges(points, triangles, min_dihedral=179.9):
    """Edges of a closed mesh whose two triangles are within 180 - min_dihedral degrees of
    coplanar, and the sum over them of the volume of the tetrahedron their four corners span.
    TetGen 1.5's -p merges adjacent facets that flat (its default facet angle tolerance, 0.1
    degree) and triangulates the merged facet with its own diagonals: the meshed domain then
    differs from the PLC by such wedges (-M keeps every facet as given)."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    edges = {}
    for i, t in enumerate(triangles):
        for k in range(3):
            edges.setdefault(tuple(sorted((t[k], t[(k + 1) % 3]))), []).append((i, t[(k + 2) % 3]))
    count, volume = 0, 0.0
    for (u, v), faces in edges.items():
        if len(faces) != 2:
            continue
        cosine = np.clip(np.dot(n[faces[0][0]], n[faces[1][0]]), -1.0, 1.0)
        if 180.0 - np.degrees(np.arccos(cosine)) > min_dihedral:
            p = [points[u], points[v], points[faces[0][1]], points[faces[1][1]]]
            volume += abs(np.dot(p[1] - p[0], np.cross(p[2] - p[0], p[3] - p[0]))) / 6.0
            count += 1
    return count, volume


def write_smesh(path, cage, mesh, holes):
    cp, ct = cage
    mp, mt = mesh
    with open(path, "w") as f:
        f.write("# SDFCage: cage and input as one PLC\n%d 3 0 0\n" % (len(cp) + len(mp)))
        for i, p in enumerate(np.vstack([cp, mp])):
            f.write("%d %.17g %.17g %.17g\n" % (i, p[0], p[1], p[2]))
        f.write("%d 0\n" % (len(ct) + len(mt)))
        for t in ct:
            f.write("3 %d %d %d\n" % tuple(t))
        for t in mt + len(cp):
            f.write("3 %d %d %d\n" % tuple(t))
        f.write("%d\n" % len(holes))
        for i, q in enumerate(holes):
            f.write("%d %.17g %.17g %.17g\n" % (i, q[0], q[1], q[2]))
        f.write("0\n")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("mesh")
    parser.add_argument("--sdfcage", required=True)
    parser.add_argument("--tetgen", default="tetgen")
    parser.add_argument("--out", required=True)
    parser.add_argument("--vertices", type=int, default=500)
    args = parser.parse_args()
    if not os.path.isfile(args.mesh):
        print("SKIPPED: no mesh %s" % args.mesh)
        return 125
    tetgen = shutil.which(args.tetgen)
    if tetgen is None:
        print("SKIPPED: no tetgen (apt-get install tetgen; .ci/setup.sh --tests installs it)")
        return 125
    os.makedirs(args.out, exist_ok=True)
    name = os.path.splitext(os.path.basename(args.mesh))[0]
    mesh = read_off(args.mesh)
    holes = hole_points(*mesh)
    print("%s: %d points, %d triangles, %d hole point(s)" % (name, len(mesh[0]), len(mesh[1]), len(holes)))
    failures = 0
    for optimize in ("none", "mips"):
        stem = os.path.join(args.out, "%s_%s" % (name, optimize))
        cage_file = stem + "_cage.off"
        cmd = [args.sdfcage, args.mesh, "-n", str(args.vertices), "--optimize", optimize, "-o", cage_file, "--quiet"]
        r = subprocess.run(cmd)
        if r.returncode != 0:
            print("FAIL: %s exited %d" % (" ".join(cmd), r.returncode))
            failures += 1
            continue
        cage = read_off(cage_file)
        smesh = stem + ".smesh"
        write_smesh(smesh, cage, mesh, holes)
        between = signed_volume(*cage) - abs(signed_volume(*mesh))
        tolerance = 1e-6 * abs(signed_volume(*cage))
        flat_edges, wedges = flat_wedges(*cage)
        # `tetgen -pQ` as a user types it, then `tetgen -pQM` (no merge of nearly coplanar facets):
        # the latter meshes exactly the PLC, so its tetrahedra must fill the space between cage
        # and input to 1e-6; the former may differ by the wedges of the cage edges it merges
        # across (a flat cage region, e.g. fertility's base: 8 edges within 0.1 degree of flat,
        # 4.1 of 59198 volume units), and by no more.
        for switches, extra in (("-pQ", wedges), ("-pQM", 0.0)):
            for old in (stem + ".1.ele", stem + ".1.node", stem + ".1.face", stem + ".1.edge"):
                if os.path.exists(old):
                    os.remove(old)
            start = time.time()
            r = subprocess.run([tetgen, switches, smesh], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            seconds = time.time() - start
            ele = stem + ".1.ele"
            tets = 0
            if os.path.exists(ele):
                with open(ele) as f:
                    tets = int(f.readline().split()[0])
            ok = r.returncode == 0 and tets > 0
            volume_note = ""
            if ok:
                # the tetrahedra fill the space between the cage and the input
                meshed = tet_volume(stem + ".1.node", ele)
                volume_ok = abs(meshed - between) <= tolerance + extra
                volume_note = ", volume %.9g (cage - input %.9g, difference %.3g, allowed %.3g: %d cage edge(s) " \
                    "within 0.1 degree of flat)" % (meshed, between, meshed - between, tolerance + extra, flat_edges)
                if len(holes) > 0 and not volume_ok:
                    ok = False
            print("%s: %s cage %d vertices: tetgen %s exit %d, %d tetrahedra, %.1f s%s" %
                  ("ok  " if ok else "FAIL", optimize, len(cage[0]), switches, r.returncode, tets, seconds, volume_note))
            if not ok:
                print(r.stdout[-2000:])
                failures += 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

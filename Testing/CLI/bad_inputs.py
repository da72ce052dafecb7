#!/usr/bin/python3
"""Hostile-input corpus for the sdfcage program (Testing/CLI/CMakeLists.txt runs each case as
its own test; label "cli").

Every case writes its input into a fresh folder, runs the program once and checks the outcome it
must have: exit code 2 with a message naming the defect, or (for odd but usable inputs) exit
code 0 with a cage that `sdfcage --check` accepts. Every run must also end quickly and small:
peak memory (the child's maximum resident set, from wait4) under MAX_RSS_MB and at most
MAX_SECONDS of wall time -- a header claiming a billion vertices must be refused before any
allocation, not after minutes of swapping. These bounds guard against hangs and runaway
allocations; they are not speed targets.

  bad_inputs.py --list
  bad_inputs.py --cli build/bin/sdfcage --workdir DIR --case NAME
"""
import argparse
import math
import os
import random
import shutil
import struct
import subprocess
import sys
import time

MAX_RSS_MB = 600
MAX_SECONDS = 120

# --- small meshes ----------------------------------------------------------------------------
CUBE_POINTS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_TRIANGLES = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
                  (2, 3, 7), (2, 7, 6), (1, 2, 6), (1, 6, 5), (3, 0, 4), (3, 4, 7)]


def off_text(points, faces, header=None):
    lines = [header if header is not None else "OFF", f"{len(points)} {len(faces)} 0"]
    lines += [" ".join(repr(float(c)) if isinstance(c, float) else str(c) for c in p) for p in points]
    lines += [" ".join(str(i) for i in (len(f),) + tuple(f)) for f in faces]
    return ("\n".join(lines) + "\n").encode()


def ply_binary(points, faces, nv=None, nf=None):
    nv = len(points) if nv is None else nv
    nf = len(faces) if nf is None else nf
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\n"
            f"property float y\nproperty float z\nelement face {nf}\n"
            "property list uchar int vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack("<3f", *p) for p in points)
    body += b"".join(struct.pack("<B", len(f)) + struct.pack(f"<{len(f)}i", *f) for f in faces)
    return head + body


def ply_ascii(points, faces, nv=None, nf=None):
    nv = len(points) if nv is None else nv
    nf = len(faces) if nf is None else nf
    text = (f"ply\nformat ascii 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n"
            f"property float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n")
    text += "".join(" ".join(str(c) for c in p) + "\n" for p in points)
    text += "".join(" ".join(str(i) for i in (len(f),) + tuple(f)) + "\n" for f in faces)
    return text.encode()


def stl_binary(points, faces, count=None):
    count = len(faces) if count is None else count
    data = b"binary STL written by bad_inputs.py".ljust(80, b" ") + struct.pack("<I", count)
    for f in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for i in f:
            data += struct.pack("<3f", *points[i])
        data += b"\0\0"
    return data


def vtk_text(points, faces, npoints=None, header_polys=None):
    npoints = len(points) if npoints is None else npoints
    text = "# vtk DataFile Version 3.0\nbad_inputs.py\nASCII\nDATASET POLYDATA\n"
    text += f"POINTS {npoints} float\n" + "".join(" ".join(str(c) for c in p) + "\n" for p in points)
    size = sum(len(f) + 1 for f in faces)
    text += (header_polys or f"POLYGONS {len(faces)} {size}") + "\n"
    text += "".join(" ".join(str(i) for i in (len(f),) + tuple(f)) + "\n" for f in faces)
    return text.encode()


def vtk_binary(points, faces, first_count=None):
    """A legacy binary POLYDATA file (big-endian); `first_count` replaces the first cell's count."""
    data = b"# vtk DataFile Version 3.0\nbad_inputs.py\nBINARY\nDATASET POLYDATA\n"
    data += b"POINTS %d float\n" % len(points) + b"".join(struct.pack(">3f", *p) for p in points) + b"\n"
    values = [v for f in faces for v in (len(f),) + tuple(f)]
    if first_count is not None:
        values[0] = first_count
    data += b"POLYGONS %d %d\n" % (len(faces), len(values)) + struct.pack(">%di" % len(values), *values) + b"\n"
    return data


def vtk5_text(points, faces, bad_offset=None):
    """A version-5.1 legacy file (OFFSETS / CONNECTIVITY); `bad_offset` replaces the second offset."""
    offsets = [0]
    for f in faces:
        offsets.append(offsets[-1] + len(f))
    if bad_offset is not None:
        offsets[1] = bad_offset
    text = "# vtk DataFile Version 5.1\nbad_inputs.py\nASCII\nDATASET POLYDATA\n"
    text += f"POINTS {len(points)} float\n" + "".join(" ".join(str(c) for c in p) + "\n" for p in points)
    text += f"POLYGONS {len(offsets)} {offsets[-1] if bad_offset is None else sum(len(f) for f in faces)}\n"
    text += "OFFSETS vtktypeint64\n" + " ".join(map(str, offsets)) + "\n"
    text += "CONNECTIVITY vtktypeint64\n" + " ".join(str(i) for f in faces for i in f) + "\n"
    return text.encode()


def obj_text(points, faces):
    text = "".join("v %r %r %r\n" % tuple(float(c) for c in p) for p in points)
    text += "".join("f " + " ".join(str(i) for i in f) + "\n" for f in faces)
    return text.encode()


def scaled_cube(scale, offset=0.0):
    return [tuple(offset + scale * c for c in p) for p in CUBE_POINTS]


def prism(sides):
    """A closed prism over a regular polygon of `sides` sides: two big polygons and quads."""
    points = []
    for z in (0.0, 1.0):
        for k in range(sides):
            a = 2 * math.pi * k / sides
            points.append((math.cos(a), math.sin(a), z))
    bottom = tuple(reversed(range(sides)))
    top = tuple(sides + k for k in range(sides))
    sides_quads = [(k, (k + 1) % sides, sides + (k + 1) % sides, sides + k) for k in range(sides)]
    return points, [bottom, top] + sides_quads


def vtp_billion():
    return (b'<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">'
            b'<PolyData><Piece NumberOfPoints="1000000000" NumberOfPolys="1"><Points>'
            b'<DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0</DataArray>'
            b'</Points><Polys><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray>'
            b'<DataArray type="Int32" Name="offsets" format="ascii">3</DataArray></Polys></Piece>'
            b'</PolyData></VTKFile>\n')


def vtp_tetrahedron(point_components=3, data_components=1):
    """A tetrahedron as ASCII VTK XML PolyData with a point data array; the components the
    Points array and the data array declare can lie."""
    return (b'<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">'
            b'<PolyData><Piece NumberOfPoints="4" NumberOfPolys="4"><PointData>'
            b'<DataArray type="Float32" Name="s" NumberOfComponents="%d" format="ascii">0 1 2 3</DataArray>'
            b'</PointData><Points><DataArray type="Float32" NumberOfComponents="%d" format="ascii">'
            b'0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points><Polys>'
            b'<DataArray type="Int32" Name="connectivity" format="ascii">0 2 1 0 1 3 0 3 2 1 2 3</DataArray>'
            b'<DataArray type="Int32" Name="offsets" format="ascii">3 6 9 12</DataArray></Polys></Piece>'
            b'</PolyData></VTKFile>\n') % (data_components, point_components)


def vtp_tetrahedron_appended(offset_lie=None, size_lie=None):
    """A tetrahedron as VTK XML PolyData with raw appended arrays (what VTK's and ParaView's
    writers write by default, and what VTK 9.1 cannot read back with an up-to-date Debian 12's
    expat: the CLI moves the arrays inline first); the third array's offset or the first array's
    byte count can lie."""
    arrays = [struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1),
              struct.pack("<12i", 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3),
              struct.pack("<4i", 3, 6, 9, 12)]
    blobs = [struct.pack("<I", len(a) if (i or size_lie is None) else size_lie) + a for i, a in enumerate(arrays)]
    offsets = [0, len(blobs[0]), len(blobs[0]) + len(blobs[1])]
    if offset_lie is not None:
        offsets[2] = offset_lie
    return (b'<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">'
            b'<PolyData><Piece NumberOfPoints="4" NumberOfPolys="4"><Points>'
            b'<DataArray type="Float32" NumberOfComponents="3" format="appended" offset="%d"/></Points><Polys>'
            b'<DataArray type="Int32" Name="connectivity" format="appended" offset="%d"/>'
            b'<DataArray type="Int32" Name="offsets" format="appended" offset="%d"/></Polys></Piece>'
            b'</PolyData><AppendedData encoding="raw">\n_' % tuple(offsets)
            + b"".join(blobs) + b'\n</AppendedData></VTKFile>\n')


def random_bytes(n, seed):
    rng = random.Random(seed)
    return bytes(rng.randrange(256) for _ in range(n))


TRIANGLE = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
FAR_CUBE = scaled_cube(1.0, 1e12)

# name -> (file name, content bytes or None (a folder) , extra args, expected exit, stderr
#          substring or None, options)
# options: "check" (the cage must pass sdfcage --check), "no_output" (no cage file may appear).
CASES = {
    # empty, header only, truncated
    "empty_off": ("m.off", b"", [], 2, "empty", {}),
    "empty_ply": ("m.ply", b"", [], 2, "empty", {}),
    "empty_stl": ("m.stl", b"", [], 2, "empty", {}),
    "empty_obj": ("m.obj", b"", [], 2, "empty", {}),
    "empty_vtp": ("m.vtp", b"", [], 2, "empty", {}),
    "empty_vtk": ("m.vtk", b"", [], 2, "empty", {}),
    "header_only_off": ("m.off", b"OFF\n", [], 2, "ends after the header", {}),
    "header_only_ply": ("m.ply", ply_ascii([], [], 8, 12), [], 2, "more than", {}),
    "header_only_ply_no_end": ("m.ply", b"ply\nformat ascii 1.0\nelement vertex 8\n", [], 2, "end_header", {}),
    "header_only_vtk": ("m.vtk", b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n", [], 2,
                        "no polygons", {}),
    "header_only_stl": ("m.stl", stl_binary([], [])[:84], [], 2, "cannot read", {}),
    "truncated_off": ("m.off", off_text(CUBE_POINTS, CUBE_TRIANGLES)[:-30], [], 2, "cannot read", {}),
    "truncated_ply_binary": ("m.ply", ply_binary(CUBE_POINTS, CUBE_TRIANGLES)[:-40], [], 2, "file ends", {}),
    "truncated_ply_ascii": ("m.ply", ply_ascii(CUBE_POINTS, CUBE_TRIANGLES)[:-30], [], 2, "cannot read", {}),
    "truncated_stl": ("m.stl", stl_binary(CUBE_POINTS, CUBE_TRIANGLES)[:-75], [], 2, "declares 12 triangles", {}),
    # header counts far larger than the file: refused before allocating
    "billion_off": ("m.off", b"OFF\n1000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", [], 2, "more than", {}),
    "billion_ply_binary": ("m.ply", ply_binary(TRIANGLE, [(0, 1, 2)], nv=1000000000), [], 2, "more than", {}),
    "billion_ply_ascii": ("m.ply", ply_ascii(TRIANGLE, [(0, 1, 2)], nv=1000000000), [], 2, "more than", {}),
    "billion_ply_faces": ("m.ply", ply_binary(TRIANGLE, [(0, 1, 2)], nf=1000000000), [], 2, "more than", {}),
    "billion_stl": ("m.stl", stl_binary(TRIANGLE, [(0, 1, 2)], count=1000000000), [], 2, "declares", {}),
    "billion_vtk_points": ("m.vtk", vtk_text(TRIANGLE, [(0, 1, 2)], npoints=1000000000), [], 2, "more than", {}),
    "billion_vtk_polys": ("m.vtk", vtk_text(TRIANGLE, [(0, 1, 2)], header_polys="POLYGONS 1000000000 4000000000"),
                          [], 2, "more than", {}),
    "billion_vtp": ("m.vtp", vtp_billion(), [], 2, "cannot read", {}),
    # negative counts
    "negative_count_off": ("m.off", b"OFF\n-8 12 0\n0 0 0\n", [], 2, "negative", {}),
    "negative_count_ply": ("m.ply", ply_ascii(CUBE_POINTS, CUBE_TRIANGLES, nv=-8), [], 2, "negative", {}),
    "negative_count_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES, npoints=-8), [], 2, "non-negative", {}),
    "negative_list_ply": ("m.ply", ply_ascii(TRIANGLE, [(0, 1, 2)]).replace(b"\n3 0 1 2", b"\n-3 0 1 2"), [], 2,
                          "claims", {}),
    # indices out of range, negative
    "index_out_of_range_off": ("m.off", off_text(CUBE_POINTS, CUBE_TRIANGLES[:-1] + [(3, 4, 99)]), [], 2,
                               "outside", {}),
    "index_negative_off": ("m.off", off_text(CUBE_POINTS, CUBE_TRIANGLES[:-1] + [(3, -1, 7)]), [], 2, "outside", {}),
    "index_out_of_range_ply": ("m.ply", ply_binary(CUBE_POINTS, CUBE_TRIANGLES[:-1] + [(3, 4, 99)]), [], 2,
                               "outside", {}),
    "index_negative_ply": ("m.ply", ply_ascii(CUBE_POINTS, CUBE_TRIANGLES[:-1] + [(3, -4, 7)]), [], 2,
                           "outside", {}),
    "index_out_of_range_obj": ("m.obj", obj_text(CUBE_POINTS, [(1, 2, 99)]), [], 2, "outside", {}),
    "index_zero_obj": ("m.obj", obj_text(CUBE_POINTS, [(0, 1, 2)]), [], 2, "not a vertex index", {}),
    "index_out_of_range_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES[:-1] + [(3, 4, 99)]), [], 2,
                               "do not exist", {}),
    "index_negative_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES[:-1] + [(3, -1, 7)]), [], 2,
                           "do not exist", {}),
    # a cell whose point count runs past its section (vtkPolyDataReader trusted it and read past
    # its buffer: a fuzzed file crashed it), in ASCII and binary legacy files
    "cell_past_section_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES, header_polys="POLYGONS 12 3"), [], 2,
                              "lists 3 points", {}),
    "cell_past_section_vtk_binary": ("m.vtk", vtk_binary(CUBE_POINTS, CUBE_TRIANGLES, first_count=900), [], 2,
                                     "lists 900 points", {}),
    # point data whose values per tuple lie (SCALARS with 1e8 components on 8 points allocated
    # 7 GB in vtkPolyDataReader, COLOR_SCALARS with 1e9 ran past 17 GB), and a lookup table of a
    # billion entries: the CLI's own legacy parser stops at POINT_DATA (a cage needs the points and
    # polygons only), so these are caged
    "scalar_components_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES)
                              + b"POINT_DATA 8\nSCALARS s float 100000000\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n",
                              ["-n", "20"], 0, None, {"check": True}),
    "color_scalars_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES)
                          + b"POINT_DATA 8\nCOLOR_SCALARS c 1000000000\n0 1 2 3 4 5 6 7\n",
                          ["-n", "20"], 0, None, {"check": True}),
    "lookup_table_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES)
                         + b"POINT_DATA 8\nSCALARS s float 1\nLOOKUP_TABLE t\n0 1 2 3 4 5 6 7\n"
                         + b"LOOKUP_TABLE t 1000000000\n0 0 0 1\n", ["-n", "20"], 0, None, {"check": True}),
    # FIELD data before the points (where vtkPolyDataReader crashed on a fuzzed file): an array
    # declaring a billion values is refused by size; keywords count in any case, as VTK reads them
    "field_array_vtk": ("m.vtk", vtk_text(CUBE_POINTS, CUBE_TRIANGLES).replace(
                        b"DATASET POLYDATA\n", b"DATASET POLYDATA\nFIELD f 1\nbig 1000 1000000 float\n1 2 3\n"),
                        [], 2, "more than", {}),
    "lowercase_billion_vtk_points": ("m.vtk", vtk_text(TRIANGLE, [(0, 1, 2)], npoints=1000000000).replace(
                                     b"POINTS", b"points"), [], 2, "more than", {}),
    # a .vtp whose Points array declares a billion components (the reader allocated 8 GB first):
    # refused; a point data array that does the same is not read at all (only points and cells
    # make the cage): caged
    "vtp_point_components": ("m.vtp", vtp_tetrahedron(point_components=1000000000), [], 2,
                             "declares 1000000000 components", {}),
    "vtp_data_components": ("m.vtp", vtp_tetrahedron(data_components=1000000000), ["-n", "20"], 0, None,
                            {"check": True}),
    # appended raw data (VTK's default): moved inline and caged; offsets and sizes that lie: refused
    "vtp_appended": ("m.vtp", vtp_tetrahedron_appended(), ["-n", "20"], 0, None, {"check": True}),
    "vtp_appended_offset_lies": ("m.vtp", vtp_tetrahedron_appended(offset_lie=10 ** 12), [], 2,
                                 "beyond the appended data", {}),
    "vtp_appended_size_lies": ("m.vtp", vtp_tetrahedron_appended(size_lie=2 ** 31), [], 2,
                               "size runs past the appended data", {}),
    # a version-5 legacy file whose offsets point outside the connectivity
    "offsets_damaged_vtk5": ("m.vtk", vtk5_text(CUBE_POINTS, CUBE_TRIANGLES, bad_offset=900), [], 2,
                             "the file is damaged", {}),
    # offsets cut short by bytes that are no numbers (a fuzzed file: vtkPolyDataReader read past its
    # buffer)
    "offsets_cut_short_vtk5": ("m.vtk", vtk5_text(CUBE_POINTS, CUBE_TRIANGLES).replace(b"9 12", b"9\xff 12"), [], 2,
                               "is not a number", {}),
    # OBJ's relative (negative) indices are valid OBJ: a tetrahedron, caged
    "relative_indices_obj": ("m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                             b"f -1 -2 -3\nf -4 -3 -2\nf -4 -2 -1\nf -4 -1 -3\n", ["-n", "20"], 0, None,
                             {"check": True}),
    # NaN and infinite coordinates
    "nan_off": ("m.off", off_text([("nan", 0, 0)] + CUBE_POINTS[1:], CUBE_TRIANGLES), [], 2, "non-finite", {}),
    "inf_off": ("m.off", off_text([("inf", 0, 0)] + CUBE_POINTS[1:], CUBE_TRIANGLES), [], 2, "non-finite", {}),
    "nan_ply": ("m.ply", ply_binary([(float("nan"), 0, 0)] + CUBE_POINTS[1:], CUBE_TRIANGLES), [], 2,
                "non-finite", {}),
    "inf_stl": ("m.stl", stl_binary([(float("inf"), 0, 0)] + CUBE_POINTS[1:], CUBE_TRIANGLES), [], 2,
                "non-finite", {}),
    "nan_obj": ("m.obj", b"v nan 0 0\n" + obj_text(CUBE_POINTS[1:], [])
                + b"".join(b"f %d %d %d\n" % tuple(i + 1 for i in t) for t in CUBE_TRIANGLES), [], 2,
                "non-finite", {}),
    # extreme coordinates: caged (the input is scaled into the unit sphere)
    "huge_coordinates": ("m.off", off_text(scaled_cube(1e30), CUBE_TRIANGLES), ["-n", "30"], 0, None,
                         {"check": True}),
    "tiny_coordinates": ("m.off", off_text(scaled_cube(1e-30), CUBE_TRIANGLES), ["-n", "30"], 0, None,
                         {"check": True}),
    "far_coordinates": ("m.off", off_text(FAR_CUBE, CUBE_TRIANGLES), ["-n", "30"], 0, None, {"check": True}),
    "far_coordinates_off_out": ("m.off", off_text(FAR_CUBE, CUBE_TRIANGLES), ["-n", "30", "-o", "cage.off"], 0,
                                None, {"check": True}),
    # a float32 format cannot hold a cage 1e12 away with its clearance: refused, not written
    "far_coordinates_stl_out": ("m.off", off_text(FAR_CUBE, CUBE_TRIANGLES), ["-n", "30", "-o", "cage.stl"], 3,
                                "single precision", {"no_output": "cage.stl"}),
    # PLY is written with doubles: the same cage, written and checked
    "far_coordinates_ply_out": ("m.off", off_text(FAR_CUBE, CUBE_TRIANGLES), ["-n", "30", "-o", "cage.ply"], 0,
                                None, {"check": True}),
    # odd but usable meshes: caged and checked
    "one_triangle": ("m.off", off_text(TRIANGLE, [(0, 1, 2)]), ["-n", "30"], 0, None, {"check": True}),
    "duplicated_faces": ("m.off", off_text(CUBE_POINTS, CUBE_TRIANGLES + CUBE_TRIANGLES), ["-n", "30"], 0, None,
                         {"check": True}),
    "overlapping_copies": ("m.off", off_text(CUBE_POINTS + scaled_cube(1.0, 0.5),
                                             CUBE_TRIANGLES + [tuple(i + 8 for i in t) for t in CUBE_TRIANGLES]),
                           ["-n", "60"], 0, None, {"check": True}),
    # (a coarse grid without active points: the fan of a 1000-gon is 998 slivers across the
    # prism, and the distance field and the active points then cost about a minute and a
    # gigabyte at the default parameters)
    "polygon_1000_sides": ("m.off", off_text(*prism(1000)), ["-n", "60", "--iso", "0.05", "--voxel", "0.05",
                                                             "--no-active-points"], 0,
                           None, {"check": True}),
    # nothing to cage
    "all_degenerate": ("m.off", off_text(CUBE_POINTS, [(0, 0, 1), (2, 2, 2), (4, 5, 5)]), [], 2,
                       "non-zero area", {}),
    "collinear_points": ("m.off", off_text([(0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 3, 3)], [(0, 1, 2), (1, 2, 3)]),
                         [], 2, "non-zero area", {}),
    "points_no_faces_off": ("m.off", off_text(CUBE_POINTS, []), [], 2, "no polygons", {}),
    "points_no_faces_ply": ("m.ply", ply_ascii(CUBE_POINTS, []), [], 2, "no polygons", {}),
    # random bytes under every extension
    "random_off": ("m.off", random_bytes(4000, 1), [], 2, "cannot read", {}),
    "random_ply": ("m.ply", random_bytes(4000, 2), [], 2, "cannot read", {}),
    "random_ply_header": ("m.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\n"
                          b"property float y\nproperty float z\nelement face 100\n"
                          b"property list uchar int vertex_indices\nend_header\n" + random_bytes(3000, 3), [], 2,
                          "cannot read", {}),
    "random_stl": ("m.stl", random_bytes(4000, 4), [], 2, "cannot read", {}),
    "random_obj": ("m.obj", random_bytes(4000, 5), [], 2, None, {}),
    "random_vtp": ("m.vtp", random_bytes(4000, 6), [], 2, "cannot read", {}),
    "random_vtk": ("m.vtk", random_bytes(4000, 7), [], 2, "cannot read", {}),
    # headers that lie about the size
    "lying_ply_more_faces": ("m.ply", ply_binary(CUBE_POINTS, CUBE_TRIANGLES, nf=14), [], 2, "cannot read", {}),
    "lying_ply_fewer_faces": ("m.ply", ply_binary(CUBE_POINTS, CUBE_TRIANGLES, nf=10), [], 2, "header does not match",
                              {}),
    "lying_stl_header": ("m.stl", stl_binary(CUBE_POINTS, CUBE_TRIANGLES[:10], count=12), [], 2, "declares", {}),
    # starts like ASCII ("solid") but VTK reads it as binary (found by fuzz_cli_read: it then
    # trusted a count of 2.2 billion triangles made of text bytes)
    "stl_solid_read_as_binary": ("m.stl", b"solid c\n" + b"\x83" * 200, [], 2, "declares", {}),
    "lying_stl_header_short": ("m.stl", stl_binary(CUBE_POINTS, CUBE_TRIANGLES, count=3), ["-n", "30"], 0, None,
                               {"check": True}),
    # files that are not meshes at all
    "unknown_extension": ("m.xyz", off_text(CUBE_POINTS, CUBE_TRIANGLES), [], 2, "unknown extension", {}),
    "folder_as_input": ("m.off", None, [], 2, "folder", {}),
    "unreadable_file": ("m.off", off_text(CUBE_POINTS, CUBE_TRIANGLES), [], 2, "permission denied", {"mode": 0}),
    # outputs that cannot be written: refused before the input is even read (the input here is
    # broken too, and the message must be about the output)
    "output_folder_missing": ("m.off", b"", ["-o", "missing/cage.vtp"], 2, "does not exist", {}),
    "output_is_folder": ("m.off", b"", ["-o", "out.vtp"], 2, "is a folder", {"mkdir": "out.vtp"}),
    "report_folder_missing": ("m.off", b"", ["--report", "missing/r.json"], 2, "does not exist", {}),
}


def run_case(name, cli, workdir):
    file_name, content, extra, expect_exit, expect_err, opts = CASES[name]
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    path = os.path.join(workdir, file_name)
    if content is None:
        os.makedirs(path)
    else:
        with open(path, "wb") as f:
            f.write(content)
    if "mkdir" in opts:
        os.makedirs(os.path.join(workdir, opts["mkdir"]))
    command = [cli, "--quiet", file_name] + extra
    if "-o" not in extra:
        command += ["-o", "cage.vtp"]
    cage = command[command.index("-o") + 1]
    preexec = None
    if "mode" in opts:
        os.chmod(path, opts["mode"])
        if os.geteuid() == 0:
            # Root reads a mode-000 file anyway. Run the program as root without the two capabilities that
            # override file permissions: the file is then unreadable to it, while the program, its libraries
            # and the working folder stay reachable whatever the permissions of the folders above the clone
            # (running as nobody failed to load the program from a clone in a 0700 folder).
            setpriv = shutil.which("setpriv")
            if not setpriv:
                print("FAILED: running as root without setpriv (util-linux), a mode-000 file stays readable")
                return 1
            command = [setpriv, "--bounding-set=-dac_override,-dac_read_search", "--"] + command

    print("running:", " ".join(command), "in", workdir)
    start = time.monotonic()
    proc = subprocess.Popen(command, cwd=workdir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            preexec_fn=preexec)
    try:
        out, err = proc.communicate(timeout=MAX_SECONDS)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        print(f"FAILED: still running after {MAX_SECONDS} s (a hang)")
        return 1
    elapsed = time.monotonic() - start
    # the peak memory of the (only) child that ended: the program
    rss_mb = 0.0
    try:
        import resource
        rss_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    except ImportError:
        pass
    out, err = out.decode(errors="replace"), err.decode(errors="replace")
    print(f"exit code {proc.returncode} after {elapsed:.2f} s, peak memory {rss_mb:.0f} MB")
    print("--- stdout ---\n" + out + "--- stderr ---\n" + err + "--------------")

    failures = []
    if proc.returncode != expect_exit:
        failures.append(f"exit code {proc.returncode}, expected {expect_exit}")
    if expect_err is not None and expect_err not in err:
        failures.append(f"stderr does not contain '{expect_err}'")
    for crash in ("Segmentation", "Aborted", "terminate called", "ERROR: In ", "Assertion", "AddressSanitizer",
                  "runtime error:"):
        if crash in err:
            failures.append(f"stderr shows a crash or a raw VTK error ('{crash}')")
    if rss_mb > MAX_RSS_MB:
        failures.append(f"peak memory {rss_mb:.0f} MB > {MAX_RSS_MB} MB")
    cage_path = os.path.join(workdir, cage)
    if expect_exit != 0 and os.path.isfile(cage_path):
        failures.append(f"a cage was written ({cage}) although the run failed")
    if opts.get("no_output") and os.path.exists(os.path.join(workdir, opts["no_output"])):
        failures.append(f"{opts['no_output']} should not exist")
    if expect_exit == 0 and opts.get("check"):
        if not os.path.isfile(cage_path):
            failures.append(f"no cage {cage}")
        else:
            check = subprocess.run([cli, "--check", file_name, cage], cwd=workdir, capture_output=True, text=True)
            print("sdfcage --check:", check.returncode, check.stdout.strip().splitlines()[-1:] or check.stderr)
            if check.returncode != 0:
                failures.append(f"sdfcage --check {file_name} {cage} exit code {check.returncode}:\n"
                                + check.stdout + check.stderr)
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--cli")
    parser.add_argument("--workdir")
    parser.add_argument("--case")
    a = parser.parse_args()
    if a.list:
        print(";".join(CASES))
        return 0
    if a.case not in CASES:
        print(f"unknown case '{a.case}'")
        return 1
    return run_case(a.case, a.cli, a.workdir)


if __name__ == "__main__":
    sys.exit(main())

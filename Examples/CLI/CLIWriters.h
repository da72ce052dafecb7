// SDFCage — CLI: writers of OBJ, binary STL and binary PLY, without VTK.
//
// Why not vtkOBJWriter, vtkSTLWriter and vtkPLYWriter: they live in VTK's IOGeometry and IOPLY
// modules, and IOGeometry alone brings 25 more shared libraries into the program (image I/O with
// JPEG, PNG, TIFF, WebP, DICOM and MetaIO, rendering core, hybrid filters), all loaded and
// relocated at every start of `sdfcage` for three file formats a few lines long. The formats:
//   OBJ   "v x y z" (shortest decimal that reads back to the same double) and "f a b c ..."
//         (1-based), one line each;
//   STL   binary: an 80-byte header, the triangle count, per triangle its unit normal and corners
//         as 32-bit floats (the format has no other kind) and a zero attribute; polygons are fanned;
//   PLY   binary little-endian: x, y, z as doubles (vtkPLYWriter wrote floats: a cage rounded to
//         floats is no longer the verified one), faces as a uchar count and int indices.
// Each returns false with a one-line reason when the file cannot be opened or written in full.
#pragma once

#include "CLIParsers.h" // ParsedMesh

#include <string>

namespace sdfcage_cli
{

bool writeOBJ(const ParsedMesh& mesh, const std::string& path, std::string& error);
bool writeSTL(const ParsedMesh& mesh, const std::string& path, std::string& error);
bool writePLY(const ParsedMesh& mesh, const std::string& path, std::string& error);

} // namespace sdfcage_cli

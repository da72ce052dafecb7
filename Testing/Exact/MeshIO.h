// SDFCage — Testing: small, dependency-free mesh readers for tests and the exact checker.
//
// These readers exist so that tests can load the shared data meshes without VTK and so that
// `sdfcage_exact_check` can verify outputs independently of the code under test. They read
// geometry and polygon connectivity only (normals, colours, texture coordinates are skipped).
#pragma once

#include "Mesh/Mesh.h"

#include <string>

namespace sdfcage
{
namespace exact
{

/// Reads .off, .obj or .ply (ASCII, binary little- or big-endian) by file extension
/// (case-insensitive). Returns false and sets `error` when the file cannot be opened or parsed.
/// Faces keep their size (quads stay quads); OBJ negative (relative) indices are resolved.
bool readPolygonMesh(const std::string& path, PolygonMesh& mesh, std::string& error);

bool readOFF(const std::string& path, PolygonMesh& mesh, std::string& error);
bool readOBJ(const std::string& path, PolygonMesh& mesh, std::string& error);
bool readPLY(const std::string& path, PolygonMesh& mesh, std::string& error);

/// Fan-triangulates every cell with >= 3 points into `out` (no validation, no point removal:
/// out.Points == mesh.Points). Returns false when a cell references a point that does not exist
/// (that cell is skipped).
bool fanTriangulate(const PolygonMesh& mesh, TriangleMesh& out);

/// Writes an ASCII OFF file (for inspecting failing test outputs). Returns false on I/O error.
bool writeOFF(const std::string& path, const TriangleMesh& mesh);

} // namespace exact
} // namespace sdfcage

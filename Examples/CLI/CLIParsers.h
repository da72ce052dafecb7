// SDFCage — CLI: PLY, OBJ, STL and legacy VTK parsers that check everything they read.
//
// PLY: VTK's vtkPLYReader trusts the header: a binary file whose header claims a billion vertices
// makes it loop (and allocate) for a billion elements past the end of the file, and a short
// ASCII line makes it read past its word list or stop on an assert. This parser reads the
// header, bounds every element count and list length by the bytes left in the file before
// anything is allocated, and returns a one-line reason on any defect. It has no VTK in it, so
// the fuzz harness (Testing/Fuzz) can drive it directly.
//
// Accepted: "format ascii | binary_little_endian | binary_big_endian 1.0", every scalar type of
// the format (char int8 uchar uint8 short int16 ushort uint16 int int32 uint uint32 float
// float32 double float64), the element "vertex" with properties x, y, z (other properties and
// other elements skipped) and the element "face" with the list "vertex_indices" (or
// "vertex_index"). Faces of fewer than 3 vertices are counted and dropped. Bytes left after the
// last element (a header that claims less than the file holds) are an error too.
//
// OBJ: VTK's vtkOBJReader reads "nan" as 0, an unreadable number as the previous value and
// 1e400 as the largest double, without a word. This parser takes "v x y z [w]" (w ignored) and
// "f a b c ..." (each a, a/t, a//n or a/t/n; 1-based, negative = relative to the last vertex)
// and refuses any malformed number or index; other statements (vt, vn, g, o, s, usemtl,
// mtllib, l, p, ...) are skipped. Numbers are read as strtod reads them (std::from_chars, and
// strtod itself for what only it accepts): "nan" and "inf" stay what they are, so that the
// pipeline's validation refuses them by name.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sdfcage_cli
{

struct ParsedMesh
{
  std::vector<double> Points;           ///< x y z per vertex
  std::vector<std::int64_t> Offsets;    ///< face f uses Connectivity[Offsets[f] .. Offsets[f+1])
  std::vector<std::int64_t> Connectivity;
  std::int64_t SkippedFaces = 0; ///< faces of 0, 1 or 2 vertices
};

/// Parses a whole PLY file held in memory. False with a one-line reason in `error` for any
/// defect (bad header, a count the remaining bytes cannot hold, a truncated body, a vertex
/// index outside [0, vertices)). `cancelled`, when set, is polled every few thousand elements
/// and makes the parse fail with "interrupted".
bool parsePLY(const char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled = {});

/// Parses a whole OBJ file held in memory; same contract as parsePLY.
bool parseOBJ(const char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled = {});

/// Parses a whole STL file (binary or ASCII) held in memory; same contract as parsePLY. Points
/// with equal coordinates are merged (STL repeats every corner). Binary when the size is what the
/// triangle count says, ASCII when the file starts with "solid", binary otherwise; no triangles
/// at all is an error. See CLISTL.cxx for why this is not vtkSTLReader.
bool parseSTL(const char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled = {});

/// Parses a whole legacy VTK POLYDATA file (.vtk, ASCII or BINARY, cell lists before and from
/// version 5) held in memory; same contract as parsePLY. The points and the polygons are read
/// (triangle strips split into triangles; vertices, lines and FIELD data read past); reading
/// stops at POINT_DATA / CELL_DATA, whose arrays a cage does not need. See CLIVTK.cxx for why
/// this is not vtkPolyDataReader.
bool parseLegacyVTK(const char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled = {});

/// A VTK XML file (held in memory) with its appended data section moved inline: each array in
/// "appended" format becomes the same array in "binary" format, and the <AppendedData> section
/// is dropped. A file without appended data is copied as it is. False with a one-line reason when
/// an offset, a header or a size does not fit the appended section. Why: VTK 9.1's XML readers
/// cannot read appended data with the expat of an up-to-date Debian 12 (CLIVTP.cxx says more).
/// The implementation uses VTK's base64 encoder.
bool inlineAppendedXML(const std::string& in, std::string& out, std::string& error);

/// The parsers' tokenizer: the next white-space separated word of [p, end) into `out` (at most
/// 257 characters: longer ones come in pieces, which no keyword or number matches), lower-cased
/// when `lower`; `p` is left after it. False at the end.
bool nextWord(const char*& p, const char* end, std::string& out, bool lower);

} // namespace sdfcage_cli

// SDFCage — CLI: mesh files in and out, chosen by extension, and the built-in shape.
#pragma once

#include <vtkSmartPointer.h>

#include <functional>
#include <string>

class vtkPolyData;

namespace sdfcage_cli
{

/// ".off .obj .ply .stl .vtp .vtk", for messages.
const char* supportedExtensions();

/// Lower-case extension with the dot (".off"), or "" when there is none.
std::string lowerExtension(const std::string& path);

/// True when the extension is one of supportedExtensions().
bool isSupportedExtension(const std::string& path);

/// Reads a surface mesh. On failure returns nullptr and a one-line reason in `error` (missing
/// file, a folder, unknown extension, empty, unreadable or non-polygonal content, a header whose
/// counts the file cannot hold). `cancelled`, when set, is polled while reading (the readers
/// that report progress stop early) and once after it: then the result is null and `error`
/// "interrupted".
vtkSmartPointer<vtkPolyData> readMesh(
  const std::string& path, std::string& error, const std::function<bool()>& cancelled = {});

/// True when `path` can be written: its folder exists and a file there can be opened for
/// writing (an existing file is left as it is, a new one is removed again). Otherwise false with
/// a one-line reason.
bool checkWritable(const std::string& path, std::string& error);

/// Writes `mesh` in the format of the extension of `path`. Returns false with a reason.
bool writeMesh(vtkPolyData* mesh, const std::string& path, std::string& error);

/// sdfcage::makeBuiltinShape() as vtkPolyData (points and triangles).
vtkSmartPointer<vtkPolyData> builtinShape();

/// Number of triangles a fan triangulation of the polygons and strips of `mesh` gives.
long long triangleCount(vtkPolyData* mesh);

} // namespace sdfcage_cli

// SDFCage — CLI: nested cages as one multi-block file (.vtm, .vtpc). Apart from CLIMeshIO so
// that the programs built from CLIMeshIO alone (the fuzzers) need no IOParallelXML.
#pragma once

#include <string>

class vtkMultiBlockDataSet;

namespace sdfcage_cli
{

/// True for the extensions of multi-block files (".vtm", ".vtpc"): nested cages in one file.
bool isMultiBlockExtension(const std::string& path);

/// Writes the nested levels (blocks of vtkPolyData, named) as one file: .vtm (VTK's XML
/// multi-block: the .vtm plus a folder of that name with one .vtp per block) or .vtpc (a
/// vtkPartitionedDataSetCollection, one partition per level, the same names; also a folder).
/// Returns false with a reason.
bool writeMultiBlock(vtkMultiBlockDataSet* levels, const std::string& path, std::string& error);

} // namespace sdfcage_cli

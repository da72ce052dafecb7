// SDFCage — CLI: see CLIMultiBlock.h.
#include "CLIMultiBlock.h"

#include "CLIMeshIO.h"
#include "CLIMessages.h"

#include <vtkCompositeDataSet.h>
#include <vtkDataSet.h>
#include <vtkInformation.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkPartitionedDataSet.h>
#include <vtkPartitionedDataSetCollection.h>
#include <vtkXMLMultiBlockDataWriter.h>
#include <vtkXMLPartitionedDataSetCollectionWriter.h>

#include <filesystem>

namespace sdfcage_cli
{

namespace
{
MessageCollector* collector()
{
  return MessageCollector::SafeDownCast(vtkOutputWindow::GetInstance());
}
} // namespace

bool isMultiBlockExtension(const std::string& path)
{
  const std::string ext = lowerExtension(path);
  return ext == ".vtm" || ext == ".vtpc";
}

bool writeMultiBlock(vtkMultiBlockDataSet* levels, const std::string& path, std::string& error)
{
  if (!isMultiBlockExtension(path))
  {
    error = "cannot write '" + path + "': a multi-block file must end in .vtm or .vtpc";
    return false;
  }
  if (MessageCollector* c = collector())
  {
    c->clear();
  }
  int ok = 0;
  unsigned long errorCode = 0;
  if (lowerExtension(path) == ".vtm")
  {
    vtkNew<vtkXMLMultiBlockDataWriter> writer;
    writer->SetDataModeToBinary(); // inline arrays: see CLIVTP.cxx
    writer->SetFileName(path.c_str());
    writer->SetInputData(levels);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  else
  {
    // the same levels as a partitioned-dataset collection: one partitioned dataset (one
    // partition) per level, named like the block
    vtkNew<vtkPartitionedDataSetCollection> collection;
    const unsigned int n = levels->GetNumberOfBlocks();
    collection->SetNumberOfPartitionedDataSets(n);
    for (unsigned int b = 0; b < n; ++b)
    {
      vtkNew<vtkPartitionedDataSet> level;
      level->SetNumberOfPartitions(1);
      level->SetPartition(0, vtkDataSet::SafeDownCast(levels->GetBlock(b)));
      collection->SetPartitionedDataSet(b, level);
      if (levels->HasMetaData(b) && levels->GetMetaData(b)->Has(vtkCompositeDataSet::NAME()))
      {
        collection->GetMetaData(b)->Set(
          vtkCompositeDataSet::NAME(), levels->GetMetaData(b)->Get(vtkCompositeDataSet::NAME()));
      }
    }
    vtkNew<vtkXMLPartitionedDataSetCollectionWriter> writer;
    writer->SetDataModeToBinary(); // inline arrays: see CLIVTP.cxx
    writer->SetFileName(path.c_str());
    writer->SetInputData(collection);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  MessageCollector* c = collector();
  const std::string vtkError = (c && !c->errors().empty()) ? c->errors().front() : std::string();
  std::error_code ec;
  if (!ok || errorCode != 0 || !vtkError.empty() || !std::filesystem::exists(path, ec))
  {
    error = "cannot write '" + path + "'" +
      (vtkError.empty() ? std::string(": check that the folder exists and is writable") : ": " + vtkError);
    return false;
  }
  return true;
}

} // namespace sdfcage_cli

/*=========================================================================

  Program:   SDFCage
  Module:    vtkOFFReader.cxx

=========================================================================*/
#include "vtkOFFReader.h"

#include "vtkCellArray.h"
#include "vtkErrorCode.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtksys/FStream.hxx"

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkOFFReader);

namespace
{
//------------------------------------------------------------------------------
// Reads meaningful lines: comments (from '#') stripped, blank lines skipped, line numbers kept.
class LineSource
{
public:
  explicit LineSource(std::istream& in)
    : In(in)
  {
  }

  bool Next(std::string& out)
  {
    while (std::getline(this->In, this->Buffer))
    {
      ++this->LineNumber;
      const std::size_t hash = this->Buffer.find('#');
      if (hash != std::string::npos)
      {
        this->Buffer.resize(hash);
      }
      std::size_t first = 0;
      while (first < this->Buffer.size() && std::isspace(static_cast<unsigned char>(this->Buffer[first])))
      {
        ++first;
      }
      if (first == this->Buffer.size())
      {
        continue;
      }
      out.assign(this->Buffer, first, std::string::npos);
      return true;
    }
    return false;
  }

  long long Line() const { return this->LineNumber; }

private:
  std::istream& In;
  std::string Buffer;
  long long LineNumber = 0;
};

//------------------------------------------------------------------------------
// Number scanning on a C string; each function advances `p` past the number on success.
void SkipSpaces(const char*& p)
{
  while (*p && std::isspace(static_cast<unsigned char>(*p)))
  {
    ++p;
  }
}

bool EndOfToken(const char* p)
{
  return *p == '\0' || std::isspace(static_cast<unsigned char>(*p));
}

bool ScanDouble(const char*& p, double& value)
{
  SkipSpaces(p);
  if (!*p)
  {
    return false;
  }
  char* end = nullptr;
  errno = 0;
  value = std::strtod(p, &end);
  if (end == p || !EndOfToken(end))
  {
    return false;
  }
  p = end;
  return true;
}

bool ScanInteger(const char*& p, long long& value)
{
  SkipSpaces(p);
  if (!*p)
  {
    return false;
  }
  char* end = nullptr;
  errno = 0;
  value = std::strtoll(p, &end, 10);
  if (end == p || !EndOfToken(end) || errno == ERANGE)
  {
    return false;
  }
  p = end;
  return true;
}

std::string FirstToken(const std::string& line)
{
  std::size_t end = 0;
  while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end])))
  {
    ++end;
  }
  return line.substr(0, end);
}

enum class HeaderKind
{
  Keyword,     // a supported keyword such as OFF, COFF, NOFF, STCNOFF
  Unsupported, // 4OFF, nOFF, ...: recognised but not supported
  Counts,      // no keyword: the line starts with a number
  Invalid
};

// Classifies the first token of an OFF file: [ST][C][N][4][n]OFF, or a number.
HeaderKind ClassifyHeader(const std::string& token)
{
  if (token.empty())
  {
    return HeaderKind::Invalid;
  }
  const bool endsWithOFF = token.size() >= 3 && token.compare(token.size() - 3, 3, "OFF") == 0;
  if (!endsWithOFF)
  {
    // no keyword: the file starts directly with the counts
    return std::isdigit(static_cast<unsigned char>(token[0])) || token[0] == '+' ? HeaderKind::Counts
                                                                                 : HeaderKind::Invalid;
  }
  std::string prefix = token.substr(0, token.size() - 3);
  bool unsupported = false;
  auto take = [&prefix](const char* p) {
    const std::size_t n = std::char_traits<char>::length(p);
    if (prefix.compare(0, n, p) == 0)
    {
      prefix.erase(0, n);
      return true;
    }
    return false;
  };
  take("ST");
  take("C");
  take("N");
  unsupported |= take("4");
  unsupported |= take("n");
  if (!prefix.empty())
  {
    return HeaderKind::Invalid;
  }
  return unsupported ? HeaderKind::Unsupported : HeaderKind::Keyword;
}
} // namespace

//------------------------------------------------------------------------------
vtkOFFReader::vtkOFFReader()
{
  this->SetNumberOfInputPorts(0);
}

//------------------------------------------------------------------------------
vtkOFFReader::~vtkOFFReader()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------
int vtkOFFReader::CanReadFile(const char* fileName)
{
  if (!fileName || !*fileName)
  {
    return 0;
  }
  vtksys::ifstream in(fileName, std::ios::in | std::ios::binary);
  if (!in)
  {
    return 0;
  }
  LineSource lines(in);
  std::string line;
  if (!lines.Next(line))
  {
    return 0;
  }
  const HeaderKind kind = ClassifyHeader(FirstToken(line));
  if (kind == HeaderKind::Keyword)
  {
    return line.find("BINARY") == std::string::npos ? 1 : 0;
  }
  if (kind == HeaderKind::Counts)
  {
    const char* p = line.c_str();
    long long a = 0, b = 0;
    return ScanInteger(p, a) && ScanInteger(p, b) && a >= 0 && b >= 0 ? 1 : 0;
  }
  return 0;
}

//------------------------------------------------------------------------------
int vtkOFFReader::RequestData(vtkInformation* vtkNotUsed(request), vtkInformationVector** vtkNotUsed(inputVector),
  vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!output)
  {
    vtkErrorMacro("The output is missing or not a vtkPolyData.");
    return 0;
  }
  output->Initialize();
  this->SetErrorCode(vtkErrorCode::NoError);

  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("FileName is not set.");
    this->SetErrorCode(vtkErrorCode::NoFileNameError);
    return 0;
  }
  vtksys::ifstream in(this->FileName, std::ios::in | std::ios::binary);
  if (!in)
  {
    vtkErrorMacro("Cannot open the file " << this->FileName << ".");
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
    return 0;
  }
  // The file size bounds the counts a header may claim (a vertex takes at least 5 bytes,
  // "0 0 0", a face at least 2, "0\n"), so a corrupt header cannot trigger a huge allocation.
  in.seekg(0, std::ios::end);
  const long long fileSize = static_cast<long long>(in.tellg());
  in.seekg(0, std::ios::beg);

  LineSource lines(in);
  auto error = [&](const std::string& what) {
    vtkErrorMacro(<< this->FileName << ":" << lines.Line() << ": " << what);
    this->SetErrorCode(vtkErrorCode::FileFormatError);
    output->Initialize();
    return 0;
  };

  std::string line;
  if (!lines.Next(line))
  {
    return error("the file is empty: expected an OFF header");
  }

  // --- header: [keyword] nv nf [ne] -------------------------------------------------------
  const std::string keyword = FirstToken(line);
  const HeaderKind kind = ClassifyHeader(keyword);
  const char* p = line.c_str();
  switch (kind)
  {
    case HeaderKind::Invalid:
      return error("'" + keyword + "' is not an OFF header (expected OFF, COFF, NOFF, ...)");
    case HeaderKind::Unsupported:
      return error("'" + keyword + "' files (4D or n-dimensional OFF) are not supported");
    case HeaderKind::Keyword:
      p += keyword.size();
      SkipSpaces(p);
      if (std::string(p).compare(0, 6, "BINARY") == 0)
      {
        return error("binary OFF files are not supported");
      }
      if (!*p)
      {
        if (!lines.Next(line))
        {
          return error("the file ends after the header: expected the vertex and face counts");
        }
        p = line.c_str();
      }
      break;
    case HeaderKind::Counts:
      break;
  }
  long long numberOfPoints = 0, numberOfFaces = 0;
  if (!ScanInteger(p, numberOfPoints) || !ScanInteger(p, numberOfFaces))
  {
    return error("expected the counts 'vertices faces [edges]'");
  }
  if (numberOfPoints < 0 || numberOfFaces < 0)
  {
    return error("negative vertex or face count");
  }
  if (fileSize >= 0 && (numberOfPoints > fileSize / 5 || numberOfFaces > fileSize / 2))
  {
    std::ostringstream msg;
    msg << "the header declares " << numberOfPoints << " vertices and " << numberOfFaces
        << " faces, more than a file of " << fileSize << " bytes can hold";
    return error(msg.str());
  }

  // --- vertices ---------------------------------------------------------------------------
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(numberOfPoints));
  for (long long i = 0; i < numberOfPoints; ++i)
  {
    if (!lines.Next(line))
    {
      std::ostringstream msg;
      msg << "the file ends after " << i << " of " << numberOfPoints << " vertices";
      return error(msg.str());
    }
    p = line.c_str();
    double x[3];
    if (!ScanDouble(p, x[0]) || !ScanDouble(p, x[1]) || !ScanDouble(p, x[2]))
    {
      std::ostringstream msg;
      msg << "vertex " << i << " needs three numeric coordinates";
      return error(msg.str());
    }
    points->SetPoint(static_cast<vtkIdType>(i), x); // colours, normals, ... are ignored
  }

  // --- faces ------------------------------------------------------------------------------
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->Allocate(numberOfFaces + 1);
  connectivity->Allocate(3 * numberOfFaces);
  offsets->InsertNextValue(0);
  vtkNew<vtkCellArray> verts;
  vtkNew<vtkCellArray> polyLines;
  std::vector<vtkIdType> ids;
  long long emptyFaces = 0;
  for (long long f = 0; f < numberOfFaces; ++f)
  {
    if (!lines.Next(line))
    {
      std::ostringstream msg;
      msg << "the file ends after " << f << " of " << numberOfFaces << " faces";
      return error(msg.str());
    }
    p = line.c_str();
    long long n = 0;
    if (!ScanInteger(p, n) || n < 0)
    {
      std::ostringstream msg;
      msg << "face " << f << " must start with its number of vertices";
      return error(msg.str());
    }
    if (n > numberOfPoints && n > 0)
    {
      std::ostringstream msg;
      msg << "face " << f << " claims " << n << " vertices, the mesh has " << numberOfPoints;
      return error(msg.str());
    }
    ids.resize(static_cast<std::size_t>(n));
    for (long long k = 0; k < n; ++k)
    {
      long long id = 0;
      if (!ScanInteger(p, id))
      {
        std::ostringstream msg;
        msg << "face " << f << " needs " << n << " integer vertex indices";
        return error(msg.str());
      }
      if (id < 0 || id >= numberOfPoints)
      {
        std::ostringstream msg;
        msg << "face " << f << " uses vertex index " << id << ", outside [0, " << numberOfPoints << ")";
        return error(msg.str());
      }
      ids[static_cast<std::size_t>(k)] = static_cast<vtkIdType>(id);
    }
    // anything left on the line (a face colour) is ignored
    if (n >= 3)
    {
      for (vtkIdType id : ids)
      {
        connectivity->InsertNextValue(id);
      }
      offsets->InsertNextValue(connectivity->GetNumberOfValues());
    }
    else if (n == 2)
    {
      polyLines->InsertNextCell(2, ids.data());
    }
    else if (n == 1)
    {
      verts->InsertNextCell(1, ids.data());
    }
    else
    {
      ++emptyFaces;
    }
  }
  if (emptyFaces > 0)
  {
    vtkWarningMacro(<< this->FileName << ": " << emptyFaces << " faces without vertices were skipped.");
  }

  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);
  output->SetPoints(points);
  output->SetPolys(polys);
  if (verts->GetNumberOfCells() > 0)
  {
    output->SetVerts(verts);
  }
  if (polyLines->GetNumberOfCells() > 0)
  {
    output->SetLines(polyLines);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkOFFReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}

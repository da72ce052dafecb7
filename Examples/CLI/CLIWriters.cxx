// SDFCage — CLI: see CLIWriters.h.
#include "CLIWriters.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

namespace sdfcage_cli
{

namespace
{

static_assert(std::numeric_limits<float>::is_iec559 && std::numeric_limits<double>::is_iec559,
  "the binary writers store IEEE 754 floats and doubles");

/// A file written through one buffer; every failure (open, write, close) is remembered and named.
class OutputFile
{
public:
  OutputFile(const std::string& path, std::string& error)
    : Path(path)
    , Error(error)
  {
    this->File = std::fopen(path.c_str(), "wb");
    if (!this->File)
      this->fail(std::strerror(errno));
  }
  ~OutputFile()
  {
    if (this->File)
      std::fclose(this->File);
  }
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void text(const char* s, std::size_t n)
  {
    this->Buffer.insert(this->Buffer.end(), s, s + n);
    this->spill();
  }
  void text(const std::string& s) { this->text(s.data(), s.size()); }
  /// The shortest decimal form that reads back to the same double.
  void number(double v)
  {
    char digits[32];
    const std::to_chars_result r = std::to_chars(digits, digits + sizeof digits, v);
    this->text(digits, static_cast<std::size_t>(r.ptr - digits));
  }
  void integer(long long v)
  {
    char digits[24];
    const std::to_chars_result r = std::to_chars(digits, digits + sizeof digits, v);
    this->text(digits, static_cast<std::size_t>(r.ptr - digits));
  }
  /// Little-endian bytes of a value (x86 and ARM as run here are little-endian; checked below).
  template <typename T>
  void binary(T v)
  {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));
    if (!littleEndian())
      std::reverse(bytes, bytes + sizeof(T));
    this->Buffer.insert(this->Buffer.end(), bytes, bytes + sizeof(T));
    this->spill();
  }
  bool close()
  {
    this->flush();
    if (this->File && std::fclose(this->File) != 0)
      this->fail(std::strerror(errno));
    this->File = nullptr;
    return this->Error.empty();
  }

private:
  static bool littleEndian()
  {
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 1;
  }
  void spill()
  {
    if (this->Buffer.size() >= (1u << 20))
      this->flush();
  }
  void flush()
  {
    if (this->File && !this->Buffer.empty() &&
      std::fwrite(this->Buffer.data(), 1, this->Buffer.size(), this->File) != this->Buffer.size())
      this->fail(std::strerror(errno));
    this->Buffer.clear();
  }
  void fail(const char* why)
  {
    if (this->Error.empty())
      this->Error = "cannot write '" + this->Path + "': " + why;
    if (this->File)
      std::fclose(this->File);
    this->File = nullptr;
  }
  std::string Path;
  std::string& Error;
  std::FILE* File = nullptr;
  std::vector<char> Buffer;
};

std::size_t pointCount(const ParsedMesh& mesh)
{
  return mesh.Points.size() / 3;
}

std::size_t faceCount(const ParsedMesh& mesh)
{
  return mesh.Offsets.empty() ? 0 : mesh.Offsets.size() - 1;
}

} // namespace

bool writeOBJ(const ParsedMesh& mesh, const std::string& path, std::string& error)
{
  error.clear();
  OutputFile out(path, error);
  out.text("# written by sdfcage\n");
  for (std::size_t i = 0; i < pointCount(mesh); ++i)
  {
    out.text("v ", 2);
    for (int k = 0; k < 3; ++k)
    {
      out.number(mesh.Points[3 * i + static_cast<std::size_t>(k)]);
      out.text(k < 2 ? " " : "\n", 1);
    }
  }
  for (std::size_t f = 0; f < faceCount(mesh); ++f)
  {
    out.text("f", 1);
    for (std::int64_t k = mesh.Offsets[f]; k < mesh.Offsets[f + 1]; ++k)
    {
      out.text(" ", 1);
      out.integer(mesh.Connectivity[static_cast<std::size_t>(k)] + 1);
    }
    out.text("\n", 1);
  }
  return out.close();
}

bool writeSTL(const ParsedMesh& mesh, const std::string& path, std::string& error)
{
  error.clear();
  std::uint64_t triangles = 0;
  for (std::size_t f = 0; f < faceCount(mesh); ++f)
  {
    const std::int64_t n = mesh.Offsets[f + 1] - mesh.Offsets[f];
    triangles += n >= 3 ? static_cast<std::uint64_t>(n - 2) : 0;
  }
  if (triangles > std::numeric_limits<std::uint32_t>::max())
  {
    error = "cannot write '" + path + "': more triangles than a binary STL file can hold";
    return false;
  }
  OutputFile out(path, error);
  char header[80] = {};
  std::snprintf(header, sizeof header, "binary STL written by sdfcage");
  out.text(header, sizeof header);
  out.binary(static_cast<std::uint32_t>(triangles));
  const auto point = [&mesh](std::int64_t id) {
    const double* p = &mesh.Points[3 * static_cast<std::size_t>(id)];
    return std::array<double, 3>{ p[0], p[1], p[2] };
  };
  for (std::size_t f = 0; f < faceCount(mesh); ++f)
  {
    const std::int64_t b = mesh.Offsets[f], e = mesh.Offsets[f + 1];
    for (std::int64_t k = b + 1; k + 1 < e; ++k)
    {
      const std::array<double, 3> c[3] = { point(mesh.Connectivity[static_cast<std::size_t>(b)]),
        point(mesh.Connectivity[static_cast<std::size_t>(k)]),
        point(mesh.Connectivity[static_cast<std::size_t>(k + 1)]) };
      const double u[3] = { c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2] };
      const double v[3] = { c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2] };
      double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (double& x : n)
        x = len > 0 ? x / len : 0.0;
      for (double x : n)
        out.binary(static_cast<float>(x));
      for (const auto& corner : c)
        for (double x : corner)
          out.binary(static_cast<float>(x));
      out.binary(std::uint16_t(0));
    }
  }
  return out.close();
}

bool writePLY(const ParsedMesh& mesh, const std::string& path, std::string& error)
{
  error.clear();
  for (std::size_t f = 0; f < faceCount(mesh); ++f)
  {
    if (mesh.Offsets[f + 1] - mesh.Offsets[f] > 255)
    {
      error = "cannot write '" + path + "': a face of more than 255 corners (PLY stores the count in a byte)";
      return false;
    }
  }
  OutputFile out(path, error);
  out.text("ply\nformat binary_little_endian 1.0\ncomment written by sdfcage\nelement vertex ");
  out.integer(static_cast<long long>(pointCount(mesh)));
  out.text("\nproperty double x\nproperty double y\nproperty double z\nelement face ");
  out.integer(static_cast<long long>(faceCount(mesh)));
  out.text("\nproperty list uchar int vertex_indices\nend_header\n");
  for (std::size_t i = 0; i < 3 * pointCount(mesh); ++i)
    out.binary(mesh.Points[i]);
  for (std::size_t f = 0; f < faceCount(mesh); ++f)
  {
    out.binary(static_cast<std::uint8_t>(mesh.Offsets[f + 1] - mesh.Offsets[f]));
    for (std::int64_t k = mesh.Offsets[f]; k < mesh.Offsets[f + 1]; ++k)
      out.binary(static_cast<std::int32_t>(mesh.Connectivity[static_cast<std::size_t>(k)]));
  }
  return out.close();
}

} // namespace sdfcage_cli

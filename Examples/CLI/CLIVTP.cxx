// SDFCage — CLI: VTK XML files with appended data rewritten with their arrays inline.
//
// Why: VTK 9.1's XML readers (vtkXMLDataParser) stop the XML parser at the <AppendedData> start
// tag and read the bytes after it themselves. Expat 2.6 (and Debian 12's 2.5.0-1+deb12u3 and
// later, which carry the same "reparse deferral" fix for CVE-2023-52425) reports that start tag
// only once more input follows, so the parser runs on into the binary data and the file is
// refused as "not well-formed (invalid token)" or "junk after document element". Every .vtp
// written by VTK's or ParaView's default (appended) writer is unreadable on such a machine
// (reproduced here with VTK 9.1.0 and libexpat1 2.5.0-1+deb12u5). VTK fixed it in its parser
// (XML_SetReparseDeferralEnabled), which 9.1 does not have. Files with inline arrays ("binary"
// or "ascii") read fine, so the appended section is moved inline here, in memory, and the result
// is given to vtkXMLPolyDataReader as a string. The sdfcage writers write inline arrays
// (CLIMeshIO.cxx) for the same reason.
//
// How: an appended array in base64 encoding is, byte for byte, what the same array inline in
// "binary" format holds, so its text is cut from the appended section. A raw appended array is
// its header (one word: the byte count; or, compressed, the block count, block size, last block
// size and one compressed size per block) followed by its bytes; inline, an uncompressed array is
// one base64 stream of both, a compressed one the header's stream followed by the blocks' stream
// (vtkBase64Utilities). The offset attribute is dropped: VTK's reader misreads an inline array
// that keeps one. Every offset and size is checked against the section before anything is
// copied.
#include "CLIParsers.h"

#include <vtkBase64Utilities.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace sdfcage_cli
{
namespace
{

bool isSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}

/// The value of the attribute `name` in the tag text [begin, end) of `s`, or false. Only the tag
/// is searched, so that the work stays linear in the file.
bool attribute(const std::string& s, std::size_t begin, std::size_t end, const char* name, std::string& value,
  std::size_t* position = nullptr)
{
  const std::string tag = s.substr(begin, end - begin);
  const std::string key = std::string(name) + "=";
  for (std::size_t a = tag.find(key); a != std::string::npos; a = tag.find(key, a + 1))
  {
    std::size_t v = a + key.size();
    if (a == 0 || !isSpace(tag[a - 1]) || v >= tag.size() || (tag[v] != '"' && tag[v] != '\''))
    {
      continue;
    }
    const char quote = tag[v++];
    const std::size_t close = tag.find(quote, v);
    if (close == std::string::npos)
    {
      return false;
    }
    value = tag.substr(v, close - v);
    if (position)
    {
      *position = begin + v;
    }
    return true;
  }
  return false;
}

bool parseOffset(const std::string& text, std::size_t& value)
{
  if (text.empty() || text.size() > 19)
  {
    return false;
  }
  value = 0;
  for (char c : text)
  {
    if (c < '0' || c > '9')
    {
      return false;
    }
    value = value * 10 + static_cast<std::size_t>(c - '0');
  }
  return true;
}

std::string base64(const unsigned char* data, std::size_t size)
{
  std::string out(4 * ((size + 2) / 3), '\0');
  const std::size_t written = vtkBase64Utilities::Encode(data, size, reinterpret_cast<unsigned char*>(&out[0]), 0);
  out.resize(written);
  return out;
}

struct Array
{
  std::size_t TagBegin; ///< '<' of <DataArray
  std::size_t TagEnd;   ///< one past its '>'
  bool SelfClosing;
  std::size_t Offset;   ///< into the appended section, after '_'
  std::size_t Format;   ///< where the format's value "appended" starts
  std::size_t OffsetAt; ///< where the offset's value starts
  bool DataArray;       ///< <DataArray>, or <Array> (field data)
};

} // namespace

bool inlineAppendedXML(const std::string& in, std::string& out, std::string& error)
{
  const std::size_t section = in.find("<AppendedData");
  if (section == std::string::npos)
  {
    out = in;
    return true;
  }
  const std::size_t sectionTagEnd = in.find('>', section);
  if (sectionTagEnd == std::string::npos)
  {
    error = "the <AppendedData> tag is not closed";
    return false;
  }
  std::string encoding = "base64";
  attribute(in, section, sectionTagEnd, "encoding", encoding);
  if (encoding != "base64" && encoding != "raw")
  {
    error = "the appended data has the unknown encoding '" + encoding + "' (raw or base64 expected)";
    return false;
  }
  const std::size_t underscore = in.find('_', sectionTagEnd);
  const std::size_t sectionEnd = in.rfind("</AppendedData>");
  if (underscore == std::string::npos || sectionEnd == std::string::npos || sectionEnd <= underscore)
  {
    error = "the appended data has no '_' marker or no </AppendedData>";
    return false;
  }
  const std::size_t dataBegin = underscore + 1;
  std::size_t dataEnd = sectionEnd;
  if (encoding == "base64")
  {
    while (dataEnd > dataBegin && isSpace(in[dataEnd - 1]))
    {
      --dataEnd;
    }
  }

  // the file's header: byte order and header word size
  const std::size_t file = in.find("<VTKFile");
  const std::size_t fileTagEnd = file == std::string::npos ? file : in.find('>', file);
  if (fileTagEnd == std::string::npos || fileTagEnd > section)
  {
    error = "no <VTKFile> tag before the appended data";
    return false;
  }
  std::string value;
  const bool bigEndian = attribute(in, file, fileTagEnd, "byte_order", value) && value == "BigEndian";
  std::size_t word = 4;
  if (attribute(in, file, fileTagEnd, "header_type", value))
  {
    if (value == "UInt64")
    {
      word = 8;
    }
    else if (value != "UInt32")
    {
      error = "the header type '" + value + "' is not UInt32 or UInt64";
      return false;
    }
  }
  const bool compressed = attribute(in, file, fileTagEnd, "compressor", value) && !value.empty();

  // every appended array in the XML part
  std::vector<Array> arrays;
  // (<DataArray> in point, cell and piece data; <Array> in field data)
  for (std::size_t p = in.find('<', fileTagEnd); p < section; p = in.find('<', p + 1))
  {
    const bool dataArray = in.compare(p + 1, 9, "DataArray") == 0 && p + 10 < in.size() && isSpace(in[p + 10]);
    if (!dataArray && !(in.compare(p + 1, 5, "Array") == 0 && p + 6 < in.size() && isSpace(in[p + 6])))
    {
      continue;
    }
    const std::size_t end = in.find('>', p);
    if (end == std::string::npos || end > section)
    {
      error = "an array's tag is not closed";
      return false;
    }
    std::size_t format = 0;
    if (!attribute(in, p, end, "format", value, &format) || value != "appended")
    {
      continue;
    }
    Array a{ p, end + 1, in[end - 1] == '/', 0, format, 0, dataArray };
    if (!attribute(in, p, end, "offset", value, &a.OffsetAt) || !parseOffset(value, a.Offset) ||
      a.Offset > dataEnd - dataBegin)
    {
      error = "an appended array has no offset or one beyond the appended data";
      return false;
    }
    arrays.push_back(a);
  }

  // the inline text of each array: base64 text is [Begin, Begin + Length) of the input, raw
  // arrays are encoded into Encoded
  struct Inline
  {
    std::size_t Begin = 0;
    std::size_t Length = 0;
    std::string Encoded;
  };
  std::vector<std::size_t> starts;
  starts.reserve(arrays.size());
  for (const Array& a : arrays)
  {
    starts.push_back(a.Offset);
  }
  std::sort(starts.begin(), starts.end());
  starts.erase(std::unique(starts.begin(), starts.end()), starts.end());
  std::map<std::size_t, Inline> text;
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(in.data());
  auto readWord = [&](std::size_t at) {
    unsigned long long v = 0;
    for (std::size_t i = 0; i < word; ++i)
    {
      const unsigned long long b = bytes[at + (bigEndian ? i : word - 1 - i)];
      v = (v << 8) | b;
    }
    return v;
  };
  for (std::size_t i = 0; i < starts.size(); ++i)
  {
    const std::size_t begin = dataBegin + starts[i];
    const std::size_t limit = i + 1 < starts.size() ? dataBegin + starts[i + 1] : dataEnd;
    if (encoding == "base64")
    {
      text[starts[i]] = Inline{ begin, limit - begin, {} };
      continue;
    }
    // raw: the header's words, then the bytes they count
    std::size_t headerWords = 1;
    if (compressed)
    {
      if (begin + word > dataEnd)
      {
        error = "an appended array's header runs past the appended data";
        return false;
      }
      const unsigned long long blocks = readWord(begin);
      if (blocks > (dataEnd - begin) / word)
      {
        error = "an appended array's header counts more blocks than the appended data holds";
        return false;
      }
      headerWords = 3 + static_cast<std::size_t>(blocks);
    }
    const std::size_t headerBytes = headerWords * word;
    if (headerBytes > dataEnd - begin)
    {
      error = "an appended array's header runs past the appended data";
      return false;
    }
    unsigned long long size = 0;
    if (!compressed)
    {
      size = readWord(begin);
    }
    else
    {
      for (std::size_t b = 3; b < headerWords; ++b)
      {
        const unsigned long long blockSize = readWord(begin + b * word);
        size += std::min<unsigned long long>(blockSize, dataEnd - begin + 1); // no wrap-around
        if (size > dataEnd - begin)
        {
          break;
        }
      }
    }
    if (size > dataEnd - begin - headerBytes)
    {
      error = "an appended array's size runs past the appended data";
      return false;
    }
    // inline, an uncompressed array is one base64 stream of its header and bytes; a compressed
    // one is its header's stream, then its blocks' stream
    text[starts[i]].Encoded = compressed
      ? base64(bytes + begin, headerBytes) + base64(bytes + begin + headerBytes, static_cast<std::size_t>(size))
      : base64(bytes + begin, headerBytes + static_cast<std::size_t>(size));
  }

  // the XML part with each appended array made inline, and what follows </AppendedData>
  out.clear();
  out.reserve(section + (dataEnd - dataBegin) * (encoding == "raw" ? 4 : 3) / 3 + 64 * arrays.size() + 64);
  std::size_t copied = 0;
  for (const Array& a : arrays)
  {
    // format="binary", and no offset (VTK's reader misreads an inline array that has one)
    std::string tag = in.substr(a.TagBegin, a.TagEnd - a.TagBegin);
    const std::size_t offsetValue = a.OffsetAt - a.TagBegin;
    const std::size_t offsetEnd = tag.find_first_of("\"'", offsetValue) + 1;
    const std::size_t offsetBegin = offsetValue - std::strlen("offset=\"");
    const std::size_t format = a.Format - a.TagBegin;
    // the later of the two edits first, so that the earlier one's position holds
    if (offsetBegin > format)
    {
      tag.erase(offsetBegin, offsetEnd - offsetBegin);
      tag.replace(format, 8, "binary");
    }
    else
    {
      tag.replace(format, 8, "binary");
      tag.erase(offsetBegin, offsetEnd - offsetBegin);
    }
    if (a.SelfClosing)
    {
      tag.erase(tag.size() - 2, 1); // "/>" -> ">"
    }
    out.append(in, copied, a.TagBegin - copied);
    out += tag;
    out += '\n';
    const Inline& t = text[a.Offset];
    if (t.Encoded.empty())
    {
      out.append(in, t.Begin, t.Length);
    }
    else
    {
      out += t.Encoded;
    }
    out += '\n';
    if (a.SelfClosing)
    {
      out += a.DataArray ? "</DataArray>" : "</Array>";
    }
    copied = a.TagEnd;
  }
  out.append(in, copied, section - copied);
  out.append(in, sectionEnd + std::strlen("</AppendedData>"), std::string::npos);
  return true;
}

} // namespace sdfcage_cli

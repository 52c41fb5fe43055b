/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include "scan_io.h"

#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <system_error>
#include <vector>

namespace selseg_apps {

std::string
lowerExtension(const std::string& path)
{
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos)
    return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
    return static_cast<char>(std::tolower(c));
  });
  return ext;
}

namespace {

bool
hasXYZ(const pcl::PCLPointCloud2& blob)
{
  return pcl::getFieldIndex(blob, "x") >= 0 && pcl::getFieldIndex(blob, "y") >= 0 &&
         pcl::getFieldIndex(blob, "z") >= 0;
}

const char*
typeName(std::uint8_t datatype)
{
  switch (datatype) {
  case pcl::PCLPointField::INT8:
    return "int8";
  case pcl::PCLPointField::UINT8:
    return "uint8";
  case pcl::PCLPointField::INT16:
    return "int16";
  case pcl::PCLPointField::UINT16:
    return "uint16";
  case pcl::PCLPointField::INT32:
    return "int32";
  case pcl::PCLPointField::UINT32:
    return "uint32";
  case pcl::PCLPointField::FLOAT32:
    return "float32";
  case pcl::PCLPointField::FLOAT64:
    return "float64";
  default:
    return "unknown";
  }
}

/** x, y and z must each be one float32 or float64 value: anything else would be read
 * as garbage (PCL's conversion leaves a field of another type at zero). */
bool
coordinateFieldsUsable(const std::string& path,
                       const pcl::PCLPointCloud2& blob,
                       std::string& error)
{
  if (!hasXYZ(blob)) {
    error = "'" + path + "' has no x, y and z fields: give a cloud of 3-D points";
    return false;
  }
  for (const char* name : {"x", "y", "z"}) {
    // Two fields of one name: PCL reads the first; which one was meant is a guess.
    if (std::count_if(blob.fields.begin(), blob.fields.end(), [&](const auto& f) {
          return f.name == name;
        }) > 1) {
      error = "'" + path + "' has more than one field " + name + ": give each once";
      return false;
    }
    const auto& f = blob.fields[pcl::getFieldIndex(blob, name)];
    if ((f.datatype != pcl::PCLPointField::FLOAT32 &&
         f.datatype != pcl::PCLPointField::FLOAT64) ||
        f.count != 1) {
      error = "'" + path + "': field " + name + " holds " + std::to_string(f.count) +
              " value(s) of type " + typeName(f.datatype) +
              "; x, y and z must each be one float32 or float64 value (PCD: SIZE 4 or "
              "8, TYPE F, COUNT 1)";
      return false;
    }
  }
  return true;
}

/** The bytes after position \a from in the file, or -1. */
long long
bytesAfter(const std::string& path, unsigned long long from)
{
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec)
    return -1;
  return size >= from ? static_cast<long long>(size - from) : -1;
}

/** A header's claims against the file's size: \a values is the least number of bytes
 * the data it declares can take; a header promising more than the file holds is
 * truncated or corrupt, and must not make us allocate what it claims. */
bool
plausibleSize(const std::string& path,
              unsigned long long values,
              long long data_bytes,
              std::string& error)
{
  if (data_bytes >= 0 && values <= static_cast<unsigned long long>(data_bytes))
    return true;
  error = "cannot read '" + path + "': its header promises at least " +
          std::to_string(values) + " bytes of data but the file holds only " +
          std::to_string(std::max<long long>(data_bytes, 0)) +
          ": the file is truncated or corrupt";
  return false;
}

/** A control character other than a tab (PCL's header readers split lines at tabs). */
bool
isControlCharacter(char c)
{
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && c != '\t') || u == 0x7f;
}

/** \a word as an unsigned number of at most \a max_digits decimal digits, nothing else
 * (no sign, no space, no exponent: PCL reads such words differently, or to garbage). */
bool
readDigits(const std::string& word, std::size_t max_digits, unsigned long long& value)
{
  if (word.empty() || word.size() > max_digits ||
      word.find_first_not_of("0123456789") != std::string::npos)
    return false;
  value = std::stoull(word);
  return true;
}

/** The header keyword PCL 1.13's PCDReader::readHeader takes a line for. It matches
 * keywords by prefix ("COUNTS" is a COUNT line) and goes on reading lines after DATA
 * until one it does not know; our check must see the lines it sees, the same way. */
std::string
pclHeaderKeyword(const std::string& word)
{
  static const char* const keywords[] = {"VERSION",
                                         "FIELDS",
                                         "COLUMNS",
                                         "SIZE",
                                         "TYPE",
                                         "COUNT",
                                         "WIDTH",
                                         "HEIGHT",
                                         "VIEWPOINT",
                                         "POINTS",
                                         "DATA"};
  if (!word.empty() && word[0] == '#')
    return "#";
  for (const char* k : keywords)
    if (word.compare(0, std::strlen(k), k) == 0)
      return std::strcmp(k, "COLUMNS") == 0 ? "FIELDS" : k;
  return "";
}

/** The rows of an ASCII PCD from \a in (at the data): PCL reads a value it cannot
 * parse as 0 (atof) and gives a row with too few values zeros or an exception, without
 * failing the read, and ignores rows beyond the header's \a points. Each row must hold
 * \a values_per_point numbers ("nan" in any case is NaN; strtod's forms, inf included,
 * are numbers), and there must be at most \a points rows. Blank lines are skipped. */
bool
asciiRowsUsable(const std::string& path,
                std::istream& in,
                unsigned long long values_per_point,
                unsigned long long points,
                std::string& error)
{
  std::string line, word;
  unsigned long long row = 0;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    unsigned long long values = 0;
    bool numbers = true;
    while (words >> word) {
      ++values;
      char* end = nullptr;
      std::strtod(word.c_str(), &end);
      const bool nan = word.size() == 3 && std::tolower(word[0]) == 'n' &&
                       std::tolower(word[1]) == 'a' && std::tolower(word[2]) == 'n';
      numbers = numbers && (nan || (end != word.c_str() && *end == '\0'));
    }
    if (values == 0)
      continue;
    if (++row > points) { // PCL stops at the header's count, with a warning
      error = "cannot read '" + path + "' as PCD: it holds more rows than the " +
              "header's " + std::to_string(points) + " points: the file is corrupt";
      return false;
    }
    if (values != values_per_point || !numbers) {
      error = "cannot read '" + path + "' as PCD: data row " + std::to_string(row) +
              (numbers ? " holds " + std::to_string(values) + " values where the " +
                             "header's fields take " + std::to_string(values_per_point)
                       : " holds '" + line.substr(0, 40) + "', not only numbers") +
              ": the file is corrupt";
      return false;
    }
  }
  return true;
}

/** The sizes a PCD header claims, read without PCL: PCL 1.13's readHeader already
 * allocates the data block the header claims, however large. \a declared_points: the
 * points it declares (the larger of POINTS and WIDTH x HEIGHT), when true. */
bool
pcdSizesPlausible(const std::string& path,
                  std::string& error,
                  unsigned long long& declared_points)
{
  std::ifstream in(path, std::ios::binary);
  std::string line;
  unsigned long long width = 0, height = 1, points = 0, bytes_per_point = 0,
                     values_per_point = 0;
  std::vector<std::string> fields, types;
  std::vector<unsigned long long> sizes, counts;
  std::string data;
  bool data_seen = false;
  std::streamoff data_start = 0;
  std::set<std::string> seen;
  const auto corrupt = [&](const std::string& why) {
    error = "cannot read '" + path + "' as PCD: " + why + ": the header is corrupt";
    return false;
  };
  while (std::getline(in, line)) {
    if (line.empty())
      continue;
    std::istringstream words(line);
    std::string key, word;
    words >> key;
    key = pclHeaderKeyword(key);
    if (data_seen) {
      // PCL reads on after DATA, skipping comments, until a line it does not know: the
      // data must not start with what it would take for a header line.
      if (key == "#")
        continue;
      if (!key.empty())
        return corrupt("a header line follows DATA");
      break;
    }
    // PCL splits a line into values at spaces, tabs and carriage returns, but reads the
    // numbers with >>, which also stops at other white space: a header line with
    // control characters would be counted one way and read another.
    if (std::any_of(line.begin(), line.end(), [](char c) {
          return c != '\r' && isControlCharacter(c);
        }))
      return corrupt("a header line holds control characters");
    if (key == "#")
      continue;
    if (key.empty())
      return corrupt("'" + line.substr(0, 40) + "' is no PCD header line");
    std::vector<std::string> rest;
    while (words >> word)
      rest.push_back(word);
    const auto numbers = [&](std::vector<unsigned long long>& out) {
      for (const auto& w : rest) {
        unsigned long long value = 0;
        if (!readDigits(w, 12, value))
          return false;
        out.push_back(value);
      }
      return true;
    };
    std::vector<unsigned long long> one;
    // Every header keyword once (after DATA, any keyword was refused above).
    if (key != "DATA" && !seen.insert(key).second)
      return corrupt("it has two " + key + " lines");
    if (key == "FIELDS")
      fields = rest;
    else if (key == "TYPE")
      types = rest;
    else if ((key == "SIZE" && !numbers(sizes)) || (key == "COUNT" && !numbers(counts)))
      return corrupt("its " + key + " line is not a list of numbers");
    else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      if (!numbers(one) || one.size() != 1)
        return corrupt("its " + key + " line is not one number");
      (key == "WIDTH" ? width : key == "HEIGHT" ? height : points) = one[0];
    } else if (key == "DATA") {
      data = rest.empty() ? "" : rest[0];
      data_seen = true;
      data_start = in.tellg();
    }
  }
  if (!data_seen || fields.empty()) {
    error = "cannot read '" + path + "' as PCD: its header is missing or malformed";
    return false;
  }
  if (data != "ascii" && data != "binary" && data != "binary_compressed")
    return corrupt("DATA '" + data + "' is none of ascii, binary, binary_compressed");
  if (sizes.size() != fields.size() || types.size() != fields.size() ||
      (!counts.empty() && counts.size() != fields.size()))
    return corrupt("FIELDS, SIZE, TYPE and COUNT list different numbers of fields");
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const unsigned long long count = counts.empty() ? 1 : counts[i];
    if ((sizes[i] != 1 && sizes[i] != 2 && sizes[i] != 4 && sizes[i] != 8) ||
        (types[i] != "I" && types[i] != "U" && types[i] != "F") || count == 0 ||
        count > (1ull << 20))
      return corrupt("field " + fields[i] + " has SIZE " + std::to_string(sizes[i]) +
                     ", TYPE " + types[i] + " and COUNT " + std::to_string(count));
    bytes_per_point += sizes[i] * count;
    values_per_point += count;
  }
  // PCL holds WIDTH and HEIGHT in 32 bits and sums a point's bytes in an int.
  if (width > 0xffffffffull || height > 0xffffffffull || points > (1ull << 40))
    return corrupt("it claims an implausible number of points");
  if (bytes_per_point > 0x7fffffffull)
    return corrupt("its points claim " + std::to_string(bytes_per_point) +
                   " bytes each");
  points = std::max(points, width * height);
  if (points > (1ull << 40))
    return corrupt("it claims an implausible number of points");
  declared_points = points;
  const long long data_bytes =
      bytesAfter(path, static_cast<unsigned long long>(data_start));
  in.clear();
  in.seekg(data_start);
  // Up to 2^40 points of up to 2^31 bytes: saturate rather than wrap.
  const auto claimed = [&](unsigned long long per_point) {
    return per_point != 0 && points > ~0ull / per_point ? ~0ull : points * per_point;
  };
  if (data == "binary_compressed") { // two sizes, then the compressed data
    std::uint32_t stored[2] = {0, 0};
    if (!in.read(reinterpret_cast<char*>(stored), sizeof stored)) {
      error = "cannot read '" + path + "': its compressed data is missing (truncated)";
      return false;
    }
    // LZF expands at most about 100 times: a larger claim is corrupt.
    if (!plausibleSize(path, stored[0] + 8ull, data_bytes, error) ||
        !plausibleSize(path, stored[1] / 100ull, data_bytes, error))
      return false;
    if (stored[1] != claimed(bytes_per_point)) {
      error = "cannot read '" + path + "': its compressed data holds " +
              std::to_string(stored[1]) + " bytes where the header promises " +
              std::to_string(claimed(bytes_per_point)) + ": the file is corrupt";
      return false;
    }
    return true;
  }
  // Binary data is exactly the points' bytes; text takes at least a byte per value.
  if (!plausibleSize(path,
                     claimed(data == "binary" ? bytes_per_point : values_per_point),
                     data_bytes,
                     error))
    return false;
  return data != "ascii" || asciiRowsUsable(path, in, values_per_point, points, error);
}

/** PCL 1.13's PCDReader::read crashes on some malformed headers (no fields): check the
 * header first. */
bool
pcdHeaderUsable(const std::string& path,
                std::string& error,
                unsigned long long& declared_points)
{
  if (!pcdSizesPlausible(path, error, declared_points))
    return false;
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  if (pcl::PCDReader().readHeader(
          path, header, origin, orientation, version, data_type, data_index) < 0 ||
      header.fields.empty()) {
    error = "cannot read '" + path + "' as PCD: its header is missing or malformed";
    return false;
  }
  return coordinateFieldsUsable(path, header, error);
}

/** The names PCL's PLY reader treats as colour when their type is uchar. */
bool
isPlyColourName(const std::string& name)
{
  const std::string base = name.rfind("diffuse_", 0) == 0 ? name.substr(8) : name;
  return base == "red" || base == "green" || base == "blue" || name == "alpha";
}

/** PCL's PLY reader makes a colour field at `red` and writes it at `blue`, moving on
 * only then; `green`, `blue` or `alpha` anywhere else write over other fields or past
 * the point (an assertion then aborts the process). So the uchar colour properties of
 * the vertices, each given as (position, name), must be none, or `red green blue`
 * (or their `diffuse_` names) one after the other, perhaps followed by `alpha`. */
bool
plyColoursUsable(const std::vector<std::pair<std::size_t, std::string>>& colours)
{
  if (colours.empty())
    return true;
  if (colours.size() != 3 && colours.size() != 4)
    return false;
  const std::string prefix = colours[0].second == "diffuse_red" ? "diffuse_" : "";
  const char* names[] = {"red", "green", "blue", "alpha"};
  for (std::size_t k = 0; k < colours.size(); ++k)
    if (colours[k].first != colours[0].first + k ||
        colours[k].second != (k < 3 ? prefix + names[k] : std::string(names[k])))
      return false;
  return true;
}

/** An ASCII PLY's vertex lines, after \a skip lines of earlier elements, each start
 * with \a properties numbers (PCL's reader makes a word a NaN coordinate, silently):
 * false with the line's number otherwise. \a in is at the first line after the
 * header. */
bool
plyAsciiVerticesAreNumbers(std::istream& in,
                           unsigned long long skip,
                           long long vertices,
                           std::size_t properties,
                           const std::string& what,
                           std::string& error)
{
  std::string line;
  for (unsigned long long k = 0; k < skip; ++k)
    if (!std::getline(in, line))
      return true; // short: PCL's reader says so
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)); };
  for (long long v = 0; v < vertices && std::getline(in, line); ++v) {
    const char* at = line.c_str();
    for (std::size_t p = 0; p < properties; ++p) {
      while (*at && space(*at))
        ++at;
      const char* start = at;
      while (*at && !space(*at))
        ++at;
      // from_chars: decimal as PCL's reader takes it (no hexadecimal, which strtod
      // would read), nan and inf included; a leading '+' is PCL's too.
      const char* digits = start < at && *start == '+' ? start + 1 : start;
      double value = 0.0;
      const auto parsed = std::from_chars(digits, at, value);
      const bool number =
          start < at && digits < at &&
          (parsed.ec == std::errc() || parsed.ec == std::errc::result_out_of_range) &&
          parsed.ptr == at;
      if (!number) {
        const std::string token(start, static_cast<std::size_t>(at - start));
        error = what + "vertex " + std::to_string(v) + " (line " +
                std::to_string(skip + static_cast<unsigned long long>(v) + 1) +
                " after the header) has " +
                (!token.empty()
                     ? "'" + token.substr(0, 40) + "' where a number should be"
                     : "fewer than its " + std::to_string(properties) + " values");
        return false;
      }
    }
  }
  return true;
}

/** Checks a PLY header line by line before PCL reads it (its parser trusts the header:
 * a negative element count sends it into a loop of about 2^64 steps) and counts the
 * values its elements promise. PCL also takes `obj_info num_cols N` / `num_rows N` as
 * the cloud's width and height (with atoi) and sizes its data by them: they must be
 * positive integers whose product is the vertex count, or PCL writes past its data
 * (an assertion in PCL's PLY reader aborts the process). */
bool
plyHeaderUsable(const std::string& path,
                std::string& error,
                unsigned long long& declared_points)
{
  std::ifstream in(path, std::ios::binary);
  std::string line;
  const std::string what = "cannot read '" + path + "' as PLY: ";
  if (!std::getline(in, line) || (line != "ply" && line != "ply\r")) {
    error = what + "it does not start with a line 'ply'";
    return false;
  }
  unsigned long long values = 0;
  long long count = 0, vertices = -1, cols = -1, rows = -1;
  bool in_element = false, in_vertex = false;
  // The vertex element's one-byte colour properties, with their positions among its
  // properties.
  std::vector<std::pair<std::size_t, std::string>> colours;
  std::size_t vertex_properties = 0;
  // ASCII: one line per element item, the vertices after the items of the elements
  // declared before them.
  bool ascii = false, vertex_has_list = false;
  unsigned long long lines_before_vertices = 0;
  while (std::getline(in, line)) {
    // PCL's PLY reader splits some lines at spaces and tabs only and asserts on what it
    // finds: no leading white space, no control characters but a final CR.
    const std::string body =
        !line.empty() && line.back() == '\r' ? line.substr(0, line.size() - 1) : line;
    if (!body.empty() && (std::isspace(static_cast<unsigned char>(body[0])) ||
                          std::any_of(body.begin(), body.end(), isControlCharacter))) {
      error = what + "malformed header line (white space first or control characters)";
      return false;
    }
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") {
      if (!plyColoursUsable(colours)) {
        error = what + "its vertex colours are not the properties red, green, blue " +
                "(uchar, one after the other, then alpha or not) that PCL's PLY " +
                "reader needs: reorder or drop them (e.g. save it as PCD)";
        return false;
      }
      // More cells than vertices: PCL's own writer declares the organized size of a
      // cloud whose NaN points it left out; the reader fills what there is, and
      // loadBinaryFormat() drops the layout. Fewer: PCL's reader writes past its data.
      if ((cols >= 0 || rows >= 0) &&
          (cols < 0 || rows < 0 || cols * rows < vertices)) {
        error = what + "its obj_info num_cols (" + std::to_string(cols) +
                ") and num_rows (" + std::to_string(rows) +
                ") are not both given or multiply to fewer than its " +
                std::to_string(std::max(vertices, 0ll)) +
                " vertices: the header is corrupt";
        return false;
      }
      declared_points = static_cast<unsigned long long>(std::max(vertices, 0ll));
      return plausibleSize(path, values, bytesAfter(path, in.tellg()), error) &&
             (!ascii || vertex_has_list ||
              plyAsciiVerticesAreNumbers(
                  in, lines_before_vertices, vertices, vertex_properties, what, error));
    }
    if (keyword == "comment")
      continue;
    bool ok = false;
    if (keyword == "obj_info") {
      // PCL splits this line at spaces and tabs only (other white space was refused).
      std::string key, number, rest;
      words >> key;
      if (key != "num_cols" && key != "num_rows")
        continue;
      unsigned long long value = 0;
      ok = static_cast<bool>(words >> number) && !(words >> rest) &&
           readDigits(number, 9, value) && value > 0;
      if (ok)
        (key == "num_cols" ? cols : rows) = static_cast<long long>(value);
    } else if (keyword == "format") {
      std::string format, version;
      ok = static_cast<bool>(words >> format >> version) &&
           (format == "ascii" || format == "binary_little_endian" ||
            format == "binary_big_endian");
      ascii = format == "ascii";
    } else if (keyword == "element") {
      std::string name, rest;
      ok = static_cast<bool>(words >> name >> count) && !(words >> rest) &&
           count >= 0 && count <= (1ll << 40);
      if (ok && name == "vertex")
        vertices = count;
      in_element = true;
      in_vertex = name == "vertex";
      if (ok && vertices < 0) // an element before the vertices
        lines_before_vertices += static_cast<unsigned long long>(count);
    } else if (keyword == "property" && in_element) {
      std::string type, name;
      ok = static_cast<bool>(words >> type >> name);
      values += static_cast<unsigned long long>(count);
      if (ok && in_vertex) {
        vertex_has_list |= type == "list";
        if ((type == "uchar" || type == "uint8") && isPlyColourName(name))
          colours.emplace_back(vertex_properties, name);
        ++vertex_properties;
      }
    }
    if (!ok) {
      error =
          what + "malformed or implausible header line '" + line.substr(0, 60) + "'";
      return false;
    }
  }
  error = what + "its header has no end_header (truncated)";
  return false;
}

/** x, y, z of every point of \a blob, converted from float32 or float64; false when
 * float's rounding of doubles would distort the scan. */
bool
extractXYZ(const std::string& path,
           const pcl::PCLPointCloud2& blob,
           pcl::PointCloud<pcl::PointXYZ>& cloud,
           std::string& error)
{
  if (!coordinateFieldsUsable(path, blob, error))
    return false;
  const std::size_t points = static_cast<std::size_t>(blob.width) * blob.height;
  const pcl::PCLPointField* fields[3];
  for (int k = 0; k < 3; ++k) {
    fields[k] = &blob.fields[pcl::getFieldIndex(blob,
                                                k == 0   ? "x"
                                                : k == 1 ? "y"
                                                         : "z")];
    const std::size_t size = fields[k]->datatype == pcl::PCLPointField::FLOAT64 ? 8 : 4;
    if (fields[k]->offset + size > blob.point_step ||
        (points > 0 && blob.data.size() < points * blob.point_step)) {
      error =
          "cannot read '" + path + "': its fields do not fit in its points (corrupt)";
      return false;
    }
  }
  cloud.resize(points);
  cloud.width = blob.width;
  cloud.height = blob.height;
  cloud.is_dense = false;
  const auto coordinate = [&](std::size_t i, int k) {
    const std::uint8_t* at = blob.data.data() + i * blob.point_step + fields[k]->offset;
    if (fields[k]->datatype == pcl::PCLPointField::FLOAT64) {
      double v;
      std::memcpy(&v, at, sizeof v);
      return v;
    }
    float v;
    std::memcpy(&v, at, sizeof v);
    return static_cast<double>(v);
  };
  bool any_double = false;
  for (int k = 0; k < 3; ++k)
    any_double |= fields[k]->datatype == pcl::PCLPointField::FLOAT64;
  // Coordinates far from the origin (georeferenced scans) lose their last digits in
  // float: with doubles, refuse when float's rounding there reaches a tenth of the
  // points' spacing (the median distance between consecutive distinct points, which
  // scans store in scan order), rather than segment a distorted scan. Near-duplicates
  // that float merges at a small distance from the origin are no reason to refuse.
  double largest = 0.0;
  std::vector<double> steps;
  bool first = true;
  Eigen::Vector3d previous_point = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points; ++i) {
    const Eigen::Vector3d p(coordinate(i, 0), coordinate(i, 1), coordinate(i, 2));
    cloud[i].getVector3fMap() = p.cast<float>();
    if (!any_double || !cloud[i].getVector3fMap().allFinite())
      continue;
    largest = std::max(largest, p.cwiseAbs().maxCoeff());
    if (!first) {
      const double step = (p - previous_point).norm();
      if (step > 0.0)
        steps.push_back(step);
    }
    first = false;
    previous_point = p;
  }
  if (steps.empty())
    return true;
  auto middle = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), middle, steps.end());
  const double rounding = largest * 0.5 * std::numeric_limits<float>::epsilon();
  if (rounding > 0.1 * *middle) {
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  "at %.6g from the origin float rounds coordinates by up to %.3g, "
                  "more than a tenth of the points' spacing (%.3g)",
                  largest,
                  rounding,
                  *middle);
    error = "cannot segment '" + path +
            "' as it is: its coordinates are doubles, and " + text +
            ": move the points near the origin first (subtract the sensor " +
            "position or the scan's centre)";
    return false;
  }
  return true;
}

/** The ground-truth "label" of every point of \a blob: one unsigned integer of 1, 2 or
 * 4 bytes, or a signed one that is not negative. */
bool
extractLabels(const std::string& path,
              const pcl::PCLPointCloud2& blob,
              std::vector<std::uint32_t>& labels,
              std::string& error)
{
  const int index = pcl::getFieldIndex(blob, "label");
  if (index < 0) {
    error = "cannot read '" + path + "': it has no \"label\" field (the ground truth)";
    return false;
  }
  const pcl::PCLPointField& field = blob.fields[static_cast<std::size_t>(index)];
  const auto type = field.datatype;
  const bool is_signed = type == pcl::PCLPointField::INT8 ||
                         type == pcl::PCLPointField::INT16 ||
                         type == pcl::PCLPointField::INT32;
  const bool is_unsigned = type == pcl::PCLPointField::UINT8 ||
                           type == pcl::PCLPointField::UINT16 ||
                           type == pcl::PCLPointField::UINT32;
  if (!(is_signed || is_unsigned) || field.count != 1) {
    error = "cannot read '" + path + "': its field label must be one integer, not " +
            std::to_string(field.count) + " x " + typeName(type);
    return false;
  }
  const std::size_t size = pcl::getFieldSize(type);
  const std::size_t points = static_cast<std::size_t>(blob.width) * blob.height;
  if (field.offset + size > blob.point_step ||
      (points > 0 && blob.data.size() < points * blob.point_step)) {
    error = "cannot read '" + path + "': its fields do not fit in its points (corrupt)";
    return false;
  }
  labels.resize(points);
  for (std::size_t i = 0; i < points; ++i) {
    const std::uint8_t* at = blob.data.data() + i * blob.point_step + field.offset;
    const auto read = [&](auto value) {
      std::memcpy(&value, at, sizeof value);
      return static_cast<std::int64_t>(value);
    };
    std::int64_t value = 0;
    switch (type) {
    case pcl::PCLPointField::INT8:
      value = read(std::int8_t{});
      break;
    case pcl::PCLPointField::UINT8:
      value = read(std::uint8_t{});
      break;
    case pcl::PCLPointField::INT16:
      value = read(std::int16_t{});
      break;
    case pcl::PCLPointField::UINT16:
      value = read(std::uint16_t{});
      break;
    case pcl::PCLPointField::INT32:
      value = read(std::int32_t{});
      break;
    default:
      value = read(std::uint32_t{});
    }
    if (value < 0) {
      error = "cannot read '" + path + "': point " + std::to_string(i) +
              " has a negative label";
      return false;
    }
    labels[i] = static_cast<std::uint32_t>(value);
  }
  return true;
}

bool
loadBinaryFormat(const std::string& path,
                 const std::string& ext,
                 pcl::PointCloud<pcl::PointXYZ>& cloud,
                 std::string& error,
                 const DeclaredPointsHook& before_reading = {},
                 std::vector<std::uint32_t>* labels = nullptr)
{
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  int version = 0;
  unsigned long long declared = 0;
  if (ext == ".pcd" ? !pcdHeaderUsable(path, error, declared)
                    : !plyHeaderUsable(path, error, declared))
    return false;
  if (before_reading)
    before_reading(static_cast<std::size_t>(declared));
  int rc = -1;
  try {
    rc = ext == ".pcd"
             ? pcl::PCDReader().read(path, blob, origin, orientation, version)
             : pcl::PLYReader().read(path, blob, origin, orientation, version);
  } catch (const std::bad_alloc&) {
    throw; // out of memory, not a corrupt file: guardedLoad() says so
  } catch (const std::exception& e) { // PCL's readers throw on some corrupt files
    rc = -1;
  }
  if (rc < 0) {
    error = "cannot read '" + path + "' as " + (ext == ".pcd" ? "PCD" : "PLY") +
            ": check that the file exists, is readable and is not truncated";
    return false;
  }
  // A PLY layout of more cells than vertices (above): the vertices, one row.
  if (ext == ".ply" &&
      static_cast<unsigned long long>(blob.width) * blob.height > declared) {
    blob.width = static_cast<std::uint32_t>(declared);
    blob.height = 1;
    blob.row_step = blob.point_step * blob.width;
    blob.data.resize(static_cast<std::size_t>(blob.row_step));
  }
  if (!extractXYZ(path, blob, cloud, error) ||
      (labels && !extractLabels(path, blob, *labels, error)))
    return false;
  cloud.sensor_origin_ = origin;
  cloud.sensor_orientation_ = orientation;
  return true;
}

/** \a word as a float coordinate of a text scan: empty when it is one (nan and inf
 * included: such points are counted and left unlabeled), else what is wrong. */
std::string
textCoordinate(const std::string& word, float& value)
{
  if (word.empty())
    return "expected three numbers 'x y z'";
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(word.c_str(), &end);
  if (end != word.c_str() + word.size())
    return "'" + word + "' is not a number (expected three numbers 'x y z')";
  if ((errno == ERANGE && std::isinf(v)) ||
      (std::isfinite(v) && std::abs(v) > std::numeric_limits<float>::max()))
    return "'" + word + "' is beyond float's range (+-3.4e38): give the points in a " +
           "larger unit";
  value = static_cast<float>(v);
  return {};
}

bool
loadText(const std::string& path,
         pcl::PointCloud<pcl::PointXYZ>& cloud,
         std::string& error)
{
  std::ifstream in(path);
  if (!in) {
    error = "cannot open '" + path + "': check the path and the permissions";
    return false;
  }
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#')
      continue;
    std::istringstream fields(line);
    std::string word[3];
    fields >> word[0] >> word[1] >> word[2];
    pcl::PointXYZ p;
    for (int k = 0; k < 3; ++k) {
      const std::string why = textCoordinate(word[k], p.data[k]);
      if (!why.empty()) {
        error = "'" + path + "' line " + std::to_string(line_number) + ": " + why;
        return false;
      }
    }
    cloud.push_back(p);
  }
  if (cloud.empty()) {
    error = "'" + path + "' holds no 'x y z' line";
    return false;
  }
  return true;
}

/** load() on an existing regular file, its exceptions turned into messages. */
template <typename Load>
bool
guardedLoad(const std::string& path, std::string& error, const Load& load)
{
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    error = "cannot read '" + path + "': it does not exist or is not a regular file";
    return false;
  }
  try {
    return load();
  } catch (const std::bad_alloc&) {
    error = "cannot read '" + path + "': not enough memory for what it declares";
  } catch (const std::exception& e) {
    error = "cannot read '" + path + "': " + e.what();
  }
  return false;
}

} // namespace

bool
loadScan(const std::string& path,
         double unit_scale,
         pcl::PointCloud<pcl::PointXYZ>& cloud,
         std::string& error,
         const DeclaredPointsHook& before_reading)
{
  cloud.clear();
  const std::string ext = lowerExtension(path);
  if (!guardedLoad(path, error, [&] {
        return (ext == ".pcd" || ext == ".ply")
                   ? loadBinaryFormat(path, ext, cloud, error, before_reading)
                   : loadText(path, cloud, error);
      })) {
    cloud.clear();
    return false;
  }
  if (unit_scale != 1.0) {
    for (auto& p : cloud)
      p.getVector3fMap() *= static_cast<float>(unit_scale);
    // The file's VIEWPOINT is a position in the same unit.
    cloud.sensor_origin_.head<3>() *= static_cast<float>(unit_scale);
  }
  return true;
}

bool
unitScaleUsable(double unit_scale)
{
  if (unit_scale >= 1e-12 && unit_scale <= 1e12)
    return true;
  pcl::console::print_error("Option -unit_scale needs a number in [1e-12, 1e12], e.g. "
                            "0.01 for centimetres or 0.001 for millimetres (%g would "
                            "overflow or underflow the coordinates).\n",
                            unit_scale);
  return false;
}

bool
loadLabeledScan(const std::string& path,
                pcl::PointCloud<pcl::PointXYZ>& cloud,
                std::vector<std::uint32_t>& labels,
                std::string& error)
{
  cloud.clear();
  labels.clear();
  if (lowerExtension(path) != ".pcd") {
    error = "cannot read '" + path + "': give a .pcd file";
    return false;
  }
  if (!guardedLoad(path, error, [&] {
        return loadBinaryFormat(path, ".pcd", cloud, error, {}, &labels);
      })) {
    cloud.clear();
    labels.clear();
    return false;
  }
  return true;
}

} // namespace selseg_apps

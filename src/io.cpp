// SPDX-License-Identifier: GPL-3.0-or-later
// File input and output. PCL's readers are used for .pcd and .ply clouds so
// that field conventions (rgb packing, normal names) match the rest of PCL,
// but only after the header and the body size have been checked here: PCL
// 1.13 crashes on some malformed PCD headers and would allocate whatever
// size a corrupt header claims. Meshes are read by small parsers of our own
// so that every format reports the same kind of errors.
#include <pcl_ms/io.h>

#include <pcl/PCLPointField.h>
#include <pcl/io/obj_io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/io/vtk_io.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>
#include <system_error>

namespace pcl_ms {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Small text and file helpers

std::string toLower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool isBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && isBlank(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && isBlank(text.back()))
    text.remove_suffix(1);
  return text;
}

std::vector<std::string_view> splitWords(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && isBlank(text[i]))
      ++i;
    const std::size_t start = i;
    while (i < text.size() && !isBlank(text[i]))
      ++i;
    if (i > start)
      words.push_back(text.substr(start, i - start));
  }
  return words;
}

bool startsWith(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

/// Whole-token number parsing, locale independent; accepts a leading '+'.
/// A float is rounded once from the text, as a writer's binary copy would be.
template <typename Number> bool parseNumber(std::string_view token, Number &value) {
  if (!token.empty() && token.front() == '+')
    token.remove_prefix(1);
  if (token.empty())
    return false;
  const char *last = token.data() + token.size();
  const auto [end, code] = std::from_chars(token.data(), last, value);
  return code == std::errc() && end == last;
}

bool parseDouble(std::string_view token, double &value) { return parseNumber(token, value); }

template <typename Integer> bool parseInteger(std::string_view token, Integer &value) {
  return parseNumber(token, value);
}

/// Printable form of a header word for error messages (garbage stays short).
std::string printable(std::string_view word) {
  std::string out = "'";
  for (char c : word.substr(0, 40))
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (word.size() > 40)
    out += "...";
  return out + "'";
}

/// True when `value` is a whole number in [low, high]; NaN and infinities are not.
bool isWholeNumberIn(double value, double low, double high) {
  return value >= low && value <= high && std::floor(value) == value;
}

/// A number from a file for an error message, in the shortest form that reads back.
std::string printableNumber(double value) {
  char text[32];
  const auto [end, code] = std::to_chars(text, text + sizeof(text), value);
  return code == std::errc() ? std::string(text, end) : std::string("?");
}

/// Checks that `path` names a readable, non-empty regular file.
bool checkInputFile(const std::string &path, std::uintmax_t &size, std::string &error) {
  std::error_code code;
  const fs::file_status status = fs::status(path, code);
  if (code && code != std::errc::no_such_file_or_directory) {
    error = "cannot access: " + code.message();
    return false;
  }
  if (!fs::exists(status)) {
    error = "file does not exist";
    return false;
  }
  if (fs::is_directory(status)) {
    error = "is a directory, not a file";
    return false;
  }
  if (!fs::is_regular_file(status)) {
    error = "is not a regular file";
    return false;
  }
  size = fs::file_size(path, code);
  if (code) {
    error = "cannot determine the file size: " + code.message();
    return false;
  }
  std::ifstream probe(path, std::ios::binary);
  if (!probe) {
    error = std::string("cannot open for reading: ") + std::strerror(errno);
    return false;
  }
  if (size == 0) {
    error = "file is empty";
    return false;
  }
  return true;
}

bool readFileBytes(const std::string &path, std::string &bytes, std::string &error) {
  std::uintmax_t size = 0;
  if (!checkInputFile(path, size, error))
    return false;
  std::ifstream in(path, std::ios::binary);
  bytes.resize(static_cast<std::size_t>(size));
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    error = "read error";
    return false;
  }
  return true;
}

/// Reads one header line of at most `max_length` characters (without the
/// newline). False at end of file or when the line is longer: a binary file
/// must not make us swallow megabytes looking for a newline.
bool readHeaderLine(std::istream &in, std::string &line, std::size_t max_length) {
  line.clear();
  char c = 0;
  while (in.get(c)) {
    if (c == '\n')
      return true;
    if (line.size() >= max_length)
      return false;
    line += c;
  }
  return !line.empty();
}

constexpr std::size_t kMaxHeaderLine = 4096;
constexpr std::size_t kMaxHeaderLines = 100000;

bool hostIsLittleEndian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

// ---------------------------------------------------------------------------
// Field checks shared by all cloud readers

const pcl::PCLPointField *findField(const pcl::PCLPointCloud2 &cloud, const std::string &name) {
  for (const pcl::PCLPointField &field : cloud.fields)
    if (field.name == name)
      return &field;
  return nullptr;
}

bool isSingleFloatField(const pcl::PCLPointField *field) {
  return field && field->datatype == pcl::PCLPointField::FLOAT32 && field->count <= 1;
}

const char *datatypeName(std::uint8_t datatype) {
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
    return "unknown type";
  }
}

bool checkCloudLayout(const pcl::PCLPointCloud2 &cloud, std::string &error) {
  for (const char *name : {"x", "y", "z"}) {
    const pcl::PCLPointField *field = findField(cloud, name);
    if (!field) {
      error = std::string("the cloud has no '") + name + "' field";
      return false;
    }
    if (!isSingleFloatField(field)) {
      error = std::string("field '") + name + "' is " + datatypeName(field->datatype) + " (count " +
              std::to_string(field->count) + "); float32 coordinates are required";
      return false;
    }
    if (field->offset + sizeof(float) > cloud.point_step) {
      error = std::string("field '") + name + "' lies outside the point record";
      return false;
    }
  }
  const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (points == 0) {
    error = "the file contains no points";
    return false;
  }
  if (cloud.data.size() != points * cloud.point_step) {
    error = "inconsistent cloud: " + std::to_string(points) + " points of " +
            std::to_string(cloud.point_step) + " bytes but " + std::to_string(cloud.data.size()) +
            " bytes of data";
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// PCD: header check before PCL's reader sees the file

bool checkPcdAsciiBody(std::istream &in, std::size_t line_number, std::uint64_t points,
                       std::uint64_t values_per_point, std::string &error) {
  std::string line;
  std::uint64_t lines_read = 0;
  while (lines_read < points && std::getline(in, line)) {
    ++line_number;
    const std::size_t values = splitWords(line).size();
    if (values == 0)
      continue;
    if (values != values_per_point) {
      error = "line " + std::to_string(line_number) + ": expected " +
              std::to_string(values_per_point) + " values, found " + std::to_string(values) +
              (in.eof() ? " (file truncated?)" : "");
      return false;
    }
    ++lines_read;
  }
  if (lines_read < points) {
    error = "truncated PCD file: " + std::to_string(lines_read) + " of " + std::to_string(points) +
            " points";
    return false;
  }
  return true;
}

bool checkPcdHeader(const std::string &path, std::uintmax_t file_size, std::string &error) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> fields, sizes, types, counts;
  bool has_fields = false, has_size = false, has_type = false;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false;
  std::string data_kind;

  std::string line;
  std::size_t line_number = 0;
  while (data_kind.empty()) {
    if (!readHeaderLine(in, line, kMaxHeaderLine) || ++line_number > kMaxHeaderLines) {
      error = line_number <= 1 ? "not a PCD file" : "incomplete PCD header (no DATA line)";
      return false;
    }
    const std::string_view text = trim(line);
    if (text.empty() && !line.empty()) {
      // PCL's reader skips empty lines but crashes after one of blanks only.
      error = "PCD header line " + std::to_string(line_number) + " holds only blanks";
      return false;
    }
    if (text.empty() || text.front() == '#')
      continue;
    const std::vector<std::string_view> words = splitWords(text);
    const std::string_view key = words.front();
    const auto values = [&]() { return std::vector<std::string>(words.begin() + 1, words.end()); };
    const auto parseCount = [&](std::uint64_t &count) {
      if (words.size() != 2 || !parseInteger(words[1], count)) {
        error = "PCD header line " + std::to_string(line_number) + ": bad " + std::string(key) +
                " value";
        return false;
      }
      return true;
    };
    if (key == "VERSION" || key == "VIEWPOINT") {
      continue;
    } else if (key == "FIELDS" || key == "COLUMNS") {
      fields = values();
      has_fields = true;
    } else if (key == "SIZE") {
      sizes = values();
      has_size = true;
    } else if (key == "TYPE") {
      types = values();
      has_type = true;
    } else if (key == "COUNT") {
      counts = values();
    } else if (key == "WIDTH") {
      if (!parseCount(width))
        return false;
      has_width = true;
    } else if (key == "HEIGHT") {
      if (!parseCount(height))
        return false;
    } else if (key == "POINTS") {
      if (!parseCount(points))
        return false;
      has_points = true;
    } else if (key == "DATA") {
      data_kind = words.size() == 2 ? std::string(words[1]) : std::string("?");
    } else {
      error = line_number == 1 ? "not a PCD file"
                               : "PCD header line " + std::to_string(line_number) +
                                     ": unknown keyword " + printable(key);
      return false;
    }
  }
  const std::uint64_t header_bytes = static_cast<std::uint64_t>(in.tellg());

  if (!has_fields || fields.empty() || !has_size || !has_type || !has_width || !has_points) {
    error = "incomplete PCD header (FIELDS, SIZE, TYPE, WIDTH and POINTS are required)";
    return false;
  }
  if (sizes.size() != fields.size() || types.size() != fields.size() ||
      (!counts.empty() && counts.size() != fields.size())) {
    error = "PCD header: FIELDS, SIZE, TYPE and COUNT list different numbers of entries";
    return false;
  }
  std::uint64_t point_bytes = 0, values_per_point = 0;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    unsigned size = 0, count = 1;
    if (!parseInteger(std::string_view(sizes[f]), size) ||
        (size != 1 && size != 2 && size != 4 && size != 8)) {
      error = "PCD header: field '" + fields[f] + "' has an invalid SIZE";
      return false;
    }
    if ((types[f] != "I" && types[f] != "U" && types[f] != "F") ||
        (types[f] == "F" && size != 4 && size != 8)) {
      error = "PCD header: field '" + fields[f] + "' has an invalid TYPE";
      return false;
    }
    if (!counts.empty() &&
        (!parseInteger(std::string_view(counts[f]), count) || count == 0 || count > 1000000)) {
      error = "PCD header: field '" + fields[f] + "' has an invalid COUNT";
      return false;
    }
    point_bytes += std::uint64_t(size) * count;
    values_per_point += count;
  }
  if (width * height != points) {
    error = "PCD header: WIDTH x HEIGHT (" + std::to_string(width * height) +
            ") differs from POINTS (" + std::to_string(points) + ")";
    return false;
  }
  if (points == 0) {
    error = "the file contains no points";
    return false;
  }

  // Compare what the header promises with what the file holds, in doubles
  // so that absurd counts cannot overflow.
  const double body = static_cast<double>(file_size) - static_cast<double>(header_bytes);
  const double expected = static_cast<double>(points) * static_cast<double>(point_bytes);
  if (data_kind == "ascii") {
    // Each value needs at least one character and one separator.
    if (static_cast<double>(points) * static_cast<double>(values_per_point) * 2 - 1 > body) {
      error = "truncated PCD file: the header declares " + std::to_string(points) +
              " points but the data is too short";
      return false;
    }
    // PCL silently accepts a short last line, so count the values per line.
    return checkPcdAsciiBody(in, line_number, points, values_per_point, error);
  } else if (data_kind == "binary") {
    if (expected > body) {
      error = "truncated PCD file: " + std::to_string(points) + " points need " +
              std::to_string(static_cast<std::uint64_t>(expected)) + " bytes, the file has " +
              std::to_string(static_cast<std::uint64_t>(std::max(body, 0.0)));
      return false;
    }
  } else if (data_kind == "binary_compressed") {
    std::uint32_t compressed = 0, uncompressed = 0;
    if (body < 8 || !in.read(reinterpret_cast<char *>(&compressed), 4) ||
        !in.read(reinterpret_cast<char *>(&uncompressed), 4)) {
      error = "truncated PCD file: compressed block sizes are missing";
      return false;
    }
    if (static_cast<double>(uncompressed) != expected) {
      error = "corrupt PCD file: the compressed block does not match the header";
      return false;
    }
    if (static_cast<double>(compressed) + 8 > body) {
      error = "truncated PCD file: the compressed block is cut short";
      return false;
    }
  } else {
    error = "PCD header: unknown DATA kind " + printable(data_kind);
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// PLY: header parsing (used to validate clouds and to read meshes)

enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8; // lists only
  PlyType value_type = PlyType::Float32;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::uint64_t header_bytes = 0;

  const PlyElement *find(const std::string &name) const {
    for (const PlyElement &element : elements)
      if (element.name == name)
        return &element;
    return nullptr;
  }
};

bool parsePlyType(std::string_view word, PlyType &type) {
  static const std::pair<std::string_view, PlyType> names[] = {
      {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto &[name, value] : names)
    if (word == name) {
      type = value;
      return true;
    }
  return false;
}

std::size_t plyTypeSize(PlyType type) {
  switch (type) {
  case PlyType::Int8:
  case PlyType::UInt8:
    return 1;
  case PlyType::Int16:
  case PlyType::UInt16:
    return 2;
  case PlyType::Int32:
  case PlyType::UInt32:
  case PlyType::Float32:
    return 4;
  case PlyType::Float64:
    return 8;
  }
  return 0;
}

bool parsePlyHeader(std::istream &in, PlyHeader &header, std::string &error) {
  std::string line;
  if (!readHeaderLine(in, line, kMaxHeaderLine) || trim(line) != "ply") {
    error = "not a PLY file (no 'ply' magic line)";
    return false;
  }
  std::size_t line_number = 1;
  bool has_format = false;
  while (true) {
    if (!readHeaderLine(in, line, kMaxHeaderLine) || ++line_number > kMaxHeaderLines) {
      error = "incomplete PLY header (no end_header)";
      return false;
    }
    const std::vector<std::string_view> words = splitWords(line);
    if (words.empty())
      continue;
    const std::string where = "PLY header line " + std::to_string(line_number) + ": ";
    const std::string_view key = words.front();
    if (key == "end_header") {
      break;
    } else if (key == "obj_info" && !startsWith(line, "obj_info")) {
      // PCL's reader asserts (and aborts) on an obj_info line that does not
      // start with the keyword itself.
      error = where + "obj_info must start the line";
      return false;
    } else if (key == "comment" || key == "obj_info") {
      continue;
    } else if (key == "format") {
      if (words.size() < 2) {
        error = where + "missing format";
        return false;
      }
      if (words[1] == "ascii")
        header.format = PlyFormat::Ascii;
      else if (words[1] == "binary_little_endian")
        header.format = PlyFormat::BinaryLittleEndian;
      else if (words[1] == "binary_big_endian")
        header.format = PlyFormat::BinaryBigEndian;
      else {
        error = where + "unknown format " + printable(words[1]);
        return false;
      }
      has_format = true;
    } else if (key == "element") {
      PlyElement element;
      if (words.size() != 3 || !parseInteger(words[2], element.count)) {
        error = where + "malformed element line";
        return false;
      }
      element.name = std::string(words[1]);
      header.elements.push_back(std::move(element));
    } else if (key == "property") {
      if (header.elements.empty()) {
        error = where + "property before any element";
        return false;
      }
      PlyProperty property;
      bool valid = false;
      if (words.size() == 5 && words[1] == "list") {
        property.is_list = true;
        valid = parsePlyType(words[2], property.count_type) &&
                parsePlyType(words[3], property.value_type) &&
                property.count_type != PlyType::Float32 && property.count_type != PlyType::Float64;
        property.name = std::string(words[4]);
      } else if (words.size() == 3) {
        valid = parsePlyType(words[1], property.value_type);
        property.name = std::string(words[2]);
      }
      if (!valid) {
        error = where + "malformed property line";
        return false;
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      error = where + "unknown keyword " + printable(key);
      return false;
    }
  }
  if (!has_format) {
    error = "PLY header has no format line";
    return false;
  }
  header.header_bytes = static_cast<std::uint64_t>(in.tellg());
  return true;
}

/// Rejects files shorter than the smallest body their header allows, which
/// catches truncation and absurd element counts before anything is allocated.
bool checkPlyBodySize(const PlyHeader &header, std::uintmax_t file_size, std::string &error) {
  double minimum = 0;
  for (const PlyElement &element : header.elements) {
    double record = 0;
    for (const PlyProperty &property : element.properties) {
      if (header.format == PlyFormat::Ascii)
        record += 2; // one character and one separator per value at least
      else
        record += static_cast<double>(
            plyTypeSize(property.is_list ? property.count_type : property.value_type));
    }
    minimum += record * static_cast<double>(element.count);
  }
  if (header.format == PlyFormat::Ascii && minimum > 0)
    minimum -= 1; // the last value needs no separator
  const double body = static_cast<double>(file_size) - static_cast<double>(header.header_bytes);
  if (minimum > body) {
    error = "truncated PLY file: the header declares more data than the file holds";
    return false;
  }
  return true;
}

/// Reads PLY values one at a time from an in-memory body, either format.
class PlyValueReader {
public:
  PlyValueReader(std::string_view body, PlyFormat format)
      : body_(body), format_(format),
        swap_(format != PlyFormat::Ascii &&
              (format == PlyFormat::BinaryLittleEndian) != hostIsLittleEndian()) {}

  bool read(PlyType type, double &value) {
    if (format_ == PlyFormat::Ascii) {
      while (position_ < body_.size() && isBlank(body_[position_]))
        ++position_;
      const std::size_t start = position_;
      while (position_ < body_.size() && !isBlank(body_[position_]))
        ++position_;
      const std::string_view token = body_.substr(start, position_ - start);
      // A float property holds what a binary file would: the text rounded
      // once to float, so ASCII and binary copies match position for position.
      if (type == PlyType::Float32) {
        float single;
        if (!parseNumber(token, single))
          return false;
        value = single;
        return true;
      }
      return parseDouble(token, value);
    }
    const std::size_t size = plyTypeSize(type);
    if (position_ + size > body_.size())
      return false;
    unsigned char raw[8];
    std::memcpy(raw, body_.data() + position_, size);
    position_ += size;
    if (swap_)
      std::reverse(raw, raw + size);
    value = decode(type, raw);
    return true;
  }

private:
  template <typename T> static double as(const unsigned char *raw) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<double>(value);
  }

  static double decode(PlyType type, const unsigned char *raw) {
    switch (type) {
    case PlyType::Int8:
      return as<std::int8_t>(raw);
    case PlyType::UInt8:
      return as<std::uint8_t>(raw);
    case PlyType::Int16:
      return as<std::int16_t>(raw);
    case PlyType::UInt16:
      return as<std::uint16_t>(raw);
    case PlyType::Int32:
      return as<std::int32_t>(raw);
    case PlyType::UInt32:
      return as<std::uint32_t>(raw);
    case PlyType::Float32:
      return as<float>(raw);
    case PlyType::Float64:
      return as<double>(raw);
    }
    return 0;
  }

  std::string_view body_;
  PlyFormat format_;
  bool swap_;
  std::size_t position_ = 0;
};

// ---------------------------------------------------------------------------
// Point clouds

bool loadPcdCloud(const std::string &path, std::uintmax_t size, pcl::PCLPointCloud2 &cloud,
                  Eigen::Vector4f &sensor_origin, std::string &error) {
  if (!checkPcdHeader(path, size, error))
    return false;
  Eigen::Quaternionf sensor_orientation;
  if (pcl::io::loadPCDFile(path, cloud, sensor_origin, sensor_orientation) < 0) {
    error = "PCL's PCD reader rejected the data (corrupt or truncated file)";
    return false;
  }
  return true;
}

/// PCL turns range scans (element range_grid) into an organized grid with NaN
/// in empty cells, and takes width and height from obj_info lines even when
/// they do not match the vertex count. Callers want the scanned vertices.
void unorganizeScan(const PlyHeader &header, pcl::PCLPointCloud2 &cloud) {
  const PlyElement *vertex = header.find("vertex");
  const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (!vertex || points == vertex->count)
    return;
  const pcl::PCLPointField *x = findField(cloud, "x");
  if (header.find("range_grid") && isSingleFloatField(x) &&
      cloud.data.size() == points * cloud.point_step) {
    std::size_t kept = 0;
    for (std::size_t p = 0; p < points; ++p) {
      const std::uint8_t *record = &cloud.data[p * cloud.point_step];
      float value;
      std::memcpy(&value, record + x->offset, sizeof(float));
      if (std::isnan(value))
        continue; // an empty grid cell
      std::memmove(&cloud.data[kept * cloud.point_step], record, cloud.point_step);
      ++kept;
    }
    cloud.data.resize(kept * cloud.point_step);
    cloud.width = static_cast<std::uint32_t>(kept);
  } else if (cloud.data.size() == vertex->count * cloud.point_step) {
    cloud.width = static_cast<std::uint32_t>(vertex->count);
  } else {
    return; // leave it to checkCloudLayout to report
  }
  cloud.height = 1;
  cloud.row_step = cloud.width * cloud.point_step;
  cloud.is_dense = false;
}

bool loadPlyCloud(const std::string &path, std::uintmax_t size, pcl::PCLPointCloud2 &cloud,
                  std::string &error) {
  PlyHeader header;
  {
    std::ifstream in(path, std::ios::binary);
    if (!parsePlyHeader(in, header, error) || !checkPlyBodySize(header, size, error))
      return false;
  }
  if (!header.find("vertex")) {
    error = "the PLY file has no vertex element";
    return false;
  }
  // Reading into a mesh gives faces somewhere to go, so mesh files load
  // without PCL complaining about unhandled properties.
  pcl::PolygonMesh mesh;
  if (pcl::io::loadPLYFile(path, mesh) < 0) {
    error = "PCL's PLY reader rejected the file (corrupt or truncated)";
    return false;
  }
  cloud = std::move(mesh.cloud);
  unorganizeScan(header, cloud);
  return true;
}

/// Whether a finite value is too large for the float the clouds store.
bool outOfFloatRange(double value) {
  return std::isfinite(value) && std::abs(value) > std::numeric_limits<float>::max();
}

/// A cloud of FLOAT32 columns (x y z [normal_x normal_y normal_z]) from
/// `values`, `columns` per point.
void makeFloatCloud(const std::vector<float> &values, std::size_t columns,
                    pcl::PCLPointCloud2 &cloud) {
  const char *names[] = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};
  cloud = pcl::PCLPointCloud2();
  for (std::size_t c = 0; c < columns; ++c) {
    pcl::PCLPointField field;
    field.name = names[c];
    field.offset = static_cast<std::uint32_t>(c * sizeof(float));
    field.datatype = pcl::PCLPointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.point_step = static_cast<std::uint32_t>(columns * sizeof(float));
  cloud.width = static_cast<std::uint32_t>(values.size() / columns);
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense =
      std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
  cloud.data.resize(values.size() * sizeof(float));
  std::memcpy(cloud.data.data(), values.data(), cloud.data.size());
}

bool loadXyzCloud(const std::string &path, pcl::PCLPointCloud2 &cloud, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;

  std::vector<float> values;
  std::size_t columns = 0, line_number = 0, position = 0;
  while (position < bytes.size()) {
    std::size_t end = bytes.find('\n', position);
    const bool has_newline = end != std::string::npos;
    if (!has_newline)
      end = bytes.size();
    std::string_view line(bytes.data() + position, end - position);
    position = end + 1;
    ++line_number;

    line = line.substr(0, line.find('#'));
    const std::vector<std::string_view> words = splitWords(line);
    if (words.empty())
      continue;
    const std::string where = "line " + std::to_string(line_number) + ": ";
    if (columns == 0) {
      if (words.size() != 3 && words.size() != 6) {
        error = where + "expected 3 (x y z) or 6 (x y z nx ny nz) columns, found " +
                std::to_string(words.size());
        return false;
      }
      columns = words.size();
    } else if (words.size() != columns) {
      const bool truncated = !has_newline && words.size() < columns;
      error = where + "expected " + std::to_string(columns) + " columns, found " +
              std::to_string(words.size()) + (truncated ? " (file truncated?)" : "");
      return false;
    }
    for (std::string_view word : words) {
      double value = 0;
      if (!parseDouble(word, value)) {
        error = where + printable(word) + " is not a number";
        return false;
      }
      if (outOfFloatRange(value)) {
        error = where + printable(word) + " is out of float range";
        return false;
      }
      values.push_back(static_cast<float>(value));
    }
  }
  if (values.empty()) {
    error = "the file contains no points";
    return false;
  }
  makeFloatCloud(values, columns, cloud);
  return true;
}

// ---------------------------------------------------------------------------
// Meshes

/// Validates one polygon's corners and appends its fan triangulation. Pass
/// kUnknownVertexCount when the vertices are not all read yet and call
/// checkTriangleIndices() at the end.
bool addPolygon(const std::vector<std::int64_t> &corners, std::size_t vertex_count,
                std::vector<Triangle> &triangles, std::string &error) {
  if (corners.size() < 3) {
    error = "has fewer than 3 corners";
    return false;
  }
  for (std::int64_t corner : corners)
    if (corner < 0 || corner > std::numeric_limits<VertexIndex>::max() ||
        static_cast<std::uint64_t>(corner) >= vertex_count) {
      error = "references vertex " + std::to_string(corner) + " but there are " +
              std::to_string(vertex_count) + " vertices";
      return false;
    }
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    triangles.push_back({static_cast<VertexIndex>(corners[0]), static_cast<VertexIndex>(corners[i]),
                         static_cast<VertexIndex>(corners[i + 1])});
  return true;
}

constexpr std::size_t kUnknownVertexCount = std::numeric_limits<std::size_t>::max();

/// Triangles of a strip (every other one flipped to keep the orientation).
bool addStrip(const std::int64_t *corners, std::size_t size, std::size_t vertex_count,
              std::vector<Triangle> &triangles, std::string &error) {
  std::vector<std::int64_t> triangle(3);
  for (std::size_t k = 0; k + 2 < size; ++k) {
    triangle = {corners[k], corners[k + 1], corners[k + 2]};
    if (triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[0] == triangle[2])
      continue; // strips repeat a corner to turn; that triangle is not part of the surface
    if (k % 2 == 1)
      std::swap(triangle[0], triangle[1]);
    if (!addPolygon(triangle, vertex_count, triangles, error))
      return false;
  }
  return true;
}

/// Several strips in one list, separated by -1 (PLY "tristrips").
bool addStrips(const std::vector<std::int64_t> &corners, std::vector<Triangle> &triangles,
               std::string &error) {
  std::size_t start = 0;
  for (std::size_t i = 0; i <= corners.size(); ++i)
    if (i == corners.size() || corners[i] == -1) {
      if (!addStrip(corners.data() + start, i - start, kUnknownVertexCount, triangles, error))
        return false;
      start = i + 1;
    }
  return true;
}

bool checkTriangleIndices(std::size_t vertex_count, const std::vector<Triangle> &triangles,
                          std::string &error) {
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (VertexIndex corner : triangles[t])
      if (corner >= vertex_count) {
        error = "a face references vertex " + std::to_string(corner) + " but there are " +
                std::to_string(vertex_count) + " vertices";
        return false;
      }
  return true;
}

bool loadPlyMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  PlyHeader header;
  {
    std::istringstream in(bytes.substr(0, std::min<std::size_t>(bytes.size(), 1 << 20)));
    if (!parsePlyHeader(in, header, error) || !checkPlyBodySize(header, bytes.size(), error))
      return false;
  }
  PlyValueReader reader(std::string_view(bytes).substr(header.header_bytes), header.format);
  bool have_vertices = false, have_faces = false;
  std::vector<std::int64_t> corners;
  for (const PlyElement &element : header.elements) {
    if (have_vertices && have_faces)
      break;
    const bool is_vertex = element.name == "vertex";
    // "tristrips" lists triangle strips separated by -1 (used by some scanners).
    const bool is_strip = element.name == "tristrips";
    const bool is_face = element.name == "face" || is_strip;
    int x = -1, y = -1, z = -1, corner_list = -1;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const std::string &name = element.properties[p].name;
      const bool is_list = element.properties[p].is_list;
      if (is_vertex && !is_list) {
        if (name == "x")
          x = static_cast<int>(p);
        else if (name == "y")
          y = static_cast<int>(p);
        else if (name == "z")
          z = static_cast<int>(p);
      }
      if (is_face && is_list && (name == "vertex_indices" || name == "vertex_index"))
        corner_list = static_cast<int>(p);
    }
    if (is_vertex && (x < 0 || y < 0 || z < 0)) {
      error = "the PLY vertex element lacks x, y or z";
      return false;
    }
    if (is_vertex)
      vertices.reserve(element.count);
    // Records without properties take no bytes: billions of them would be
    // a long loop that reads nothing (a fuzz finding).
    if (element.properties.empty())
      continue;

    for (std::uint64_t r = 0; r < element.count; ++r) {
      Eigen::Vector3d point = Eigen::Vector3d::Zero();
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty &property = element.properties[p];
        double value = 0;
        bool ok = reader.read(property.is_list ? property.count_type : property.value_type, value);
        if (ok && property.is_list) {
          const bool keep = static_cast<int>(p) == corner_list;
          if (!isWholeNumberIn(value, 0, 1e6)) {
            error = "corrupt PLY file: list of " + std::to_string(value) + " items in element '" +
                    element.name + "' record " + std::to_string(r);
            return false;
          }
          const auto length = static_cast<std::size_t>(value);
          if (keep)
            corners.clear();
          for (std::size_t i = 0; ok && i < length; ++i) {
            ok = reader.read(property.value_type, value);
            if (!ok || !keep)
              continue;
            // -1 separates triangle strips; anything else must be an index.
            if (!isWholeNumberIn(value, -1, std::numeric_limits<VertexIndex>::max())) {
              error = "corrupt PLY file: vertex index " + std::to_string(value) + " in element '" +
                      element.name + "' record " + std::to_string(r);
              return false;
            }
            corners.push_back(static_cast<std::int64_t>(value));
          }
        } else if (ok && is_vertex) {
          if (static_cast<int>(p) == x)
            point.x() = value;
          else if (static_cast<int>(p) == y)
            point.y() = value;
          else if (static_cast<int>(p) == z)
            point.z() = value;
        }
        if (!ok) {
          error = "truncated or malformed PLY data in element '" + element.name + "' record " +
                  std::to_string(r);
          return false;
        }
      }
      if (is_vertex)
        vertices.push_back(point);
      if (is_face && corner_list >= 0) {
        std::string reason;
        // Faces may precede the vertices in the file: indices are checked at the end.
        if (is_strip ? !addStrips(corners, triangles, reason)
                     : !addPolygon(corners, kUnknownVertexCount, triangles, reason)) {
          error = element.name + " " + std::to_string(r) + " " + reason;
          return false;
        }
      }
    }
    have_vertices = have_vertices || is_vertex;
    have_faces = have_faces || (is_face && corner_list >= 0);
  }
  if (!have_vertices) {
    error = "the PLY file has no vertex element";
    return false;
  }
  return checkTriangleIndices(vertices.size(), triangles, error);
}

bool loadObjMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  // Faces are checked once all vertices are known: OBJ allows forward references.
  std::vector<std::vector<std::int64_t>> faces;
  std::vector<std::size_t> face_lines;
  std::size_t position = 0, line_number = 0;
  while (position < bytes.size()) {
    std::size_t end = bytes.find('\n', position);
    if (end == std::string::npos)
      end = bytes.size();
    std::string_view line(bytes.data() + position, end - position);
    position = end + 1;
    ++line_number;
    line = line.substr(0, line.find('#'));
    const std::vector<std::string_view> words = splitWords(line);
    if (words.empty())
      continue;
    const std::string where = "line " + std::to_string(line_number) + ": ";
    if (words[0] == "v") {
      Eigen::Vector3d point;
      if (words.size() < 4 || !parseDouble(words[1], point.x()) ||
          !parseDouble(words[2], point.y()) || !parseDouble(words[3], point.z())) {
        error = where + "malformed vertex";
        return false;
      }
      vertices.push_back(point);
    } else if (words[0] == "f") {
      std::vector<std::int64_t> corners;
      for (std::size_t w = 1; w < words.size(); ++w) {
        // "v", "v/vt", "v//vn" or "v/vt/vn": only the vertex index matters.
        std::int64_t index = 0;
        if (!parseInteger(words[w].substr(0, words[w].find('/')), index) || index == 0) {
          error = where + "malformed face corner " + printable(words[w]);
          return false;
        }
        // Negative indices count back from the latest vertex.
        corners.push_back(index > 0 ? index - 1
                                    : static_cast<std::int64_t>(vertices.size()) + index);
      }
      faces.push_back(std::move(corners));
      face_lines.push_back(line_number);
    }
    // Texture coordinates, normals, groups and materials are not needed.
  }
  for (std::size_t f = 0; f < faces.size(); ++f) {
    std::string reason;
    if (!addPolygon(faces[f], vertices.size(), triangles, reason)) {
      error = "line " + std::to_string(face_lines[f]) + ": face " + reason;
      return false;
    }
  }
  return true;
}

bool loadOffMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  // OFF is line oriented: one vertex or face per line, optionally followed by
  // colours, which is why tokens are not read as one flat stream.
  std::size_t position = 0, line_number = 0;
  std::vector<std::string_view> words;
  const auto nextLine = [&]() {
    while (position < bytes.size()) {
      std::size_t end = bytes.find('\n', position);
      if (end == std::string::npos)
        end = bytes.size();
      std::string_view line(bytes.data() + position, end - position);
      position = end + 1;
      ++line_number;
      words = splitWords(line.substr(0, line.find('#')));
      if (!words.empty())
        return true;
    }
    return false;
  };

  if (!nextLine()) {
    error = "the file has no OFF header";
    return false;
  }
  static const char *variants[] = {"OFF",   "COFF",   "NOFF",   "CNOFF",
                                   "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
  if (std::none_of(std::begin(variants), std::end(variants),
                   [&](const char *variant) { return words[0] == variant; })) {
    error = words[0].size() >= 3 && words[0].substr(words[0].size() - 3) == "OFF"
                ? "unsupported OFF variant " + printable(words[0])
                : "not an OFF file (first word is " + printable(words[0]) + ")";
    return false;
  }
  if (words.size() > 1 && words[1] == "BINARY") {
    error = "binary OFF files are not supported";
    return false;
  }
  // The counts follow the keyword on the same line or on the next one.
  std::size_t counts_at = 1;
  if (words.size() == 1) {
    if (!nextLine()) {
      error = "the OFF header has no vertex and face counts";
      return false;
    }
    counts_at = 0;
  }
  std::uint64_t vertex_count = 0, face_count = 0;
  if (words.size() < counts_at + 2 || !parseInteger(words[counts_at], vertex_count) ||
      !parseInteger(words[counts_at + 1], face_count)) {
    error = "line " + std::to_string(line_number) + ": malformed OFF counts";
    return false;
  }
  // Every vertex and face needs a line of at least a few bytes.
  if (static_cast<double>(vertex_count) + static_cast<double>(face_count) >
      static_cast<double>(bytes.size())) {
    error = "truncated OFF file: the counts exceed the file size";
    return false;
  }

  vertices.reserve(vertex_count);
  for (std::uint64_t v = 0; v < vertex_count; ++v) {
    Eigen::Vector3d point;
    if (!nextLine()) {
      error = "truncated OFF file: " + std::to_string(v) + " of " + std::to_string(vertex_count) +
              " vertices";
      return false;
    }
    if (words.size() < 3 || !parseDouble(words[0], point.x()) ||
        !parseDouble(words[1], point.y()) || !parseDouble(words[2], point.z())) {
      error = "line " + std::to_string(line_number) + ": malformed vertex";
      return false;
    }
    vertices.push_back(point);
  }
  std::vector<std::int64_t> corners;
  for (std::uint64_t f = 0; f < face_count; ++f) {
    if (!nextLine()) {
      error = "truncated OFF file: " + std::to_string(f) + " of " + std::to_string(face_count) +
              " faces";
      return false;
    }
    std::size_t size = 0;
    if (!parseInteger(words[0], size) || words.size() < size + 1) {
      error = "line " + std::to_string(line_number) + ": malformed face";
      return false;
    }
    corners.assign(size, 0);
    for (std::size_t i = 0; i < size; ++i)
      if (!parseInteger(words[i + 1], corners[i])) {
        error = "line " + std::to_string(line_number) + ": malformed face";
        return false;
      }
    std::string reason;
    if (!addPolygon(corners, vertices.size(), triangles, reason)) {
      error = "line " + std::to_string(line_number) + ": face " + reason;
      return false;
    }
  }
  return true;
}

/// Legacy VTK reader for POLYDATA: POINTS plus POLYGONS and TRIANGLE_STRIPS,
/// ascii or (big-endian) binary, with both the classic cell layout and the
/// OFFSETS/CONNECTIVITY layout of file version 5.
class VtkReader {
public:
  explicit VtkReader(std::string_view bytes) : bytes_(bytes) {}

  bool read(std::vector<Eigen::Vector3d> &vertices, std::vector<Triangle> &triangles,
            std::string &error) {
    std::string_view line;
    if (!nextLine(line) || !startsWith(line, "# vtk DataFile")) {
      error = "not a legacy VTK file";
      return false;
    }
    if (!nextLine(line) || !nextLine(line)) { // title, then format
      error = "incomplete VTK header";
      return false;
    }
    if (trim(line) == "BINARY")
      binary_ = true;
    else if (trim(line) != "ASCII") {
      error = "VTK header: expected ASCII or BINARY, found " + printable(trim(line));
      return false;
    }
    if (!nextNonEmptyLine(line) ||
        splitWords(line) != std::vector<std::string_view>{"DATASET", "POLYDATA"}) {
      error = "only legacy VTK POLYDATA meshes are supported";
      return false;
    }
    bool have_points = false;
    while (nextNonEmptyLine(line)) {
      const std::vector<std::string_view> words = splitWords(line);
      const std::string_view key = words[0];
      if (key == "POINTS") {
        if (!readPoints(words, vertices, error))
          return false;
        have_points = true;
      } else if (key == "POLYGONS" || key == "TRIANGLE_STRIPS" || key == "VERTICES" ||
                 key == "LINES") {
        if (!readCells(words, vertices.size(), key == "POLYGONS", key == "TRIANGLE_STRIPS",
                       triangles, error))
          return false;
      } else if (key == "POINT_DATA" || key == "CELL_DATA" || key == "FIELD" || key == "METADATA") {
        break; // attributes follow the geometry; nothing more to read
      } else {
        error = "unexpected VTK section " + printable(key);
        return false;
      }
    }
    if (!have_points) {
      error = "the VTK file has no POINTS";
      return false;
    }
    return true;
  }

private:
  bool nextLine(std::string_view &line) {
    if (position_ >= bytes_.size())
      return false;
    std::size_t end = bytes_.find('\n', position_);
    if (end == std::string_view::npos)
      end = bytes_.size();
    line = bytes_.substr(position_, end - position_);
    position_ = end + 1;
    return true;
  }

  bool nextNonEmptyLine(std::string_view &line) {
    while (nextLine(line))
      if (!trim(line).empty())
        return true;
    return false;
  }

  /// Reads `count` numbers of VTK type `type` into `out`.
  bool readValues(std::string_view type, std::uint64_t count, std::vector<double> &out,
                  std::string &error) {
    std::size_t size = 0;
    bool is_float = false, is_signed = true;
    if (type == "float")
      size = 4, is_float = true;
    else if (type == "double")
      size = 8, is_float = true;
    else if (type == "int" || type == "vtktypeint32")
      size = 4;
    else if (type == "unsigned_int" || type == "vtktypeuint32")
      size = 4, is_signed = false;
    else if (type == "long" || type == "vtktypeint64" || type == "vtkIdType")
      size = 8;
    else if (type == "unsigned_long" || type == "vtktypeuint64")
      size = 8, is_signed = false;
    else if (type == "short")
      size = 2;
    else if (type == "unsigned_short")
      size = 2, is_signed = false;
    else {
      error = "unsupported VTK data type " + printable(type);
      return false;
    }
    const double bytes_per_value = binary_ ? static_cast<double>(size) : 2.0;
    if (static_cast<double>(count) * bytes_per_value >
        static_cast<double>(bytes_.size() - std::min(position_, bytes_.size())) + 1) {
      error = "truncated VTK file";
      return false;
    }
    out.resize(count);
    for (std::uint64_t i = 0; i < count; ++i) {
      if (binary_) {
        if (position_ + size > bytes_.size()) {
          error = "truncated VTK file";
          return false;
        }
        unsigned char raw[8];
        std::memcpy(raw, bytes_.data() + position_, size);
        position_ += size;
        if (hostIsLittleEndian())
          std::reverse(raw, raw + size); // legacy binary VTK is big-endian
        out[i] = decode(raw, size, is_float, is_signed);
      } else {
        while (position_ < bytes_.size() && isBlank(bytes_[position_]))
          ++position_;
        const std::size_t start = position_;
        while (position_ < bytes_.size() && !isBlank(bytes_[position_]))
          ++position_;
        if (!parseDouble(bytes_.substr(start, position_ - start), out[i])) {
          error = start >= bytes_.size()
                      ? "truncated VTK file"
                      : "malformed VTK value " + printable(bytes_.substr(start, position_ - start));
          return false;
        }
      }
    }
    // Whatever remains of the line is read as an (empty) line by the caller.
    return true;
  }

  static double decode(const unsigned char *raw, std::size_t size, bool is_float, bool is_signed) {
    const auto get = [raw](auto value) {
      std::memcpy(&value, raw, sizeof(value));
      return static_cast<double>(value);
    };
    if (is_float)
      return size == 4 ? get(float()) : get(double());
    switch (size) {
    case 2:
      return is_signed ? get(std::int16_t()) : get(std::uint16_t());
    case 4:
      return is_signed ? get(std::int32_t()) : get(std::uint32_t());
    default:
      return is_signed ? get(std::int64_t()) : get(std::uint64_t());
    }
  }

  bool readPoints(const std::vector<std::string_view> &words,
                  std::vector<Eigen::Vector3d> &vertices, std::string &error) {
    std::uint64_t count = 0;
    if (words.size() != 3 || !parseInteger(words[1], count)) {
      error = "malformed VTK POINTS line";
      return false;
    }
    std::vector<double> values;
    if (!readValues(words[2], 3 * count, values, error))
      return false;
    vertices.resize(count);
    for (std::uint64_t i = 0; i < count; ++i)
      vertices[i] = Eigen::Vector3d(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
    return true;
  }

  bool readCells(const std::vector<std::string_view> &words, std::size_t vertex_count,
                 bool polygons, bool strips, std::vector<Triangle> &triangles, std::string &error) {
    std::uint64_t cell_count = 0, total = 0;
    if (words.size() != 3 || !parseInteger(words[1], cell_count) ||
        !parseInteger(words[2], total)) {
      error = "malformed VTK " + std::string(words[0]) + " line";
      return false;
    }
    // Build (offsets, connectivity) from whichever layout the file uses.
    std::vector<double> offsets, connectivity;
    const std::size_t saved = position_;
    std::string_view line;
    if (nextNonEmptyLine(line) && startsWith(trim(line), "OFFSETS")) {
      const std::vector<std::string_view> offset_words = splitWords(line);
      if (offset_words.size() != 2) {
        error = "malformed VTK OFFSETS line";
        return false;
      }
      if (!readValues(offset_words[1], cell_count, offsets, error))
        return false;
      if (!nextNonEmptyLine(line) || !startsWith(trim(line), "CONNECTIVITY")) {
        error = "VTK OFFSETS without CONNECTIVITY";
        return false;
      }
      const std::vector<std::string_view> connectivity_words = splitWords(line);
      if (connectivity_words.size() != 2) {
        error = "malformed VTK CONNECTIVITY line";
        return false;
      }
      if (!readValues(connectivity_words[1], total, connectivity, error))
        return false;
    } else {
      position_ = saved;
      std::vector<double> cells;
      if (!readValues("int", total, cells, error))
        return false;
      offsets.push_back(0);
      std::size_t at = 0;
      for (std::uint64_t c = 0; c < cell_count; ++c) {
        if (at >= cells.size() || !isWholeNumberIn(cells[at], 0, cells.size() - at - 1)) {
          error = "corrupt VTK cell list";
          return false;
        }
        const auto size = static_cast<std::size_t>(cells[at]);
        connectivity.insert(connectivity.end(), cells.begin() + at + 1,
                            cells.begin() + at + 1 + size);
        at += size + 1;
        offsets.push_back(static_cast<double>(connectivity.size()));
      }
    }
    if (!polygons && !strips)
      return true;
    // Values are read as doubles; anything not a whole number in range would
    // make the integer conversions below undefined.
    for (double corner : connectivity)
      if (!isWholeNumberIn(corner, 0, static_cast<double>(vertex_count) - 1)) {
        error = "VTK cell references vertex " + printableNumber(corner) + " but there are " +
                std::to_string(vertex_count) + " vertices";
        return false;
      }
    std::vector<std::int64_t> corners;
    for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
      if (!isWholeNumberIn(offsets[c], 0, static_cast<double>(connectivity.size())) ||
          !isWholeNumberIn(offsets[c + 1], offsets[c], static_cast<double>(connectivity.size()))) {
        error = "corrupt VTK cell offsets";
        return false;
      }
      corners.assign(connectivity.begin() + static_cast<std::ptrdiff_t>(offsets[c]),
                     connectivity.begin() + static_cast<std::ptrdiff_t>(offsets[c + 1]));
      std::string reason;
      if (polygons && !addPolygon(corners, vertex_count, triangles, reason)) {
        error = "VTK polygon " + std::to_string(c) + " " + reason;
        return false;
      }
      if (strips && !addStrip(corners.data(), corners.size(), vertex_count, triangles, reason)) {
        error = "VTK triangle strip " + std::to_string(c) + " " + reason;
        return false;
      }
    }
    return true;
  }

  std::string_view bytes_;
  std::size_t position_ = 0;
  bool binary_ = false;
};

bool loadVtkMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  return VtkReader(bytes).read(vertices, triangles, error);
}

// ---------------------------------------------------------------------------
// Saving

/// PCL's mesh writers declare properties by field name but write values only
/// for the types they expect, so a known name with an unexpected type (say a
/// float64 normal_x) yields a corrupt file. Keep only fields they handle.
bool writerHandlesField(const pcl::PCLPointField &field) {
  if (field.count > 1)
    return false;
  static const char *float_fields[] = {"x",        "y",        "z",        "rgb",
                                       "normal_x", "normal_y", "normal_z", "curvature"};
  for (const char *name : float_fields)
    if (field.name == name)
      return field.datatype == pcl::PCLPointField::FLOAT32;
  return field.name == "rgba" && field.datatype == pcl::PCLPointField::UINT32;
}

bool checkMeshForSaving(const pcl::PolygonMesh &mesh, std::string &error) {
  if (!checkCloudLayout(mesh.cloud, error)) {
    if (error == "the file contains no points")
      error = "the mesh has no vertices";
    return false;
  }
  const std::size_t points = static_cast<std::size_t>(mesh.cloud.width) * mesh.cloud.height;
  for (std::size_t p = 0; p < mesh.polygons.size(); ++p) {
    const pcl::Indices &corners = mesh.polygons[p].vertices;
    if (corners.empty()) {
      error = "polygon " + std::to_string(p) + " has no vertices";
      return false;
    }
    for (const pcl::index_t corner : corners)
      if (corner < 0 || static_cast<std::size_t>(corner) >= points) {
        error = "polygon " + std::to_string(p) + " references vertex " + std::to_string(corner) +
                " but the cloud has " + std::to_string(points) + " points";
        return false;
      }
  }
  return true;
}

std::string unknownFormat(const std::string &extension, const char *kind, const char *known) {
  return (extension.empty() ? std::string("no file extension to tell the ") + kind + " format"
                            : "unknown " + std::string(kind) + " format '" + extension + "'") +
         " (use " + known + ")";
}

} // namespace

// ---------------------------------------------------------------------------
// Public functions

std::string fileExtension(const std::string &path) {
  return toLower(fs::path(path).extension().string());
}

bool hasNormals(const pcl::PCLPointCloud2 &cloud) {
  return isSingleFloatField(findField(cloud, "normal_x")) &&
         isSingleFloatField(findField(cloud, "normal_y")) &&
         isSingleFloatField(findField(cloud, "normal_z"));
}

namespace {

/// The mesh reader for the file's extension (faces may be absent).
bool readMeshFile(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                  std::vector<Triangle> &triangles, std::string &reason) {
  const std::string extension = fileExtension(path);
  if (extension == ".ply")
    return loadPlyMesh(path, vertices, triangles, reason);
  if (extension == ".obj")
    return loadObjMesh(path, vertices, triangles, reason);
  if (extension == ".off")
    return loadOffMesh(path, vertices, triangles, reason);
  if (extension == ".vtk")
    return loadVtkMesh(path, vertices, triangles, reason);
  reason = unknownFormat(extension, "mesh", ".ply, .obj, .off or .vtk");
  return false;
}

/// The vertices of an .obj, .off or .vtk mesh as a cloud, in file order;
/// faces may be absent (a vertex-only OFF is a point cloud).
bool loadMeshVerticesCloud(const std::string &path, pcl::PCLPointCloud2 &cloud,
                           std::string &reason) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
  if (!readMeshFile(path, vertices, triangles, reason))
    return false;
  if (vertices.empty()) {
    reason = "the file contains no vertices";
    return false;
  }
  std::vector<float> values;
  values.reserve(3 * vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double value = vertices[i][k];
      if (outOfFloatRange(value)) {
        reason = "vertex " + std::to_string(i) + " is out of float range";
        return false;
      }
      values.push_back(static_cast<float>(value));
    }
  makeFloatCloud(values, 3, cloud);
  return true;
}

} // namespace

bool loadPointCloud(const std::string &path, pcl::PCLPointCloud2 &cloud, std::string &error,
                    Eigen::Vector4f *sensor_origin) {
  cloud = pcl::PCLPointCloud2();
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  std::string reason;
  bool ok = false;
  try {
    const std::string extension = fileExtension(path);
    std::uintmax_t size = 0;
    if (!checkInputFile(path, size, reason))
      ok = false;
    else if (extension == ".pcd")
      ok = loadPcdCloud(path, size, cloud, origin, reason);
    else if (extension == ".ply")
      ok = loadPlyCloud(path, size, cloud, reason);
    else if (extension == ".xyz" || extension == ".txt")
      ok = loadXyzCloud(path, cloud, reason);
    else if (extension == ".obj" || extension == ".off" || extension == ".vtk")
      ok = loadMeshVerticesCloud(path, cloud, reason);
    else
      reason = unknownFormat(extension, "point cloud",
                             ".pcd, .ply, .xyz, .txt, or a mesh's vertices: .obj, .off, .vtk");
    ok = ok && checkCloudLayout(cloud, reason);
  } catch (const std::exception &exception) {
    reason = std::string("unexpected failure: ") + exception.what();
    ok = false;
  }
  if (!ok) {
    cloud = pcl::PCLPointCloud2();
    origin = Eigen::Vector4f::Zero();
    error = path + ": " + reason;
  }
  if (sensor_origin)
    *sensor_origin = origin;
  return ok;
}

bool loadMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
              std::vector<Triangle> &triangles, std::string &error) {
  vertices.clear();
  triangles.clear();
  std::string reason;
  bool ok = false;
  try {
    std::uintmax_t size = 0;
    ok = checkInputFile(path, size, reason) && readMeshFile(path, vertices, triangles, reason);
    if (ok && triangles.empty()) {
      reason = "the file contains no faces";
      ok = false;
    }
  } catch (const std::exception &exception) {
    reason = std::string("unexpected failure: ") + exception.what();
    ok = false;
  }
  if (!ok) {
    vertices.clear();
    triangles.clear();
    error = path + ": " + reason;
  }
  return ok;
}

bool isMeshOutputSupported(const std::string &path) {
  const std::string extension = fileExtension(path);
  return extension == ".ply" || extension == ".vtk" || extension == ".obj";
}

bool saveMesh(const std::string &path, const pcl::PolygonMesh &mesh, std::string &error,
              bool binary) {
  std::string reason;
  bool created = false, ok = false;
  try {
    const std::string extension = fileExtension(path);
    if (!isMeshOutputSupported(path)) {
      reason = unknownFormat(extension, "mesh", ".ply, .vtk or .obj");
    } else if (checkMeshForSaving(mesh, reason)) {
      // PCL's writers do not all check that the file opened; find out first.
      std::error_code code;
      if (fs::is_directory(path, code)) {
        reason = "is a directory";
      } else if (!std::ofstream(path, std::ios::binary | std::ios::trunc)) {
        reason = std::string("cannot open for writing: ") + std::strerror(errno);
      } else {
        created = true;
        const pcl::PolygonMesh *to_write = &mesh;
        pcl::PolygonMesh filtered;
        const auto handled =
            std::count_if(mesh.cloud.fields.begin(), mesh.cloud.fields.end(), writerHandlesField);
        if (static_cast<std::size_t>(handled) != mesh.cloud.fields.size()) {
          filtered = mesh;
          auto &fields = filtered.cloud.fields;
          fields.erase(std::remove_if(fields.begin(), fields.end(),
                                      [](const pcl::PCLPointField &field) {
                                        return !writerHandlesField(field);
                                      }),
                       fields.end());
          to_write = &filtered;
        }
        // Enough digits that float coordinates survive the text formats.
        const unsigned precision = std::numeric_limits<float>::max_digits10;
        int status = 0;
        if (extension == ".ply")
          status = binary ? pcl::io::savePLYFileBinary(path, *to_write)
                          : pcl::io::savePLYFile(path, *to_write, precision);
        else if (extension == ".vtk")
          status = pcl::io::saveVTKFile(path, *to_write, precision);
        else
          status = pcl::io::saveOBJFile(path, *to_write, precision);
        if (status < 0)
          reason = "PCL's writer failed";
        else if (fs::file_size(path, code) == 0 || code)
          reason = "nothing was written";
        else
          ok = true;
      }
    }
  } catch (const std::exception &exception) {
    reason = std::string("unexpected failure: ") + exception.what();
    ok = false;
  }
  if (!ok) {
    if (created) {
      std::error_code ignored;
      fs::remove(path, ignored);
    }
    error = path + ": " + reason;
  }
  return ok;
}

bool saveMedialAxis(const std::string &path, const MedialAxis &axis, std::string &error,
                    bool binary) {
  const std::size_t nodes = axis.node_positions.size();
  std::string reason;
  if (fileExtension(path) != ".ply")
    reason = unknownFormat(fileExtension(path), "medial axis", ".ply");
  else if (axis.node_radii.size() != nodes || axis.node_side.size() != nodes)
    reason = "the medial axis has " + std::to_string(nodes) + " nodes but " +
             std::to_string(axis.node_radii.size()) + " radii and " +
             std::to_string(axis.node_side.size()) + " sides";
  else if (nodes > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    reason = "too many nodes for PLY's int indices";
  for (std::size_t c = 0; reason.empty() && c < axis.curves.size(); ++c)
    if (axis.curves[c][0] >= nodes || axis.curves[c][1] >= nodes)
      reason = "curve " + std::to_string(c) + " joins a node that does not exist";
  std::error_code code;
  if (reason.empty() && fs::is_directory(path, code))
    reason = "is a directory";
  if (!reason.empty()) {
    error = path + ": " + reason;
    return false;
  }

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    error = path + ": cannot open for writing: " + std::strerror(errno);
    return false;
  }
  out << "ply\nformat "
      << (!binary                ? "ascii"
          : hostIsLittleEndian() ? "binary_little_endian"
                                 : "binary_big_endian")
      << " 1.0\n"
      << "comment pcl_ms medial axis: A1^4 nodes (Voronoi vertices that are poles) with the\n"
      << "comment radius of their maximal ball; inside 1 = inside a closed component,\n"
      << "comment 0 = outside, 2 = next to an open part; edges are A1^3 shock curves\n"
      << "element vertex " << nodes << "\n"
      << "property float x\nproperty float y\nproperty float z\nproperty float radius\n"
      << "property uchar inside\n"
      << "element edge " << axis.curves.size() << "\n"
      << "property int vertex1\nproperty int vertex2\nend_header\n";
  if (binary) {
    for (std::size_t n = 0; n < nodes; ++n) {
      const float values[4] = {static_cast<float>(axis.node_positions[n].x()),
                               static_cast<float>(axis.node_positions[n].y()),
                               static_cast<float>(axis.node_positions[n].z()),
                               static_cast<float>(axis.node_radii[n])};
      out.write(reinterpret_cast<const char *>(values), sizeof(values));
      out.put(static_cast<char>(axis.node_side[n]));
    }
    for (const auto &curve : axis.curves) {
      const std::int32_t ends[2] = {static_cast<std::int32_t>(curve[0]),
                                    static_cast<std::int32_t>(curve[1])};
      out.write(reinterpret_cast<const char *>(ends), sizeof(ends));
    }
  } else {
    out.precision(std::numeric_limits<float>::max_digits10);
    for (std::size_t n = 0; n < nodes; ++n)
      out << static_cast<float>(axis.node_positions[n].x()) << ' '
          << static_cast<float>(axis.node_positions[n].y()) << ' '
          << static_cast<float>(axis.node_positions[n].z()) << ' '
          << static_cast<float>(axis.node_radii[n]) << ' ' << int(axis.node_side[n]) << '\n';
    for (const auto &curve : axis.curves)
      out << curve[0] << ' ' << curve[1] << '\n';
  }
  out.close();
  if (!out) {
    fs::remove(path, code);
    error = path + ": writing failed";
    return false;
  }
  return true;
}

} // namespace pcl_ms

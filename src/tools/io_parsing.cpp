// SPDX-License-Identifier: GPL-3.0-or-later
// Parsing pieces that the file readers share (see io_parsing.h).
#include "io_parsing.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

namespace pcl_ms {
namespace io_detail {

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

/// Printable form of a header word for error messages (garbage stays short).
bool WordLines::next() {
  while (position_ < bytes_.size()) {
    std::size_t end = bytes_.find('\n', position_);
    ends_with_newline_ = end != std::string_view::npos;
    if (!ends_with_newline_)
      end = bytes_.size();
    const std::string_view line = bytes_.substr(position_, end - position_);
    position_ = end + 1;
    ++line_number_;
    words_ = splitWords(line.substr(0, line.find('#')));
    if (!words_.empty())
      return true;
  }
  words_.clear();
  return false;
}

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
std::string unknownFormat(const std::string &extension, const char *kind, const char *known) {
  return (extension.empty() ? std::string("no file extension to tell the ") + kind + " format"
                            : "unknown " + std::string(kind) + " format '" + extension + "'") +
         " (use " + known + ")";
}

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

bool hostIsLittleEndian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

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

} // namespace io_detail
} // namespace pcl_ms

// SPDX-License-Identifier: GPL-3.0-or-later
// Parsing pieces that the file readers share (see io_parsing.h).
#include "io_parsing.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
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

namespace {

/// `text` without the leading and trailing characters `is_blank` names.
template <typename IsBlank> std::string_view trimmed(std::string_view text, IsBlank is_blank) {
  while (!text.empty() && is_blank(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back()))
    text.remove_suffix(1);
  return text;
}

/// Blanks as PCL's PCD reader sees them in a header line: spaces, tabs and
/// carriage returns only (a vertical tab or form feed is part of a word).
bool isPcdBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

/// The words of `text` between separators.
template <typename Separates>
std::vector<std::string_view> splitAt(std::string_view text, Separates separates) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && separates(text[i]))
      ++i;
    const std::size_t start = i;
    while (i < text.size() && !separates(text[i]))
      ++i;
    if (i > start)
      words.push_back(text.substr(start, i - start));
  }
  return words;
}

/// Words as PCL's PCD reader splits a header line (isPcdBlank).
std::vector<std::string_view> splitPcdWords(std::string_view text) {
  return splitAt(text, isPcdBlank);
}

/// Applies an obj_info line as PCL's PLY reader does: split at runs of
/// spaces and tabs (boost::split, compressed, so a line ending in one has an
/// empty last word), num_cols and num_rows set the cloud's width and height
/// through atoi, from the third word of three or more.
void applyObjInfo(std::string_view line, PlyHeader &header) {
  std::vector<std::string_view> words;
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = line.find_first_of(" \t", start);
    words.push_back(line.substr(start, end == std::string_view::npos ? end : end - start));
    if (end == std::string_view::npos)
      break;
    start = line.find_first_not_of(" \t", end);
    if (start == std::string_view::npos) {
      words.emplace_back();
      break;
    }
  }
  if (words.size() < 3)
    return;
  // atoi is (int) strtol in glibc; PCL stores the int in a uint32 field.
  const auto value = static_cast<std::uint32_t>(
      static_cast<int>(std::strtol(std::string(words[2]).c_str(), nullptr, 10)));
  if (words[1] == "num_cols")
    header.grid_width = value;
  else if (words[1] == "num_rows")
    header.grid_height = value;
}

} // namespace

std::string_view trim(std::string_view text) { return trimmed(text, isBlank); }

std::vector<std::string_view> splitWords(std::string_view text) { return splitAt(text, isBlank); }

bool startsWith(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

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
  // PCL's parser reads the magic from the file's first three bytes.
  if (!readHeaderLine(in, line, kMaxHeaderLine) || !startsWith(line, "ply") ||
      trim(line) != "ply") {
    error = "not a PLY file (no 'ply' magic line)";
    return false;
  }
  // A carriage return right after the magic makes PCL's parser break lines
  // at carriage returns and skip the character after each: only a header
  // whose every line ends in "\r\n", with no other carriage return, reads
  // the same both ways (fuzz_binary_layout finding: a magic line of many).
  const bool breaks_at_carriage_returns = line.size() > 3 && line[3] == '\r';
  auto endsWithCrLf = [&](const std::string &text) {
    return !in.eof() && !text.empty() && text.find('\r') == text.size() - 1;
  };
  if (breaks_at_carriage_returns && !endsWithCrLf(line)) {
    error = "PLY magic line: 'ply' followed by more than \\r\\n";
    return false;
  }
  std::size_t line_number = 1;
  bool has_format = false;
  while (true) {
    if (!readHeaderLine(in, line, kMaxHeaderLine) || ++line_number > kMaxHeaderLines) {
      error = "incomplete PLY header (no end_header)";
      return false;
    }
    if (breaks_at_carriage_returns && !endsWithCrLf(line)) {
      error = "PLY header line " + std::to_string(line_number) +
              ": does not end in \\r\\n like the magic line (or holds another \\r)";
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
    } else if (key == "comment") {
      continue;
    } else if (key == "obj_info") {
      header.has_obj_info = true;
      applyObjInfo(line, header);
      continue;
    } else if (key == "format") {
      // PCL's parser takes one format line, of three words, version 1.0.
      if (words.size() < 2) {
        error = where + "missing format";
        return false;
      }
      if (has_format) {
        error = where + "a second format line";
        return false;
      }
      if (words.size() != 3 || words[2] != "1.0") {
        error = where + "PLY version " + printable(words.size() > 2 ? words[2] : "(none)") +
                " is not supported (1.0 only)";
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
      if (header.find(element.name)) {
        error = where + "element " + printable(words[1]) + " is declared twice";
        return false;
      }
      // PCL keeps a grid that obj_info lines set in full before the vertices.
      if (element.name == "vertex" && (header.grid_width == 0 || header.grid_height == 0)) {
        header.grid_width = static_cast<std::uint32_t>(element.count);
        header.grid_height = 1;
      }
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
      std::vector<PlyProperty> &properties = header.elements.back().properties;
      if (std::any_of(properties.begin(), properties.end(),
                      [&](const PlyProperty &other) { return other.name == property.name; })) {
        error = where + "property " + printable(property.name) + " is declared twice";
        return false;
      }
      properties.push_back(std::move(property));
    } else {
      error = where + "unknown keyword " + printable(key);
      return false;
    }
  }
  if (!has_format) {
    error = "PLY header has no format line";
    return false;
  }
  // Records without properties hold nothing, yet PCL's parser walks them
  // one by one: a huge count of them would hang it.
  for (const PlyElement &element : header.elements)
    if (element.properties.empty() && element.count > 0) {
      error = "PLY element " + printable(element.name) + " declares " +
              std::to_string(element.count) + " records but no properties";
      return false;
    }
  // PCL sizes the vertex data for its grid and aborts on a vertex beyond it;
  // a grid larger than both the vertices and the range grid only allocates.
  if (const PlyElement *vertex = header.find("vertex")) {
    const std::uint64_t grid = std::uint64_t{header.grid_width} * header.grid_height;
    const PlyElement *range_grid = header.find("range_grid");
    if (grid < vertex->count ||
        grid > std::max(vertex->count, range_grid ? range_grid->count : 0)) {
      error = "PLY header: obj_info num_cols and num_rows give a " +
              std::to_string(header.grid_width) + " x " + std::to_string(header.grid_height) +
              " grid for " + std::to_string(vertex->count) + " vertices";
      return false;
    }
  }
  const std::streampos data_begins = in.tellg();
  if (data_begins < 0) { // end_header ends the file without a line break
    error = "truncated PLY file: the header's last line is cut short";
    return false;
  }
  header.header_bytes = static_cast<std::uint64_t>(data_begins);
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

// ---------------------------------------------------------------------------
// PCD header

namespace {

/// PCL's reader (1.13) does not stop at the DATA line: it goes on reading
/// lines and applies any that start like a keyword (it compares prefixes)
/// until one does not. Emulates that on the lines after DATA and fails when
/// one of them would change the header PCL reads.
bool dataReadsAsHeader(std::istream &in, std::string &keyword) {
  static constexpr std::string_view kKeywords[] = {"FIELDS", "COLUMNS", "SIZE",      "TYPE",
                                                   "COUNT",  "WIDTH",   "HEIGHT",    "POINTS",
                                                   "DATA",   "VERSION", "VIEWPOINT", "#"};
  for (;;) {
    int c = in.get();
    if (c == std::char_traits<char>::eof())
      return false;
    if (c == '\n') // an empty line: PCL skips it
      continue;
    while (c != '\n' && c != std::char_traits<char>::eof() && std::isspace(c))
      c = in.get();
    std::string word;
    while (c != '\n' && c != std::char_traits<char>::eof() && !std::isspace(c) &&
           word.size() < 16) {
      word.push_back(static_cast<char>(c));
      c = in.get();
    }
    const auto matches = [&](std::string_view key) { return startsWith(word, key); };
    const auto found = std::find_if(std::begin(kKeywords), std::end(kKeywords), matches);
    if (found == std::end(kKeywords))
      return false;
    if (*found != "#" && *found != "VERSION") { // PCL skips these and reads on
      keyword = std::string(*found);
      return true;
    }
    if (c != '\n')
      in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
}

} // namespace

bool parsePcdHeader(std::istream &in, PcdHeader &header, std::string &error) {
  header = PcdHeader();
  std::vector<std::string> names, sizes, types, counts;
  bool has_fields = false, has_size = false, has_type = false, has_count = false;
  bool has_width = false, has_points = false;
  std::string data_kind;

  std::string line;
  std::size_t line_number = 0;
  while (data_kind.empty()) {
    if (!readHeaderLine(in, line, kMaxHeaderLine) || ++line_number > kMaxHeaderLines) {
      error = line_number <= 1 ? "not a PCD file" : "incomplete PCD header (no DATA line)";
      return false;
    }
    const std::string_view text = trimmed(line, isPcdBlank);
    if (text.empty() && !line.empty()) {
      // PCL's reader skips empty lines but crashes after one of blanks only.
      error = "PCD header line " + std::to_string(line_number) + " holds only blanks";
      return false;
    }
    if (text.empty() || text.front() == '#')
      continue;
    const std::vector<std::string_view> words = splitPcdWords(text);
    const std::string_view key = words.front();
    const auto values = [&]() { return std::vector<std::string>(words.begin() + 1, words.end()); };
    const auto badValue = [&]() {
      error =
          "PCD header line " + std::to_string(line_number) + ": bad " + std::string(key) + " value";
      return false;
    };
    const auto declaredTwice = [&]() {
      error = "PCD header line " + std::to_string(line_number) + ": a second " + std::string(key) +
              " line";
      return false;
    };
    // PCL's reader holds these counts in 32 bits and refuses a WIDTH or
    // HEIGHT beyond them even when a later line corrects it.
    const auto parseCount = [&](std::uint64_t &count) {
      return words.size() == 2 && parseInteger(words[1], count) && count <= UINT32_MAX;
    };
    if (key == "VERSION") {
      continue;
    } else if (key == "VIEWPOINT") {
      if (words.size() != 8)
        return badValue();
      for (std::size_t k = 0; k < 7; ++k)
        if (!parseDouble(words[k + 1], header.viewpoint[k]))
          return badValue();
    } else if (key == "FIELDS" || key == "COLUMNS") {
      if (has_fields)
        return declaredTwice();
      names = values();
      has_fields = true;
    } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
      // PCL's reader checks each of these lines against the FIELDS line
      // read before it, so they must follow it, in this order: TYPE after
      // SIZE, COUNT after both.
      std::vector<std::string> &list = key == "SIZE" ? sizes : key == "TYPE" ? types : counts;
      bool &seen = key == "SIZE" ? has_size : key == "TYPE" ? has_type : has_count;
      if (seen)
        return declaredTwice();
      if ((key != "SIZE" && !has_size) || (key == "COUNT" && !has_type)) {
        error = "PCD header line " + std::to_string(line_number) + ": " + std::string(key) +
                (key == "TYPE" ? " before SIZE" : " before SIZE and TYPE");
        return false;
      }
      if (words.size() - 1 != names.size()) {
        error = "PCD header line " + std::to_string(line_number) + ": " + std::string(key) +
                " lists " + std::to_string(words.size() - 1) + " entries, FIELDS before it " +
                std::to_string(names.size());
        return false;
      }
      list = values();
      seen = true;
    } else if (key == "WIDTH") {
      if (!parseCount(header.width))
        return badValue();
      has_width = true;
    } else if (key == "HEIGHT") {
      if (!parseCount(header.height))
        return badValue();
    } else if (key == "POINTS") {
      if (!has_fields) { // PCL's reader sizes the data from the fields here
        error = "PCD header line " + std::to_string(line_number) + ": POINTS before FIELDS";
        return false;
      }
      if (!parseCount(header.points))
        return badValue();
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
  const std::streampos data_begins = in.tellg();
  if (data_begins < 0) { // the DATA line ends the file
    error = "truncated PCD file: nothing follows the header";
    return false;
  }
  header.header_bytes = static_cast<std::uint64_t>(data_begins);
  header.header_lines = line_number;

  if (data_kind == "ascii") {
    header.data = PcdData::Ascii;
  } else if (data_kind == "binary") {
    header.data = PcdData::Binary;
  } else if (data_kind == "binary_compressed") {
    header.data = PcdData::BinaryCompressed;
  } else {
    error = "PCD header: unknown DATA kind " + printable(data_kind);
    return false;
  }
  if (!has_fields || names.empty() || !has_size || !has_type || !has_width || !has_points) {
    error = "incomplete PCD header (FIELDS, SIZE, TYPE, WIDTH and POINTS are required)";
    return false;
  }
  if (sizes.size() != names.size() || types.size() != names.size() ||
      (!counts.empty() && counts.size() != names.size())) {
    error = "PCD header: FIELDS, SIZE, TYPE and COUNT list different numbers of entries";
    return false;
  }
  for (std::size_t f = 0; f < names.size(); ++f) {
    PcdField field;
    field.name = names[f];
    if (!parseInteger(std::string_view(sizes[f]), field.size) ||
        (field.size != 1 && field.size != 2 && field.size != 4 && field.size != 8)) {
      error = "PCD header: field '" + field.name + "' has an invalid SIZE";
      return false;
    }
    field.type = types[f].size() == 1 ? types[f][0] : '?';
    if ((field.type != 'I' && field.type != 'U' && field.type != 'F') ||
        (field.type == 'F' && field.size != 4 && field.size != 8)) {
      error = "PCD header: field '" + field.name + "' has an invalid TYPE";
      return false;
    }
    if (!counts.empty() && (!parseInteger(std::string_view(counts[f]), field.count) ||
                            field.count == 0 || field.count > 1000000)) {
      error = "PCD header: field '" + field.name + "' has an invalid COUNT";
      return false;
    }
    field.offset = header.point_bytes;
    header.point_bytes += std::uint64_t(field.size) * field.count;
    header.values_per_point += field.count;
    header.fields.push_back(field);
  }
  // WIDTH and HEIGHT are 32-bit (parseCount), so their product cannot wrap.
  if (header.width * header.height != header.points) {
    error = "PCD header: WIDTH x HEIGHT (" + std::to_string(header.width) + " x " +
            std::to_string(header.height) + ") differs from POINTS (" +
            std::to_string(header.points) + ")";
    return false;
  }
  if (header.points == 0) {
    error = "the file contains no points";
    return false;
  }
  std::string keyword;
  if (dataReadsAsHeader(in, keyword)) {
    error =
        "corrupt PCD file: the data after the DATA line begins like a " + keyword + " header line";
    return false;
  }
  in.clear();
  in.seekg(static_cast<std::streamoff>(header.header_bytes));
  return true;
}

} // namespace io_detail
} // namespace pcl_ms

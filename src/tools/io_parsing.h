// SPDX-License-Identifier: GPL-3.0-or-later
// Parsing pieces that the file readers share: words and numbers of text
// formats, whole files and header lines read with limits, and the PLY header.
// Internal to the library: not installed.
#pragma once

#include <array>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace pcl_ms {
namespace io_detail {

std::string toLower(std::string text);
bool isBlank(char c);
std::string_view trim(std::string_view text);
std::vector<std::string_view> splitWords(std::string_view text);
bool startsWith(std::string_view text, std::string_view prefix);

/// The whole token as a number (a leading '+' allowed), nothing else.
template <typename Number> bool parseNumber(std::string_view token, Number &value) {
  if (!token.empty() && token.front() == '+')
    token.remove_prefix(1);
  if (token.empty())
    return false;
  const char *last = token.data() + token.size();
  const auto [end, code] = std::from_chars(token.data(), last, value);
  return code == std::errc() && end == last;
}

inline bool parseDouble(std::string_view token, double &value) { return parseNumber(token, value); }

template <typename Integer> bool parseInteger(std::string_view token, Integer &value) {
  return parseNumber(token, value);
}

/// The lines of a text file that hold words once a '#' comment is cut off,
/// one at a time (the .xyz, .obj and .off readers).
class WordLines {
public:
  explicit WordLines(std::string_view bytes) : bytes_(bytes) {}
  /// Moves to the next line with words; false at the end of the bytes.
  bool next();
  const std::vector<std::string_view> &words() const { return words_; }
  /// 1-based, counting every line, blank and comment lines too.
  std::size_t lineNumber() const { return line_number_; }
  /// False for a last line that the file ends without a newline.
  bool endsWithNewline() const { return ends_with_newline_; }

private:
  std::string_view bytes_;
  std::size_t position_ = 0, line_number_ = 0;
  bool ends_with_newline_ = true;
  std::vector<std::string_view> words_;
};

/// Printable form of a header word for error messages (garbage stays short).
std::string printable(std::string_view word);
/// True when `value` is a whole number in [low, high]; NaN and infinities are not.
bool isWholeNumberIn(double value, double low, double high);
/// A number from a file for an error message, in the shortest form that reads back.
std::string printableNumber(double value);

/// "unknown <kind> format '.x' (use <known>)", or the same for no extension.
std::string unknownFormat(const std::string &extension, const char *kind, const char *known);

/// Checks that `path` names a readable, non-empty regular file.
bool checkInputFile(const std::string &path, std::uintmax_t &size, std::string &error);
/// The whole file, after checkInputFile().
bool readFileBytes(const std::string &path, std::string &bytes, std::string &error);
/// Reads one header line of at most `max_length` characters (without the
/// newline). False at end of file or when the line is longer: a binary file
/// must not make us swallow megabytes looking for a newline.
bool readHeaderLine(std::istream &in, std::string &line, std::size_t max_length);
inline constexpr std::size_t kMaxHeaderLine = 4096;
inline constexpr std::size_t kMaxHeaderLines = 100000;

bool hostIsLittleEndian();

// ---------------------------------------------------------------------------
// PLY header (used to validate clouds and to read meshes)

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
  /// PCL's reader takes a cloud's width and height from obj_info lines.
  bool has_obj_info = false;
  /// The width and height PCL's reader gives the cloud by the end of the
  /// header (obj_info num_cols and num_rows, else the vertex count by 1):
  /// it sizes the vertex data for that many points.
  std::uint32_t grid_width = 0, grid_height = 0;

  const PlyElement *find(const std::string &name) const {
    for (const PlyElement &element : elements)
      if (element.name == name)
        return &element;
    return nullptr;
  }
};

bool parsePlyType(std::string_view word, PlyType &type);
std::size_t plyTypeSize(PlyType type);
bool parsePlyHeader(std::istream &in, PlyHeader &header, std::string &error);
/// Rejects files shorter than the smallest body their header allows, which
/// catches truncation and absurd element counts before anything is allocated.
bool checkPlyBodySize(const PlyHeader &header, std::uintmax_t file_size, std::string &error);

// ---------------------------------------------------------------------------
// PCD header (checked before PCL's reader sees a file; read by the MPI tool)

enum class PcdData { Ascii, Binary, BinaryCompressed };

struct PcdField {
  std::string name;
  unsigned size = 4;        // bytes of one value: 1, 2, 4 or 8
  char type = 'F';          // 'F', 'I' or 'U'
  unsigned count = 1;       // values per point
  std::uint64_t offset = 0; // byte offset in a binary record
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0, height = 1, points = 0;
  std::array<double, 7> viewpoint = {0, 0, 0, 1, 0, 0, 0}; // tx ty tz qw qx qy qz
  PcdData data = PcdData::Ascii;
  std::uint64_t header_bytes = 0; // where the data begins
  std::size_t header_lines = 0;
  std::uint64_t point_bytes = 0;      // one binary record
  std::uint64_t values_per_point = 0; // one ASCII line

  const PcdField *find(std::string_view name) const {
    for (const PcdField &field : fields)
      if (field.name == name)
        return &field;
    return nullptr;
  }
};

/// Reads and checks a PCD header: known keywords only, consistent field
/// lists, WIDTH x HEIGHT = POINTS > 0. Also rejects a file whose data begins
/// with a line PCL's reader would take for one more header line (it keeps
/// parsing keywords after DATA), since PCL then reads the body with a layout
/// the file does not have. Leaves `in` at the first byte of the data.
bool parsePcdHeader(std::istream &in, PcdHeader &header, std::string &error);

} // namespace io_detail
} // namespace pcl_ms

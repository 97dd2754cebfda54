// SPDX-License-Identifier: GPL-3.0-or-later
// STL reader, ASCII and binary (see mesh_readers.h). STL stores every facet
// with its own three corner positions, so shared corners are welded here into
// one vertex each.
#include "mesh_readers.h"

#include "io_parsing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <unordered_map>

namespace pcl_ms {
namespace io_detail {
namespace {

constexpr std::uint64_t kBinaryHeaderBytes = 84; // 80-byte header + uint32 count
constexpr std::uint64_t kBinaryFacetBytes = 50;  // normal, 3 corners, uint16 attribute

/// Turns corner positions into vertices: the first corner at a position
/// becomes a vertex (so vertices are numbered in order of first use, the
/// same for the same file), later corners at the same position reuse it.
/// Positions are compared as float bit patterns, with -0 read as +0: the
/// same value written twice gives the same bits, and nothing closer but
/// different is merged.
class Welder {
public:
  Welder(std::vector<Eigen::Vector3d> &vertices, std::vector<Triangle> &triangles)
      : vertices_(vertices), triangles_(triangles) {}

  void reserve(std::uint64_t facets) {
    // Closed meshes have about half as many vertices as facets.
    vertices_.reserve(facets / 2 + 3);
    triangles_.reserve(facets);
    index_.reserve(facets / 2 + 3);
  }

  /// Adds a facet; false when two corners are the same vertex (it is dropped).
  bool addFacet(const std::array<float, 9> &corners) {
    Triangle triangle;
    for (int k = 0; k < 3; ++k)
      triangle[k] = vertex(corners[3 * k] + 0.0f, corners[3 * k + 1] + 0.0f,
                           corners[3 * k + 2] + 0.0f); // + 0.0f turns -0 into +0
    if (triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[0] == triangle[2])
      return false;
    triangles_.push_back(triangle);
    return true;
  }

private:
  using Key = std::array<std::uint32_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key &key) const {
      std::uint64_t hash = 1469598103934665603ull; // FNV-1a over the three words
      for (std::uint32_t word : key)
        hash = (hash ^ word) * 1099511628211ull;
      return static_cast<std::size_t>(hash ^ (hash >> 29));
    }
  };

  VertexIndex vertex(float x, float y, float z) {
    Key key;
    std::memcpy(&key[0], &x, 4);
    std::memcpy(&key[1], &y, 4);
    std::memcpy(&key[2], &z, 4);
    const auto [found, added] = index_.emplace(key, static_cast<VertexIndex>(vertices_.size()));
    if (added)
      vertices_.emplace_back(x, y, z);
    return found->second;
  }

  std::vector<Eigen::Vector3d> &vertices_;
  std::vector<Triangle> &triangles_;
  std::unordered_map<Key, VertexIndex, KeyHash> index_;
};

bool allFinite(const std::array<float, 9> &corners) {
  return std::all_of(corners.begin(), corners.end(), [](float v) { return std::isfinite(v); });
}

std::uint32_t littleEndianUInt32(const char *bytes) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i)
    value = (value << 8) | static_cast<unsigned char>(bytes[i]);
  return value;
}

float littleEndianFloat(const char *bytes) {
  const std::uint32_t bits = littleEndianUInt32(bytes);
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

/// The size a binary STL with the triangle count in its header must have,
/// or 0 when the file is too short to hold a count.
std::uint64_t binarySize(std::string_view bytes, std::uint32_t &count) {
  if (bytes.size() < kBinaryHeaderBytes)
    return 0;
  count = littleEndianUInt32(bytes.data() + 80);
  return kBinaryHeaderBytes + kBinaryFacetBytes * std::uint64_t{count};
}

bool readBinary(std::string_view bytes, std::uint32_t count, Welder &welder, std::string &error) {
  welder.reserve(count);
  std::array<float, 9> corners;
  for (std::uint32_t f = 0; f < count; ++f) {
    // Skip the facet normal (recomputed from the corners by whoever needs
    // it) and read the corners; the 2-byte attribute after them is unused.
    const char *record = bytes.data() + kBinaryHeaderBytes + kBinaryFacetBytes * f + 12;
    for (int i = 0; i < 9; ++i)
      corners[i] = littleEndianFloat(record + 4 * i);
    if (!allFinite(corners)) {
      error = "binary STL facet " + std::to_string(f) + " has a non-finite coordinate";
      return false;
    }
    welder.addFacet(corners);
  }
  return true;
}

/// The words of an ASCII STL one at a time, with their line numbers.
class StlWords {
public:
  explicit StlWords(std::string_view bytes) : bytes_(bytes) {}

  /// The next word, or an empty one at the end of the file.
  std::string_view next() {
    while (position_ < bytes_.size() && isBlank(bytes_[position_])) {
      line_ += bytes_[position_] == '\n';
      ++position_;
    }
    const std::size_t start = position_;
    while (position_ < bytes_.size() && !isBlank(bytes_[position_]))
      ++position_;
    return bytes_.substr(start, position_ - start);
  }

  /// Skips what is left of the current line (the name after solid/endsolid).
  void skipLine() {
    while (position_ < bytes_.size() && bytes_[position_] != '\n')
      ++position_;
  }

  std::string where() const { return "line " + std::to_string(line_) + ": "; }

private:
  std::string_view bytes_;
  std::size_t position_ = 0, line_ = 1;
};

/// Keywords are compared without case: some exporters write them in capitals.
bool isKeyword(std::string_view word, std::string_view keyword) {
  return word.size() == keyword.size() &&
         std::equal(word.begin(), word.end(), keyword.begin(),
                    [](char a, char b) { return (a | 0x20) == b; });
}

bool expectKeyword(StlWords &words, std::string_view keyword, std::string &error) {
  const std::string_view word = words.next();
  if (isKeyword(word, keyword))
    return true;
  error = words.where() + "expected '" + std::string(keyword) + "', found " +
          (word.empty() ? std::string("the end of the file (truncated?)") : printable(word));
  return false;
}

/// Reads `count` numbers as floats (STL's precision: an ASCII file and its
/// binary copy give the same vertices, and welding compares floats).
bool readFloats(StlWords &words, float *values, int count, const char *what, std::string &error) {
  for (int i = 0; i < count; ++i) {
    const std::string_view word = words.next();
    if (!parseNumber(word, values[i])) {
      error = words.where() + (word.empty()
                                   ? std::string("the file ends inside a ") + what + " (truncated?)"
                                   : std::string(what) + " value " + printable(word) +
                                         " is not a number in float range");
      return false;
    }
  }
  return true;
}

/// solid NAME, then facets (facet normal n n n / outer loop / vertex x y z
/// three times / endloop / endfacet), then endsolid [NAME]; several solids
/// may follow one another.
bool readAscii(std::string_view bytes, Welder &welder, std::string &error) {
  StlWords words(bytes);
  std::size_t facet = 0;
  std::string_view word = words.next();
  do {
    if (!isKeyword(word, "solid")) {
      error = words.where() + "expected 'solid', found " + printable(word);
      return false;
    }
    words.skipLine();
    for (word = words.next(); isKeyword(word, "facet"); word = words.next(), ++facet) {
      float normal[3];
      std::array<float, 9> corners;
      if (!expectKeyword(words, "normal", error) ||
          !readFloats(words, normal, 3, "facet normal", error) ||
          !expectKeyword(words, "outer", error) || !expectKeyword(words, "loop", error))
        return false;
      for (int k = 0; k < 3; ++k)
        if (!expectKeyword(words, "vertex", error) ||
            !readFloats(words, &corners[3 * k], 3, "vertex", error))
          return false;
      if (!allFinite(corners)) {
        error = words.where() + "facet " + std::to_string(facet) + " has a non-finite coordinate";
        return false;
      }
      if (!expectKeyword(words, "endloop", error) || !expectKeyword(words, "endfacet", error))
        return false;
      welder.addFacet(corners);
    }
    if (!isKeyword(word, "endsolid")) {
      error = words.where() + "expected 'facet' or 'endsolid', found " +
              (word.empty() ? std::string("the end of the file (truncated?)") : printable(word));
      return false;
    }
    words.skipLine();
    word = words.next();
  } while (!word.empty());
  return true;
}

/// The first byte that no text file holds (a control character other than
/// white space), or npos.
std::size_t firstBinaryByte(std::string_view bytes) {
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if ((c < 0x20 && !isBlank(bytes[i])) || c == 0x7f)
      return i;
  }
  return std::string_view::npos;
}

} // namespace

bool loadStlMesh(const std::string &path, std::vector<Eigen::Vector3d> &vertices,
                 std::vector<Triangle> &triangles, std::string &error) {
  std::string bytes;
  if (!readFileBytes(path, bytes, error))
    return false;
  Welder welder(vertices, triangles);
  // A binary header may begin with "solid" too, so the size decides, as in
  // most readers: a binary file is exactly 84 + 50 * count bytes. This is
  // checked before room for the facets is reserved, so an absurd count
  // costs nothing.
  std::uint32_t count = 0;
  const std::uint64_t binary_size = binarySize(bytes, count);
  if (binary_size == bytes.size())
    return readBinary(bytes, count, welder, error);

  const std::string_view text = trim(std::string_view(bytes).substr(0, 80));
  const bool says_solid = text.size() >= 5 && isKeyword(text.substr(0, 5), "solid");
  const std::size_t binary_byte = firstBinaryByte(bytes);
  if (says_solid && binary_byte == std::string_view::npos)
    return readAscii(bytes, welder, error);
  const std::string not_ascii =
      says_solid ? "not ASCII STL (control byte at offset " + std::to_string(binary_byte) + ")"
                 : "not ASCII STL (it does not begin with 'solid')";
  if (binary_size == 0)
    error =
        not_ascii + " and too short for a binary STL (" + std::to_string(bytes.size()) + " bytes)";
  else
    error = not_ascii + " and not binary STL: its header declares " + std::to_string(count) +
            " triangles, which need " + std::to_string(binary_size) + " bytes, but the file has " +
            std::to_string(bytes.size()) + " (truncated or corrupt?)";
  return false;
}

} // namespace io_detail
} // namespace pcl_ms

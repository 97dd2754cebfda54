// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the STL reader behind pcl_ms::loadMesh and pcl_ms::loadPointCloud
// (suite IoStl): ASCII and binary files written here byte by byte, corners
// welded into vertices, and broken files rejected with a reason.
#include "program_test.h"
#include "test_support.h"

#include <pcl_ms/io.h>

#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace pcl_ms_test;

using Corners = std::array<std::array<float, 3>, 3>;

/// An ASCII STL of the facets (the normals are left zero: readers ignore them).
std::string asciiStl(const std::vector<Corners> &facets, const std::string &name = "test") {
  std::ostringstream out;
  out.precision(9); // gives every float back exactly
  out << "solid " << name << "\n";
  for (const Corners &facet : facets) {
    out << "  facet normal 0 0 0\n    outer loop\n";
    for (const auto &corner : facet)
      out << "      vertex " << corner[0] << " " << corner[1] << " " << corner[2] << "\n";
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid " << name << "\n";
  return out.str();
}

void appendLittleEndian(std::string &bytes, std::uint32_t value, int size) {
  for (int i = 0; i < size; ++i)
    bytes += static_cast<char>((value >> (8 * i)) & 0xff);
}

void appendFloat(std::string &bytes, float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  appendLittleEndian(bytes, bits, 4);
}

/// A binary STL: an 80-byte header, the count, then 50 bytes per facet.
std::string binaryStl(const std::vector<Corners> &facets, const std::string &header = "pcl_ms") {
  std::string bytes = header;
  bytes.resize(80, ' ');
  appendLittleEndian(bytes, static_cast<std::uint32_t>(facets.size()), 4);
  for (const Corners &facet : facets) {
    for (int k = 0; k < 3; ++k)
      appendFloat(bytes, 0.0f); // normal
    for (const auto &corner : facet)
      for (float value : corner)
        appendFloat(bytes, value);
    appendLittleEndian(bytes, 0, 2); // attribute byte count
  }
  return bytes;
}

/// The unit cube as 12 facets, as an exporter writes it: every corner
/// repeated in each facet that touches it (36 corners, 8 positions).
std::vector<Corners> cubeFacets() {
  const auto p = [](int corner) {
    return std::array<float, 3>{static_cast<float>(corner & 1),
                                static_cast<float>((corner >> 1) & 1),
                                static_cast<float>((corner >> 2) & 1)};
  };
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Corners> facets;
  for (const auto &face : faces) {
    facets.push_back({p(face[0]), p(face[1]), p(face[2])});
    facets.push_back({p(face[0]), p(face[2]), p(face[3])});
  }
  return facets;
}

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
};

/// The mesh welded independently of the reader: a std::map from position to
/// the index of its first use.
Mesh weldedByHand(const std::vector<Corners> &facets) {
  Mesh mesh;
  std::map<std::array<float, 3>, pcl_ms::VertexIndex> index;
  for (const Corners &facet : facets) {
    pcl_ms::Triangle triangle;
    for (int k = 0; k < 3; ++k) {
      const auto [found, added] =
          index.emplace(facet[k], static_cast<pcl_ms::VertexIndex>(mesh.vertices.size()));
      if (added)
        mesh.vertices.emplace_back(facet[k][0], facet[k][1], facet[k][2]);
      triangle[k] = found->second;
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

class IoStl : public TempDirTest {
protected:
  Mesh load(const std::string &name) {
    Mesh mesh;
    std::string error;
    EXPECT_TRUE(pcl_ms::loadMesh(path(name), mesh.vertices, mesh.triangles, error)) << error;
    return mesh;
  }
};

TEST_F(IoStl, CubeWeldsTwelveFacetsIntoEightVerticesInBothEncodings) {
  const std::vector<Corners> cube = cubeFacets();
  writeFile(path("ascii.stl"), asciiStl(cube));
  writeFile(path("binary.stl"), binaryStl(cube));
  for (const char *name : {"ascii.stl", "binary.stl"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = load(name);
    ASSERT_EQ(mesh.vertices.size(), 8u);
    ASSERT_EQ(mesh.triangles.size(), 12u);
    // Vertices in order of first use: corners 0, 2, 3, 1 of the first face,
    // then 4, 5, 7, 6 of the second.
    const int first_use[8] = {0, 2, 3, 1, 4, 5, 7, 6};
    for (int v = 0; v < 8; ++v)
      EXPECT_EQ(mesh.vertices[v],
                Eigen::Vector3d(first_use[v] & 1, (first_use[v] >> 1) & 1, (first_use[v] >> 2) & 1))
          << "vertex " << v;
    const std::vector<pcl_ms::Triangle> first_faces = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    EXPECT_EQ(std::vector<pcl_ms::Triangle>(mesh.triangles.begin(), mesh.triangles.begin() + 4),
              first_faces);
    // Closed: every edge in exactly two facets, once each way.
    std::map<std::pair<pcl_ms::VertexIndex, pcl_ms::VertexIndex>, int> edges;
    for (const pcl_ms::Triangle &t : mesh.triangles)
      for (int k = 0; k < 3; ++k)
        ++edges[{t[k], t[(k + 1) % 3]}];
    EXPECT_EQ(edges.size(), 36u);
    for (const auto &[edge, uses] : edges) {
      EXPECT_EQ(uses, 1);
      EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
    }
  }
}

TEST_F(IoStl, BunnyPartRoundTripsExactlyInBothEncodings) {
  // 5,000 of the bunny's triangles with its float positions: both encodings
  // give back every corner's position and the welding a plain map makes.
  const ReferenceMesh &bunny = bunnyReference();
  std::vector<Corners> facets;
  for (std::size_t t = 0; t < 5000; ++t) {
    Corners facet;
    for (int k = 0; k < 3; ++k)
      for (int axis = 0; axis < 3; ++axis)
        facet[k][axis] = static_cast<float>(bunny.vertices[bunny.triangles[t][k]][axis]);
    facets.push_back(facet);
  }
  const Mesh expected = weldedByHand(facets);
  ASSERT_LT(expected.vertices.size(), 3 * facets.size() / 2); // corners are shared
  writeFile(path("bunny_ascii.stl"), asciiStl(facets, "bunny part"));
  // A binary header may begin with "solid" as ASCII files do.
  writeFile(path("bunny_binary.stl"), binaryStl(facets, "solid bunny part"));
  for (const char *name : {"bunny_ascii.stl", "bunny_binary.stl"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = load(name);
    EXPECT_EQ(mesh.vertices, expected.vertices);
    EXPECT_EQ(mesh.triangles, expected.triangles);
    // The cloud reader gives the same vertices as floats, in the same order.
    pcl::PCLPointCloud2 blob;
    std::string error;
    ASSERT_TRUE(pcl_ms::loadPointCloud(path(name), blob, error)) << error;
    pcl::PointCloud<pcl::PointXYZ> cloud;
    pcl::fromPCLPointCloud2(blob, cloud);
    ASSERT_EQ(cloud.size(), expected.vertices.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
      ASSERT_EQ(Eigen::Vector3d(cloud[i].getVector3fMap().cast<double>()), expected.vertices[i])
          << "point " << i;
  }
}

TEST_F(IoStl, FacetsWithTwoEqualCornersAreDropped) {
  std::vector<Corners> facets = {{{{-0.f, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, // stored as +0
                                 {{{0, 0, 0}, {0, 0, 0}, {1, 1, 1}}},    // two equal corners
                                 {{{-0.f, 0, 0}, {0, 0, 0}, {1, 0, 0}}}, // -0 is 0
                                 {{{1, 0, 0}, {2, 0, 0}, {3, 0, 0}}},    // flat but three corners
                                 {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
  writeFile(path("ascii.stl"), asciiStl(facets));
  writeFile(path("binary.stl"), binaryStl(facets));
  for (const char *name : {"ascii.stl", "binary.stl"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = load(name);
    const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}, {1, 4, 5}, {1, 2, 6}};
    EXPECT_EQ(mesh.triangles, expected);
    ASSERT_EQ(mesh.vertices.size(), 7u); // (1,1,1) stays: it was read
    EXPECT_EQ(mesh.vertices[3], Eigen::Vector3d(1, 1, 1));
    EXPECT_FALSE(std::signbit(mesh.vertices[0].x()));
  }
  // Nothing but degenerate facets: no faces, which loadMesh refuses.
  writeFile(path("flat.stl"), asciiStl({facets[1], facets[2]}));
  EXPECT_TRUE(contains(expectMeshFailure(path("flat.stl")), "no faces"));
}

TEST_F(IoStl, CapitalKeywordsAndSeveralSolids) {
  const std::vector<Corners> cube = cubeFacets();
  std::string text = asciiStl({cube.begin(), cube.begin() + 6}, "first") + "\n" +
                     asciiStl({cube.begin() + 6, cube.end()}, "second");
  for (const char *keyword : {"solid", "facet", "normal", "outer", "loop", "vertex"}) {
    std::string upper = keyword;
    for (char &c : upper)
      c = static_cast<char>(c - 'a' + 'A');
    for (std::size_t at = text.find(keyword); at != std::string::npos;
         at = text.find(keyword, at + 1))
      text.replace(at, upper.size(), upper);
  }
  writeFile(path("two.stl"), text);
  const Mesh mesh = load("two.stl");
  EXPECT_EQ(mesh.vertices.size(), 8u); // welded across the two solids
  EXPECT_EQ(mesh.triangles.size(), 12u);
}

TEST_F(IoStl, BrokenBinaryFilesFailWithAReason) {
  const std::string cube = binaryStl(cubeFacets());
  ASSERT_EQ(cube.size(), 84u + 12 * 50);
  // Cut anywhere, with or without "solid" in the header: the count no longer
  // matches the size.
  for (std::size_t cut :
       {std::size_t(83), std::size_t(84), std::size_t(84 + 25), cube.size() - 1}) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    writeFile(path("cut.stl"), cube.substr(0, cut));
    const std::string reason = expectMeshFailure(path("cut.stl"));
    if (cut >= 84) {
      EXPECT_TRUE(contains(reason, "declares 12 triangles")) << reason;
      EXPECT_TRUE(contains(reason, "truncated")) << reason;
    } else {
      EXPECT_TRUE(contains(reason, "too short")) << reason;
    }
    writeFile(path("cut_solid.stl"), binaryStl(cubeFacets(), "solid cube").substr(0, cut));
    EXPECT_TRUE(contains(expectMeshFailure(path("cut_solid.stl")), "not ASCII STL"));
  }
  // Bytes past the last facet are a count that does not match either.
  writeFile(path("long.stl"), cube + std::string(50, '\0'));
  EXPECT_TRUE(contains(expectMeshFailure(path("long.stl")), "declares 12 triangles"));
  // An absurd count fails on the size check, before anything is allocated.
  std::string absurd = cube;
  absurd.replace(80, 4, std::string(4, '\xff'));
  writeFile(path("absurd.stl"), absurd);
  EXPECT_TRUE(contains(expectMeshFailure(path("absurd.stl")), "declares 4294967295 triangles"));
  // Non-finite coordinates.
  const float bad_values[] = {std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity()};
  for (float bad : bad_values) {
    std::vector<Corners> facets = cubeFacets();
    facets[7][2][1] = bad;
    writeFile(path("bad.stl"), binaryStl(facets));
    EXPECT_TRUE(contains(expectMeshFailure(path("bad.stl")), "facet 7 has a non-finite"));
  }
  writeFile(path("empty.stl"), "");
  EXPECT_TRUE(contains(expectMeshFailure(path("empty.stl")), "empty"));
  // No facets at all: a valid file, but no mesh and no cloud.
  writeFile(path("none.stl"), binaryStl({}));
  EXPECT_TRUE(contains(expectMeshFailure(path("none.stl")), "no faces"));
  EXPECT_TRUE(contains(expectCloudFailure(path("none.stl")), "no vertices"));
}

TEST_F(IoStl, BrokenAsciiFilesFailWithAReason) {
  const std::string cube = asciiStl(cubeFacets());
  const auto expectReason = [&](const std::string &text, const std::string &reason) {
    SCOPED_TRACE(reason);
    writeFile(path("broken.stl"), text);
    const std::string error = expectMeshFailure(path("broken.stl"));
    EXPECT_TRUE(contains(error, reason)) << error;
    expectCloudFailure(path("broken.stl"));
  };
  const auto replaced = [&](const std::string &from, const std::string &to) {
    std::string text = cube;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  // Line 3 is the first facet's "outer loop".
  expectReason(replaced("facet normal", "facet normals"), "line 2: expected 'normal'");
  expectReason(replaced("outer loop", "outer lop"), "line 3: expected 'loop', found 'lop'");
  // A facet with two vertices: the third is missing.
  expectReason(replaced("      vertex 1 1 0\n    endloop", "    endloop"),
               "line 6: expected 'vertex', found 'endloop'");
  expectReason(replaced("endloop\n  endfacet\n  facet", "endloop\n  facet"),
               "expected 'endfacet', found 'facet'");
  expectReason(replaced("vertex 1 1 0", "vertex 1 1"), "vertex value 'endloop' is not a number");
  expectReason(replaced("vertex 1 1 0", "vertex 1 1 nan"), "facet 0 has a non-finite coordinate");
  expectReason(replaced("vertex 1 1 0", "vertex 1 1 -inf"), "non-finite coordinate");
  expectReason(replaced("vertex 1 1 0", "vertex 1 1 1e39"), "not a number in float range");
  expectReason(cube.substr(0, cube.find("endloop", cube.size() / 2)),
               "expected 'endloop', found the end of the file (truncated?)");
  expectReason(cube.substr(0, cube.find("endsolid")),
               "expected 'facet' or 'endsolid', found the end");
  expectReason(cube + "facet\n", "expected 'solid', found 'facet'");
  expectReason(replaced("solid test", "solid\x01 test"), "control byte at offset 5");
  expectReason("soli d\n", "too short for a binary STL");
}

} // namespace

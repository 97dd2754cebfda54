// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of pcl_ms/io.h (suites Io*; the STL reader's are in test_io_stl.cpp);
// the pcl_ms_reconstruct program is tested in test_app.cpp. Every file they
// write goes to a fresh temporary directory.
#include "program_test.h"
#include "test_support.h"

#include <pcl_ms/io.h>

#include <gtest/gtest.h>
#include <pcl/common/point_tests.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace pcl_ms_test;

const std::string kDataDir = PCL_MS_DATA_DIR;

/// Keeps the first `size` bytes of a file, as an interrupted copy would.
void cutFile(const std::string &path, std::size_t size) {
  const std::string bytes = readFile(path);
  ASSERT_LT(size, bytes.size());
  writeFile(path, bytes.substr(0, size));
}

/// Offset of the first byte after the header line that starts with `last_key`.
std::size_t headerEnd(const std::string &path, const std::string &last_key) {
  const std::string bytes = readFile(path);
  const std::size_t key = bytes.find("\n" + last_key);
  return key == std::string::npos ? std::string::npos : bytes.find('\n', key + 1) + 1;
}

pcl::PointCloud<pcl::PointNormal> makeCloud(std::size_t size) {
  pcl::PointCloud<pcl::PointNormal> cloud;
  std::mt19937 random(42);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  for (std::size_t i = 0; i < size; ++i) {
    pcl::PointNormal point;
    point.x = coordinate(random);
    point.y = coordinate(random);
    point.z = coordinate(random);
    point.normal_x = 0.0f;
    point.normal_y = 0.6f;
    point.normal_z = 0.8f;
    point.curvature = 0.25f;
    cloud.push_back(point);
  }
  return cloud;
}

/// A flat grid of rows x columns vertices, two triangles per cell.
pcl::PolygonMesh makeGridMesh(int rows, int columns) {
  pcl::PointCloud<pcl::PointNormal> cloud;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      pcl::PointNormal point;
      point.x = 0.1f * static_cast<float>(c);
      point.y = 0.2f * static_cast<float>(r);
      point.z = 0.01f * static_cast<float>(r * c);
      point.normal_x = point.normal_y = 0.0f;
      point.normal_z = 1.0f;
      point.curvature = 0.0f;
      cloud.push_back(point);
    }
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(cloud, mesh.cloud);
  for (int r = 0; r + 1 < rows; ++r)
    for (int c = 0; c + 1 < columns; ++c) {
      const int corner = r * columns + c;
      pcl::Vertices first, second;
      first.vertices = pcl::Indices{corner, corner + 1, corner + columns + 1};
      second.vertices = pcl::Indices{corner, corner + columns + 1, corner + columns};
      mesh.polygons.push_back(first);
      mesh.polygons.push_back(second);
    }
  return mesh;
}

void expectSameCloud(const pcl::PointCloud<pcl::PointNormal> &expected,
                     const pcl::PCLPointCloud2 &loaded, bool with_normals, float tolerance) {
  pcl::PointCloud<pcl::PointNormal> actual;
  pcl::fromPCLPointCloud2(loaded, actual);
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(actual[i].x, expected[i].x, tolerance) << "point " << i;
    EXPECT_NEAR(actual[i].y, expected[i].y, tolerance) << "point " << i;
    EXPECT_NEAR(actual[i].z, expected[i].z, tolerance) << "point " << i;
    if (with_normals) {
      EXPECT_NEAR(actual[i].normal_y, expected[i].normal_y, tolerance) << "point " << i;
      EXPECT_NEAR(actual[i].normal_z, expected[i].normal_z, tolerance) << "point " << i;
    }
  }
}

/// Loads `file`, whose points must be `expected`'s, bit for bit, into `loaded`.
void expectSamePoints(const std::string &file, const pcl::PointCloud<pcl::PointXYZ> &expected,
                      pcl::PCLPointCloud2 &loaded) {
  SCOPED_TRACE(file);
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(file, loaded, error)) << error;
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(loaded, points);
  ASSERT_EQ(points.size(), expected.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    ASSERT_TRUE(points[i].getVector3fMap() == expected[i].getVector3fMap()) << "point " << i;
}

// ---------------------------------------------------------------------------
// Point clouds

class IoLoadPointCloud : public TempDirTest {};

TEST_F(IoLoadPointCloud, PcdRoundTripInAllThreeEncodings) {
  const pcl::PointCloud<pcl::PointNormal> cloud = makeCloud(500);
  ASSERT_EQ(pcl::io::savePCDFileASCII(path("a.pcd"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinary(path("b.pcd"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(path("c.pcd"), cloud), 0);
  for (const char *name : {"a.pcd", "b.pcd", "c.pcd"}) {
    pcl::PCLPointCloud2 loaded;
    std::string error;
    ASSERT_TRUE(pcl_ms::loadPointCloud(path(name), loaded, error)) << error;
    EXPECT_TRUE(pcl_ms::hasNormals(loaded)) << name;
    expectSameCloud(cloud, loaded, true, name[0] == 'a' ? 1e-6f : 0.0f);
  }
}

TEST_F(IoLoadPointCloud, PlyRoundTripAsciiAndBinary) {
  const pcl::PointCloud<pcl::PointNormal> cloud = makeCloud(300);
  ASSERT_EQ(pcl::io::savePLYFile(path("a.ply"), cloud, false), 0);
  ASSERT_EQ(pcl::io::savePLYFile(path("b.ply"), cloud, true), 0);
  for (const char *name : {"a.ply", "b.ply"}) {
    pcl::PCLPointCloud2 loaded;
    std::string error;
    ASSERT_TRUE(pcl_ms::loadPointCloud(path(name), loaded, error)) << error;
    EXPECT_TRUE(pcl_ms::hasNormals(loaded)) << name;
    expectSameCloud(cloud, loaded, true, name[0] == 'a' ? 1e-5f : 0.0f);
  }
}

TEST_F(IoLoadPointCloud, ExtensionIsCaseInsensitive) {
  const pcl::PointCloud<pcl::PointNormal> cloud = makeCloud(10);
  ASSERT_EQ(pcl::io::savePCDFileBinary(path("upper.PCD"), cloud), 0);
  writeFile(path("upper.TXT"), "1 2 3\n4 5 6\n");
  pcl::PCLPointCloud2 loaded;
  std::string error;
  EXPECT_TRUE(pcl_ms::loadPointCloud(path("upper.PCD"), loaded, error)) << error;
  EXPECT_EQ(loaded.width, 10u);
  EXPECT_TRUE(pcl_ms::loadPointCloud(path("upper.TXT"), loaded, error)) << error;
  EXPECT_EQ(loaded.width, 2u);
}

TEST_F(IoLoadPointCloud, XyzWithCommentsAndThreeColumns) {
  writeFile(path("points.xyz"), "# exported by hand\n"
                                "\n"
                                "1.5 -2 3e-1\n"
                                "  # indented comment\n"
                                "+4\t5 6 # trailing comment\n"
                                "7 8 9"); // no final newline: still a complete line
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("points.xyz"), loaded, error)) << error;
  EXPECT_FALSE(pcl_ms::hasNormals(loaded));
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(loaded, points);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_FLOAT_EQ(points[0].x, 1.5f);
  EXPECT_FLOAT_EQ(points[0].y, -2.0f);
  EXPECT_FLOAT_EQ(points[0].z, 0.3f);
  EXPECT_FLOAT_EQ(points[1].x, 4.0f);
  EXPECT_FLOAT_EQ(points[2].z, 9.0f);
}

TEST_F(IoLoadPointCloud, XyzWithSixColumnsHasNormals) {
  writeFile(path("oriented.txt"), "0 0 0 0 0 1\n1 0 0 0 1 0\n0 1 0 1 0 0\n");
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("oriented.txt"), loaded, error)) << error;
  ASSERT_TRUE(pcl_ms::hasNormals(loaded));
  pcl::PointCloud<pcl::PointNormal> points;
  pcl::fromPCLPointCloud2(loaded, points);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_FLOAT_EQ(points[1].x, 1.0f);
  EXPECT_FLOAT_EQ(points[1].normal_y, 1.0f);
  EXPECT_FLOAT_EQ(points[2].normal_x, 1.0f);
}

TEST_F(IoLoadPointCloud, XyzMalformedLineIsNamed) {
  writeFile(path("bad.xyz"), "# header\n1 2 3\n4 five 6\n7 8 9\n");
  const std::string error = expectCloudFailure(path("bad.xyz"));
  EXPECT_TRUE(contains(error, "line 3")) << error;
  EXPECT_TRUE(contains(error, "five")) << error;
}

TEST_F(IoLoadPointCloud, XyzTruncatedLastLineIsNamed) {
  writeFile(path("cut.xyz"), "1 2 3\n4 5 6\n7 8");
  const std::string error = expectCloudFailure(path("cut.xyz"));
  EXPECT_TRUE(contains(error, "line 3")) << error;
  EXPECT_TRUE(contains(error, "truncated")) << error;
}

TEST_F(IoLoadPointCloud, XyzWrongColumnCounts) {
  writeFile(path("four.xyz"), "1 2 3 4\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("four.xyz")), "line 1"));
  writeFile(path("mixed.xyz"), "1 2 3\n1 2 3 0 0 1\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("mixed.xyz")), "line 2"));
  writeFile(path("comments_only.xyz"), "# nothing here\n\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("comments_only.xyz")), "no points"));
}

TEST_F(IoLoadPointCloud, SampleBunnyHasAllVertices) {
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(kDataDir + "/bunny.pcd", loaded, error)) << error;
  EXPECT_EQ(loaded.width * loaded.height, 35947u);
  EXPECT_FALSE(pcl_ms::hasNormals(loaded));
}

TEST_F(IoLoadPointCloud, SampleBun0HasNormals) {
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(kDataDir + "/bun0.pcd", loaded, error)) << error;
  EXPECT_EQ(loaded.width * loaded.height, 397u);
  EXPECT_TRUE(pcl_ms::hasNormals(loaded));
}

TEST_F(IoLoadPointCloud, SampleRawScanHasAllPoints) {
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(kDataDir + "/bun000.pcd", loaded, error)) << error;
  EXPECT_EQ(loaded.width * loaded.height, 40256u);
}

TEST_F(IoLoadPointCloud, MeshPlyGivesItsVertices) {
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(kDataDir + "/bun_zipper.ply", loaded, error)) << error;
  EXPECT_EQ(loaded.width * loaded.height, 35947u);
  // Same float32 vertices as bunny.pcd, in the same order.
  pcl::PCLPointCloud2 bunny;
  ASSERT_TRUE(pcl_ms::loadPointCloud(kDataDir + "/bunny.pcd", bunny, error)) << error;
  pcl::PointCloud<pcl::PointXYZ> from_mesh, from_pcd;
  pcl::fromPCLPointCloud2(loaded, from_mesh);
  pcl::fromPCLPointCloud2(bunny, from_pcd);
  ASSERT_EQ(from_mesh.size(), from_pcd.size());
  for (std::size_t i = 0; i < from_mesh.size(); i += 997)
    EXPECT_EQ(from_mesh[i].getVector3fMap(), from_pcd[i].getVector3fMap()) << "vertex " << i;
}

TEST_F(IoLoadPointCloud, RangeGridScanGivesVerticesInFileOrder) {
  // Like the Stanford raw scans: 3 vertices on a 3 x 2 pixel grid with gaps.
  writeFile(path("scan.ply"), "ply\n"
                              "format ascii 1.0\n"
                              "obj_info num_cols 3\n"
                              "obj_info num_rows 2\n"
                              "element vertex 3\n"
                              "property float x\n"
                              "property float y\n"
                              "property float z\n"
                              "element range_grid 6\n"
                              "property list uchar int vertex_indices\n"
                              "end_header\n"
                              "1 0 0\n"
                              "2 0 0\n"
                              "3 0 0\n"
                              "1 0\n0\n1 1\n0\n0\n1 2\n");
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("scan.ply"), loaded, error)) << error;
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(loaded, points);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(loaded.height, 1u);
  EXPECT_FLOAT_EQ(points[0].x, 1.0f);
  EXPECT_FLOAT_EQ(points[1].x, 2.0f);
  EXPECT_FLOAT_EQ(points[2].x, 3.0f);
}

TEST_F(IoLoadPointCloud, ObjInfoGridThatCannotHoldTheVerticesFails) {
  // PCL's reader sizes the vertex data for the grid that obj_info num_cols
  // and num_rows give (atoi of the third word) and aborts on a vertex past
  // it; a grid far larger than the vertices only allocates. Found by fuzzing.
  const std::string body = "1 0 0\n2 0 0\n3 0 0\n4 0 0\n";
  const std::pair<std::string, std::string> cases[] = {
      {"element vertex 4\nobj_info num_cols ny\n", "0 x 1 grid"},
      {"element vertex 4\nobj_info num_cols \n", "0 x 1 grid"}, // "" after the blank
      {"obj_info num_cols 3\nobj_info num_rows 1\nelement vertex 4\n", "3 x 1 grid"},
      {"element vertex 4\nobj_info num_rows 2\n", "4 x 2 grid"},
      {"obj_info num_cols -1\nobj_info num_rows 1\nelement vertex 4\n", "4294967295 x 1"}};
  for (const auto &[lines, message] : cases) {
    SCOPED_TRACE(lines);
    writeFile(path("grid.ply"), "ply\nformat ascii 1.0\n" + lines +
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "end_header\n" +
                                    body);
    EXPECT_TRUE(contains(expectCloudFailure(path("grid.ply")), message));
  }
  // A grid as large as the vertices is an organized cloud, and loads.
  writeFile(path("grid.ply"), "ply\nformat ascii 1.0\nobj_info num_cols 2\n"
                              "obj_info num_rows 2\nelement vertex 4\nproperty float x\n"
                              "property float y\nproperty float z\nend_header\n" +
                                  body);
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("grid.ply"), loaded, error)) << error;
  EXPECT_EQ(loaded.width * loaded.height, 4u);
}

TEST_F(IoLoadPointCloud, TruncatedBinaryPcdFails) {
  ASSERT_EQ(pcl::io::savePCDFileBinary(path("full.pcd"), makeCloud(1000)), 0);
  const std::size_t header = headerEnd(path("full.pcd"), "DATA");
  const std::size_t size = readFile(path("full.pcd")).size();
  for (std::size_t cut : {std::size_t(10), header - 5, header, header + 1000, size - 1}) {
    fs::copy_file(path("full.pcd"), path("cut.pcd"), fs::copy_options::overwrite_existing);
    cutFile(path("cut.pcd"), cut);
    SCOPED_TRACE("cut at " + std::to_string(cut));
    expectCloudFailure(path("cut.pcd"));
  }
}

TEST_F(IoLoadPointCloud, TruncatedCompressedAndAsciiPcdFail) {
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(path("full_c.pcd"), makeCloud(1000)), 0);
  ASSERT_EQ(pcl::io::savePCDFileASCII(path("full_a.pcd"), makeCloud(1000)), 0);
  for (const char *name : {"full_c.pcd", "full_a.pcd"}) {
    const std::size_t header = headerEnd(path(name), "DATA");
    const std::size_t size = readFile(path(name)).size();
    // Cutting an ascii file inside its last number leaves a valid shorter
    // number, so cut deep enough into the last line to lose whole values.
    const std::size_t last_cut = name[5] == 'a' ? size - 20 : size - 3;
    for (std::size_t cut : {header + 4, (header + size) / 2, last_cut}) {
      fs::copy_file(path(name), path("cut.pcd"), fs::copy_options::overwrite_existing);
      cutFile(path("cut.pcd"), cut);
      SCOPED_TRACE(std::string(name) + " cut at " + std::to_string(cut));
      expectCloudFailure(path("cut.pcd"));
    }
  }
}

TEST_F(IoLoadPointCloud, TruncatedBinaryPlyFails) {
  ASSERT_EQ(pcl::io::savePLYFile(path("full.ply"), makeCloud(1000), true), 0);
  std::string error;
  ASSERT_TRUE(pcl_ms::saveMesh(path("mesh.ply"), makeGridMesh(20, 20), error)) << error;
  for (const char *name : {"full.ply", "mesh.ply"}) {
    const std::size_t header = headerEnd(path(name), "end_header");
    const std::size_t size = readFile(path(name)).size();
    for (std::size_t cut : {std::size_t(20), header, (header + size) / 2, size - 1}) {
      fs::copy_file(path(name), path("cut.ply"), fs::copy_options::overwrite_existing);
      cutFile(path("cut.ply"), cut);
      SCOPED_TRACE(std::string(name) + " cut at " + std::to_string(cut));
      expectCloudFailure(path("cut.ply"));
    }
  }
}

TEST_F(IoLoadPointCloud, GarbageBytesFail) {
  std::mt19937 random(7);
  std::string garbage(4096, '\0');
  for (char &byte : garbage)
    byte = static_cast<char>(random());
  for (const char *name : {"noise.pcd", "noise.ply", "noise.xyz", "noise.txt"}) {
    writeFile(path(name), garbage);
    expectCloudFailure(path(name));
  }
  // Text that looks almost right.
  writeFile(path("words.pcd"), "hello world\nDATA ascii\n1 2 3\n");
  expectCloudFailure(path("words.pcd"));
  writeFile(path("words.ply"), "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
  expectCloudFailure(path("words.ply"));
}

TEST_F(IoLoadPointCloud, AbsurdHeaderCountsFailFast) {
  writeFile(path("huge.pcd"), "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                              "WIDTH 2000000000\nHEIGHT 1\nPOINTS 2000000000\nDATA binary\n"
                              "0123456789ab");
  EXPECT_TRUE(contains(expectCloudFailure(path("huge.pcd")), "truncated"));
  writeFile(path("huge.ply"), "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "end_header\n0123456789ab");
  EXPECT_TRUE(contains(expectCloudFailure(path("huge.ply")), "truncated"));
}

// PCL's reader goes on parsing header keywords after the DATA line, so data
// that begins like one would make it read the body with another layout (a
// fuzzer's finding crashed it). Data that begins like a comment is harmless.
TEST_F(IoLoadPointCloud, DataThatReadsAsHeaderLineFails) {
  const std::string header = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                             "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";
  std::string body(24, '\0');
  writeFile(path("columns.pcd"), header + "DATA binary\nCOLUMNS" + body);
  EXPECT_TRUE(contains(expectCloudFailure(path("columns.pcd")), "COLUMNS header line"));
  writeFile(path("size.pcd"), header + "DATA ascii\n\n  SIZE 8 8 8\n1 2 3\n4 5 6\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("size.pcd")), "SIZE header line"));
  const std::string fuzzer_finding =
      readFile(kDataDir + "/../tests/fuzz/corpus/pcd/finding_data_reads_as_header.pcd");
  writeFile(path("finding.pcd"), fuzzer_finding);
  EXPECT_TRUE(contains(expectCloudFailure(path("finding.pcd")), "header line"));

  // The first x begins with '#' and the data holds a newline: PCL skips that
  // "comment" line, reads on, and still loads the records from the DATA line.
  const std::array<float, 6> values = {0.0f, 2.5f, -1.0f, 3.0f, 0.5f, 0.25f};
  std::string records(sizeof(values), '\0');
  std::memcpy(records.data(), values.data(), sizeof(values));
  records[0] = '#';
  records[5] = '\n';
  writeFile(path("hash.pcd"), header + "DATA binary\n" + records);
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("hash.pcd"), loaded, error)) << error;
  ASSERT_EQ(loaded.data.size(), records.size());
  EXPECT_EQ(std::memcmp(loaded.data.data(), records.data(), records.size()), 0);
}

// A carriage return after the magic makes PCL's parser break header lines
// at carriage returns: a header of "\r\n" lines loads as with "\n", one that
// mixes them (or repeats carriage returns) is refused, as PCL refuses or
// misreads it (a fuzzer's finding had the MPI tool's reader accept one).
TEST_F(IoLoadPointCloud, PlyHeaderWithCarriageReturnsLoadsOnlyWhenEveryLineHasOne) {
  const std::array<float, 6> values = {1.0f, 2.0f, 3.0f, -4.0f, 5.5f, 0.25f};
  std::string body(sizeof(values), '\0');
  std::memcpy(body.data(), values.data(), sizeof(values));
  const std::string lines[] = {"format binary_little_endian 1.0",
                               "comment from another system",
                               "element vertex 2",
                               "property float x",
                               "property float y",
                               "property float z",
                               "end_header"};
  std::string crlf = "ply\r\n", mixed = "ply\r\n";
  for (const std::string &line : lines) {
    crlf += line + "\r\n";
    mixed += line + "\n";
  }
  writeFile(path("crlf.ply"), crlf + body);
  pcl::PCLPointCloud2 loaded;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("crlf.ply"), loaded, error)) << error;
  EXPECT_EQ(loaded.width, 2u);
  ASSERT_EQ(loaded.data.size(), body.size());
  EXPECT_EQ(std::memcmp(loaded.data.data(), body.data(), body.size()), 0);

  writeFile(path("mixed.ply"), mixed + body);
  EXPECT_TRUE(contains(expectCloudFailure(path("mixed.ply")), "does not end in \\r\\n"));
  writeFile(path("returns.ply"), "ply\r\r\r\n" + crlf.substr(5) + body);
  EXPECT_TRUE(contains(expectCloudFailure(path("returns.ply")), "magic line"));
  const std::string fuzzer_finding = readFile(
      kDataDir + "/../tests/fuzz/corpus/binary_layout/finding_ply_magic_line_of_carriage_returns");
  writeFile(path("finding.ply"), fuzzer_finding.substr(1)); // its first byte picks PLY
  EXPECT_TRUE(contains(expectCloudFailure(path("finding.ply")), "magic line"));
}

TEST_F(IoLoadPointCloud, MissingOrWrongCoordinateFields) {
  writeFile(path("intensity.pcd"), "VERSION 0.7\nFIELDS intensity\nSIZE 4\nTYPE F\nCOUNT 1\n"
                                   "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1\n2\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("intensity.pcd")), "'x'"));
  writeFile(path("short.pcd"), "VERSION 0.7\nFIELDS x y z\nSIZE 2 2 2\nTYPE I I I\nCOUNT 1 1 1\n"
                               "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  const std::string error = expectCloudFailure(path("short.pcd"));
  EXPECT_TRUE(contains(error, "int16") && contains(error, "float32 or float64")) << error;
}

/// The bunny's points (and made-up normals) written with double fields:
/// binary and ASCII PLY as CGAL and Open3D write them, binary and ASCII PCD.
void writeDoubleClouds(const pcl::PointCloud<pcl::PointXYZ> &points,
                       const std::function<std::string(const char *)> &path) {
  std::ostringstream ply_header, pcd_header, ply_ascii, pcd_ascii;
  ply_header << "element vertex " << points.size() << "\nproperty double x\nproperty double y\n"
             << "property double z\nproperty double nx\nproperty double ny\nproperty double nz\n"
             << "end_header\n";
  pcd_header << "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH "
             << points.size() << "\nHEIGHT 1\nPOINTS " << points.size() << "\nDATA ";
  std::string ply_binary, pcd_binary;
  for (const pcl::PointXYZ &point : points) {
    const double values[6] = {point.x, point.y, point.z, 0.0, 0.6, 0.8};
    ply_binary.append(reinterpret_cast<const char *>(values), sizeof values);
    pcd_binary.append(reinterpret_cast<const char *>(values), 3 * sizeof(double));
    ply_ascii.precision(17);
    pcd_ascii.precision(17);
    ply_ascii << values[0] << " " << values[1] << " " << values[2] << " 0 0.6 0.8\n";
    pcd_ascii << values[0] << " " << values[1] << " " << values[2] << "\n";
  }
  writeFile(path("binary.ply"),
            "ply\nformat binary_little_endian 1.0\n" + ply_header.str() + ply_binary);
  writeFile(path("ascii.ply"), "ply\nformat ascii 1.0\n" + ply_header.str() + ply_ascii.str());
  writeFile(path("binary.pcd"), pcd_header.str() + "binary\n" + pcd_binary);
  writeFile(path("ascii.pcd"), pcd_header.str() + "ascii\n" + pcd_ascii.str());
}

TEST_F(IoLoadPointCloud, DoubleFieldsAreReadAsFloat) {
  // Doubles that hold floats exactly: the same points, bit for bit, in
  // float32 fields; PLY normals too.
  const auto bunny = pcl_ms_test::loadXYZ("bunny.pcd");
  writeDoubleClouds(*bunny, [&](const char *name) { return path(name); });
  for (const char *name : {"binary.ply", "ascii.ply", "binary.pcd", "ascii.pcd"}) {
    pcl::PCLPointCloud2 loaded;
    ASSERT_NO_FATAL_FAILURE(expectSamePoints(path(name), *bunny, loaded));
    const bool ply = contains(name, ".ply");
    EXPECT_EQ(pcl_ms::hasNormals(loaded), ply) << name;
    if (ply) {
      pcl::PointCloud<pcl::PointNormal> points;
      pcl::fromPCLPointCloud2(loaded, points);
      EXPECT_EQ(points[7].getNormalVector3fMap(), Eigen::Vector3f(0.0f, 0.6f, 0.8f)) << name;
    }
  }
}

/// A 40 x 40 terrain patch, points `spacing` apart (jittered), each
/// coordinate plus `offset`: as .xyz text, as OFF and as double PLY.
void writeTerrainPatch(const std::function<std::string(const char *)> &path, const char *stem,
                       double spacing, const std::array<double, 3> &offset) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.4, 0.4);
  std::ostringstream xyz, off;
  std::string ply;
  const int side = 40;
  off << "OFF\n" << side * side << " 0 0\n";
  for (std::ostringstream *out : {&xyz, &off})
    out->precision(12);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      const double point[3] = {offset[0] + spacing * (i + jitter(random)),
                               offset[1] + spacing * (j + jitter(random)),
                               offset[2] + spacing * (2 * std::sin(0.2 * i) + jitter(random))};
      ply.append(reinterpret_cast<const char *>(point), sizeof point);
      xyz << point[0] << " " << point[1] << " " << point[2] << "\n";
      off << point[0] << " " << point[1] << " " << point[2] << "\n";
    }
  const std::string name = stem;
  writeFile(path((name + ".xyz").c_str()), xyz.str());
  writeFile(path((name + ".off").c_str()), off.str());
  writeFile(path((name + ".ply").c_str()),
            "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(side * side) +
                "\nproperty double x\nproperty double y\nproperty double z\nend_header\n" + ply);
}

TEST_F(IoLoadPointCloud, GeoreferencedDoublesAreRefusedNotRounded) {
  // UTM coordinates: a float holds a northing of 5.4e6 to half a metre, so
  // rounding moves points by up to a quarter of a metre. Points 0.5 m apart
  // would move by half their spacing: every reader that rounds doubles
  // refuses them and says why. 5 m apart (5 %), or 0.5 m apart on an 8 km
  // site grid (0.05 %), they load, every point kept.
  const auto inTemp = [&](const char *name) { return path(name); };
  writeTerrainPatch(inTemp, "utm", 0.5, {512000.0, 5401000.0, 120.0});
  writeTerrainPatch(inTemp, "utm_sparse", 5.0, {512000.0, 5401000.0, 120.0});
  writeTerrainPatch(inTemp, "site", 0.5, {8000.0, 8000.0, 120.0});
  for (const char *name : {"utm.xyz", "utm.off", "utm.ply"}) {
    const std::string error = expectCloudFailure(path(name));
    EXPECT_TRUE(contains(error, "as large as 5.401e+06") && contains(error, "typical spacing") &&
                contains(error, "shift the cloud near the origin"))
        << error;
  }
  for (const char *name :
       {"utm_sparse.xyz", "utm_sparse.off", "utm_sparse.ply", "site.xyz", "site.off", "site.ply"}) {
    SCOPED_TRACE(name);
    pcl::PCLPointCloud2 loaded;
    std::string error;
    ASSERT_TRUE(pcl_ms::loadPointCloud(path(name), loaded, error)) << error;
    pcl::PointCloud<pcl::PointXYZ> points;
    pcl::fromPCLPointCloud2(loaded, points);
    std::vector<std::array<float, 3>> distinct;
    for (const pcl::PointXYZ &point : points)
      distinct.push_back({point.x, point.y, point.z});
    std::sort(distinct.begin(), distinct.end());
    EXPECT_EQ(std::unique(distinct.begin(), distinct.end()) - distinct.begin(), 1600);
  }
}

TEST_F(IoLoadPointCloud, DoubleOutOfFloatRangeIsNamed) {
  const double values[6] = {1.0, 2.0, 3.0, 4.0, 1e39, 6.0};
  writeFile(path("huge.ply"),
            "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\n"
            "property double y\nproperty double z\nend_header\n" +
                std::string(reinterpret_cast<const char *>(values), sizeof values));
  const std::string error = expectCloudFailure(path("huge.ply"));
  EXPECT_TRUE(contains(error, "point 1: y = 1e+39 is out of float range")) << error;
}

TEST_F(IoLoadPointCloud, HeaderWithoutPointsFails) {
  writeFile(path("empty_cloud.pcd"), "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                                     "COUNT 1 1 1\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("empty_cloud.pcd")), "no points"));
  writeFile(path("header_only.pcd"), "# .PCD v0.7\nVERSION 0.7\n");
  expectCloudFailure(path("header_only.pcd"));
  writeFile(path("empty_cloud.ply"), "ply\nformat ascii 1.0\nelement vertex 0\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "end_header\n");
  expectCloudFailure(path("empty_cloud.ply"));
}

TEST_F(IoLoadPointCloud, NonexistentFileFails) {
  EXPECT_TRUE(contains(expectCloudFailure(path("missing.pcd")), "does not exist"));
}

TEST_F(IoLoadPointCloud, DirectoryFails) {
  fs::create_directory(path("folder.pcd"));
  EXPECT_TRUE(contains(expectCloudFailure(path("folder.pcd")), "directory"));
}

TEST_F(IoLoadPointCloud, MeshVerticesInFileOrderWithOrWithoutFaces) {
  // The bunny's vertices through a mesh file with faces (OBJ), one without
  // (a vertex-only OFF) and legacy VTK: the same floats as bunny.pcd.
  const pcl_ms_test::ReferenceMesh &bunny = pcl_ms_test::bunnyReference();
  std::ostringstream obj, off, vtk;
  for (std::ostringstream *out : {&obj, &off, &vtk})
    out->precision(9); // enough to give back each float exactly
  off << "OFF\n" << bunny.vertices.size() << " 0 0\n";
  vtk << "# vtk DataFile Version 3.0\nbunny\nASCII\nDATASET POLYDATA\nPOINTS "
      << bunny.vertices.size() << " float\n";
  for (const Eigen::Vector3d &v : bunny.vertices) {
    obj << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
    off << v.x() << " " << v.y() << " " << v.z() << "\n";
    vtk << v.x() << " " << v.y() << " " << v.z() << "\n";
  }
  vtk << "POLYGONS " << bunny.triangles.size() << " " << 4 * bunny.triangles.size() << "\n";
  for (const pcl_ms::Triangle &t : bunny.triangles) {
    obj << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
    vtk << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  }
  writeFile(path("bunny.obj"), obj.str());
  writeFile(path("bunny.off"), off.str());
  writeFile(path("bunny.vtk"), vtk.str());
  const auto expected = pcl_ms_test::loadXYZ("bunny.pcd");
  for (const char *name : {"bunny.obj", "bunny.off", "bunny.vtk"}) {
    pcl::PCLPointCloud2 loaded;
    ASSERT_NO_FATAL_FAILURE(expectSamePoints(path(name), *expected, loaded));
  }
  writeFile(path("empty.off"), "OFF\n0 0 0\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("empty.off")), "no vertices"));
}

TEST_F(IoLoadPointCloud, UnknownExtensionFails) {
  writeFile(path("points.las"), "1 2 3\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("points.las")), "unknown"));
  writeFile(path("no_extension"), "1 2 3\n");
  EXPECT_TRUE(contains(expectCloudFailure(path("no_extension")), "no file extension"));
}

TEST_F(IoLoadPointCloud, EmptyFileFails) {
  for (const char *name : {"empty.pcd", "empty.ply", "empty.xyz", "empty.txt"}) {
    writeFile(path(name), "");
    EXPECT_TRUE(contains(expectCloudFailure(path(name)), "empty")) << name;
  }
}

// ---------------------------------------------------------------------------
// Meshes

class IoLoadMesh : public TempDirTest {};

TEST_F(IoLoadMesh, SampleBunnyReference) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(kDataDir + "/bun_zipper.ply", vertices, triangles, error)) << error;
  EXPECT_EQ(vertices.size(), 35947u);
  EXPECT_EQ(triangles.size(), 69451u);
}

TEST_F(IoLoadMesh, OffWithCommentsColorsAndQuads) {
  writeFile(path("shape.off"), "OFF\n"
                               "# a unit square and an apex\n"
                               "5 3 0\n"
                               "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                               "0.5 0.5 1 # apex\n"
                               "4 0 1 2 3\n"
                               "3 0 1 4 255 0 0\n"
                               "3 1 2 4\n");
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("shape.off"), vertices, triangles, error)) << error;
  ASSERT_EQ(vertices.size(), 5u);
  EXPECT_EQ(vertices[4], Eigen::Vector3d(0.5, 0.5, 1));
  const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {1, 2, 4}};
  EXPECT_EQ(triangles, expected);

  writeFile(path("same_line.off"), "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  ASSERT_TRUE(pcl_ms::loadMesh(path("same_line.off"), vertices, triangles, error)) << error;
  EXPECT_EQ(triangles.size(), 1u);
}

TEST_F(IoLoadMesh, ObjWithSlashesAndNegativeIndices) {
  writeFile(path("shape.obj"), "# test\nmtllib none.mtl\no square\n"
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "vt 0 0\nvn 0 0 1\n"
                               "f 1/1/1 2/1/1 3/1/1 4/1/1\n"
                               "v 0.5 0.5 1\n"
                               "f -5//1 -4//1 -1//1\n");
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("shape.obj"), vertices, triangles, error)) << error;
  EXPECT_EQ(vertices.size(), 5u);
  const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}};
  EXPECT_EQ(triangles, expected);
}

TEST_F(IoLoadMesh, LegacyVtkAsciiPolygonsAndStrips) {
  writeFile(path("shape.vtk"), "# vtk DataFile Version 3.0\n"
                               "hand made\n"
                               "ASCII\n"
                               "DATASET POLYDATA\n"
                               "POINTS 5 float\n"
                               "0 0 0 1 0 0 1 1 0\n0 1 0 0.5 0.5 1\n"
                               "VERTICES 1 2\n1 4\n"
                               "POLYGONS 1 5\n4 0 1 2 3\n"
                               "TRIANGLE_STRIPS 1 5\n4 0 1 4 2\n"
                               "POINT_DATA 5\nSCALARS s float 1\nLOOKUP_TABLE default\n"
                               "1 2 3 4 5\n");
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("shape.vtk"), vertices, triangles, error)) << error;
  EXPECT_EQ(vertices.size(), 5u);
  const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {4, 1, 2}};
  EXPECT_EQ(triangles, expected);
}

TEST_F(IoLoadMesh, LegacyVtkVersion5OffsetsLayout) {
  writeFile(path("new.vtk"), "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET POLYDATA\n"
                             "POINTS 4 float\n0 0 0 1 0 0 1 1 0 0 1 0\n"
                             "POLYGONS 3 6\nOFFSETS vtktypeint64\n0 3 6\n"
                             "CONNECTIVITY vtktypeint64\n0 1 2 0 2 3\n");
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("new.vtk"), vertices, triangles, error)) << error;
  const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(triangles, expected);
}

TEST_F(IoLoadMesh, LegacyVtkBinaryIsBigEndian) {
  std::string bytes = "# vtk DataFile Version 3.0\nbinary\nBINARY\nDATASET POLYDATA\n"
                      "POINTS 3 float\n";
  const auto appendBigEndian = [&bytes](auto value) {
    unsigned char raw[sizeof(value)];
    std::memcpy(raw, &value, sizeof(value));
    std::reverse(raw, raw + sizeof(value));
    bytes.append(reinterpret_cast<const char *>(raw), sizeof(value));
  };
  for (float coordinate : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 2.f, 0.f})
    appendBigEndian(coordinate);
  bytes += "\nPOLYGONS 1 4\n";
  for (std::int32_t value : {3, 0, 1, 2})
    appendBigEndian(value);
  bytes += "\n";
  writeFile(path("binary.vtk"), bytes);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("binary.vtk"), vertices, triangles, error)) << error;
  ASSERT_EQ(vertices.size(), 3u);
  EXPECT_EQ(vertices[2], Eigen::Vector3d(0, 2, 0));
  const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}};
  EXPECT_EQ(triangles, expected);
}

TEST_F(IoLoadMesh, PlyTriangleStrips) {
  writeFile(path("strips.ply"), "ply\nformat ascii 1.0\nelement vertex 5\n"
                                "property double x\nproperty double y\nproperty double z\n"
                                "element tristrips 1\nproperty list int int vertex_indices\n"
                                "end_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 2 0\n"
                                "6 0 1 2 3 -1 4\n");
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("strips.ply"), vertices, triangles, error)) << error;
  const std::vector<pcl_ms::Triangle> expected = {{0, 1, 2}, {2, 1, 3}};
  EXPECT_EQ(triangles, expected);
}

TEST_F(IoLoadMesh, BadIndicesAndShortFilesFail) {
  writeFile(path("index.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("index.off")), "vertex 7"));
  writeFile(path("short.off"), "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("short.off")), "truncated"));
  writeFile(path("index.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("index.obj")), "line 4"));
  writeFile(path("two_corners.obj"), "v 0 0 0\nv 1 0 0\nf 1 2\n");
  expectMeshFailure(path("two_corners.obj"));
  writeFile(path("index.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("index.ply")), "vertex 3"));
  // VTK values are read as numbers: indices past any integer type, fractions
  // and NaN must be refused before they are converted.
  const std::string vtk_head = "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n"
                               "POINTS 4 float\n0 0 0 1 0 0 0 1 0 1 1 0\n";
  writeFile(path("huge.vtk"), vtk_head + "TRIANGLE_STRIPS 1 5\n4 4e37 1 0 1\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("huge.vtk")), "vertex 4e+37"));
  writeFile(path("fraction.vtk"), vtk_head + "POLYGONS 1 4\n3 0 1.5 2\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("fraction.vtk")), "vertex 1.5"));
  writeFile(path("nan_size.vtk"), vtk_head + "POLYGONS 1 4\nnan 0 1 2\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("nan_size.vtk")), "corrupt VTK cell list"));
  writeFile(path("nan_offset.vtk"), vtk_head + "POLYGONS 2 3\nOFFSETS vtktypeint64\n0 nan\n"
                                               "CONNECTIVITY vtktypeint64\n0 1 2\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("nan_offset.vtk")), "offsets"));
  // Faces checked against four points, then two points in a second list (a
  // fuzzer's find): the faces would index points the mesh does not have.
  writeFile(path("two_point_lists.vtk"),
            vtk_head + "POLYGONS 1 4\n3 0 1 3\nPOINTS 2 float\n0 0 0 1 0 0\n");
  EXPECT_TRUE(
      contains(expectMeshFailure(path("two_point_lists.vtk")), "more than one POINTS section"));
}

TEST_F(IoLoadMesh, PointCloudFilesHaveNoFaces) {
  EXPECT_TRUE(contains(expectMeshFailure(kDataDir + "/bun0.pcd"), "unknown"));
  ASSERT_EQ(pcl::io::savePLYFile(path("cloud.ply"), makeCloud(10), true), 0);
  EXPECT_TRUE(contains(expectMeshFailure(path("cloud.ply")), "no faces"));
}

TEST_F(IoLoadMesh, TruncatedBinaryPlyFails) {
  std::string error;
  ASSERT_TRUE(pcl_ms::saveMesh(path("mesh.ply"), makeGridMesh(20, 20), error)) << error;
  const std::size_t header = headerEnd(path("mesh.ply"), "end_header");
  const std::size_t size = readFile(path("mesh.ply")).size();
  for (std::size_t cut : {std::size_t(5), header, (header + size) / 2, size - 1}) {
    fs::copy_file(path("mesh.ply"), path("cut.ply"), fs::copy_options::overwrite_existing);
    cutFile(path("cut.ply"), cut);
    SCOPED_TRACE("cut at " + std::to_string(cut));
    expectMeshFailure(path("cut.ply"));
  }
}

TEST_F(IoLoadMesh, GarbageMissingEmptyAndUnknownFail) {
  std::mt19937 random(11);
  std::string garbage(4096, '\0');
  for (char &byte : garbage)
    byte = static_cast<char>(random());
  for (const char *name : {"noise.ply", "noise.off", "noise.obj", "noise.vtk", "noise.stl"}) {
    writeFile(path(name), garbage);
    expectMeshFailure(path(name));
    writeFile(path(std::string("empty_") + name), "");
    EXPECT_TRUE(contains(expectMeshFailure(path(std::string("empty_") + name)), "empty"));
  }
  EXPECT_TRUE(contains(expectMeshFailure(path("missing.ply")), "does not exist"));
  fs::create_directory(path("folder.off"));
  EXPECT_TRUE(contains(expectMeshFailure(path("folder.off")), "directory"));
  writeFile(path("mesh.wrl"), "#VRML V2.0 utf8\n");
  EXPECT_TRUE(contains(expectMeshFailure(path("mesh.wrl")), "unknown"));
}

// ---------------------------------------------------------------------------
// Saving

class IoSaveMesh : public TempDirTest {};

TEST_F(IoSaveMesh, RoundTripThroughEveryFormat) {
  const pcl::PolygonMesh mesh = makeGridMesh(7, 9);
  pcl::PointCloud<pcl::PointXYZ> original;
  pcl::fromPCLPointCloud2(mesh.cloud, original);
  struct Case {
    const char *name;
    bool binary;
  };
  for (const Case &format : {Case{"binary.ply", true}, Case{"ascii.ply", false},
                             Case{"mesh.vtk", true}, Case{"mesh.obj", true}}) {
    SCOPED_TRACE(format.name);
    std::string error;
    ASSERT_TRUE(pcl_ms::saveMesh(path(format.name), mesh, error, format.binary)) << error;
    std::vector<Eigen::Vector3d> vertices;
    std::vector<pcl_ms::Triangle> triangles;
    ASSERT_TRUE(pcl_ms::loadMesh(path(format.name), vertices, triangles, error)) << error;
    ASSERT_EQ(vertices.size(), original.size());
    for (std::size_t v = 0; v < vertices.size(); ++v)
      EXPECT_EQ(vertices[v].cast<float>(), original[v].getVector3fMap()) << "vertex " << v;
    ASSERT_EQ(triangles.size(), mesh.polygons.size());
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int corner = 0; corner < 3; ++corner)
        EXPECT_EQ(static_cast<int>(triangles[t][corner]), mesh.polygons[t].vertices[corner]);
  }
}

TEST_F(IoSaveMesh, PlyKeepsNormals) {
  std::string error;
  ASSERT_TRUE(pcl_ms::saveMesh(path("normals.ply"), makeGridMesh(4, 4), error)) << error;
  pcl::PCLPointCloud2 loaded;
  ASSERT_TRUE(pcl_ms::loadPointCloud(path("normals.ply"), loaded, error)) << error;
  EXPECT_EQ(loaded.width * loaded.height, 16u);
  EXPECT_TRUE(pcl_ms::hasNormals(loaded));
}

TEST_F(IoSaveMesh, FieldsTheWritersCannotHandleAreDropped) {
  // PCL's PLY writer would declare an int32 curvature as float but not write
  // its values, corrupting the file; such fields must be left out instead.
  pcl::PolygonMesh mesh = makeGridMesh(3, 3);
  for (pcl::PCLPointField &field : mesh.cloud.fields)
    if (field.name == "curvature")
      field.datatype = pcl::PCLPointField::INT32;
  std::string error;
  for (const char *name : {"odd.ply", "odd.vtk", "odd.obj"}) {
    ASSERT_TRUE(pcl_ms::saveMesh(path(name), mesh, error)) << error;
    std::vector<Eigen::Vector3d> vertices;
    std::vector<pcl_ms::Triangle> triangles;
    ASSERT_TRUE(pcl_ms::loadMesh(path(name), vertices, triangles, error)) << error;
    EXPECT_EQ(vertices.size(), 9u);
    EXPECT_EQ(triangles.size(), 8u);
  }
}

TEST_F(IoSaveMesh, UnknownExtensionFails) {
  std::string error;
  EXPECT_FALSE(pcl_ms::saveMesh(path("mesh.stl"), makeGridMesh(3, 3), error));
  EXPECT_TRUE(contains(error, "unknown")) << error;
  EXPECT_FALSE(fs::exists(path("mesh.stl")));
  EXPECT_FALSE(pcl_ms::isMeshOutputSupported("mesh.stl"));
  EXPECT_TRUE(pcl_ms::isMeshOutputSupported("MESH.PLY"));
}

TEST_F(IoSaveMesh, UnwritablePathFails) {
  std::string error;
  EXPECT_FALSE(pcl_ms::saveMesh(path("no_such_dir/mesh.ply"), makeGridMesh(3, 3), error));
  EXPECT_TRUE(contains(error, "cannot open")) << error;
  fs::create_directory(path("folder.ply"));
  EXPECT_FALSE(pcl_ms::saveMesh(path("folder.ply"), makeGridMesh(3, 3), error));
  EXPECT_TRUE(contains(error, "directory")) << error;
}

TEST_F(IoSaveMesh, InvalidMeshFailsWithoutLeavingAFile) {
  std::string error;
  EXPECT_FALSE(pcl_ms::saveMesh(path("empty.ply"), pcl::PolygonMesh(), error));
  EXPECT_FALSE(fs::exists(path("empty.ply")));
  pcl::PolygonMesh mesh = makeGridMesh(3, 3);
  mesh.polygons[1].vertices[2] = 9;
  for (const char *name : {"bad.ply", "bad.vtk", "bad.obj"}) {
    EXPECT_FALSE(pcl_ms::saveMesh(path(name), mesh, error));
    EXPECT_TRUE(contains(error, "polygon 1")) << error;
    EXPECT_FALSE(fs::exists(path(name)));
  }
  mesh = makeGridMesh(3, 3);
  mesh.polygons[0].vertices.clear();
  EXPECT_FALSE(pcl_ms::saveMesh(path("hole.vtk"), mesh, error));
}

TEST(IoHasNormals, NeedsAllThreeFloatFields) {
  pcl::PCLPointCloud2 cloud;
  pcl::toPCLPointCloud2(pcl::PointCloud<pcl::PointXYZ>(), cloud);
  EXPECT_FALSE(pcl_ms::hasNormals(cloud));
  pcl::toPCLPointCloud2(pcl::PointCloud<pcl::PointNormal>(), cloud);
  EXPECT_TRUE(pcl_ms::hasNormals(cloud));
  cloud.fields.erase(
      std::remove_if(cloud.fields.begin(), cloud.fields.end(),
                     [](const pcl::PCLPointField &field) { return field.name == "normal_z"; }),
      cloud.fields.end());
  EXPECT_FALSE(pcl_ms::hasNormals(cloud));
}

TEST(IoFileExtension, LowerCaseWithDot) {
  EXPECT_EQ(pcl_ms::fileExtension("dir.v2/Scan.PLY"), ".ply");
  EXPECT_EQ(pcl_ms::fileExtension("dir.v2/scan"), "");
  EXPECT_EQ(pcl_ms::fileExtension("a.b.Xyz"), ".xyz");
}

} // namespace

// SPDX-License-Identifier: GPL-3.0-or-later
// Reference meshes as distributed are often ASCII PLY with extra vertex
// properties: their float positions must read exactly as the same floats
// stored in binary, or exact position matching finds nothing.
#include "program_test.h"

#include <pcl_ms/io.h>

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace {

using namespace pcl_ms_test;

class PlyPrecision : public TempDirTest {};

// Decimal texts as a scanner writes them: none is exactly a float, and each
// rounds differently as a double than as a float.
const std::vector<std::string> kCoordinateTexts = {"-0.0378297", "0.12794",  "0.00447467",
                                                   "-0.0447794", "0.128887", "0.00190497",
                                                   "-0.0680095", "0.151244", "0.0371953"};

std::string binaryFloats(const std::vector<float> &values) {
  std::string bytes(values.size() * sizeof(float), '\0');
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

TEST_F(PlyPrecision, AsciiFloatPropertiesReadAsTheirBinaryCopy) {
  std::string ascii = "ply\nformat ascii 1.0\nelement vertex 3\n"
                      "property float x\nproperty float y\nproperty float z\n"
                      "property float confidence\nproperty float intensity\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<float> binary_vertices;
  for (int v = 0; v < 3; ++v) {
    for (int k = 0; k < 3; ++k) {
      ascii += kCoordinateTexts[3 * v + k] + " ";
      binary_vertices.push_back(std::stof(kCoordinateTexts[3 * v + k]));
    }
    ascii += "1 0.5\n";
  }
  ascii += "3 0 1 2\n";
  writeFile(path("ascii.ply"), ascii);

  // Binary little-endian (this machine's order is checked below) with x y z only.
  std::uint16_t probe = 1;
  std::uint8_t first_byte;
  std::memcpy(&first_byte, &probe, 1);
  ASSERT_EQ(first_byte, 1) << "the test writes little-endian floats";
  std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                       binaryFloats(binary_vertices);
  const std::int32_t corners[3] = {0, 1, 2};
  binary += '\3';
  binary += std::string(reinterpret_cast<const char *>(corners), sizeof corners);
  writeFile(path("binary.ply"), binary);

  std::vector<Eigen::Vector3d> from_ascii, from_binary;
  std::vector<pcl_ms::Triangle> ascii_triangles, binary_triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("ascii.ply"), from_ascii, ascii_triangles, error)) << error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("binary.ply"), from_binary, binary_triangles, error)) << error;
  ASSERT_EQ(from_ascii.size(), 3u);
  ASSERT_EQ(from_binary.size(), 3u);
  for (std::size_t v = 0; v < 3; ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(from_ascii[v][k], from_binary[v][k]) << "vertex " << v << " axis " << k;
  EXPECT_EQ(ascii_triangles, binary_triangles);
}

/// A three-vertex, one-face ASCII PLY whose coordinates have `type`.
std::string asciiTriangle(const std::string &type, const std::string &vertex_lines) {
  return "ply\nformat ascii 1.0\nelement vertex 3\nproperty " + type + " x\nproperty " + type +
         " y\nproperty " + type + " z\nelement face 1\nproperty list uchar int vertex_indices\n" +
         "end_header\n" + vertex_lines + "3 0 1 2\n";
}

TEST_F(PlyPrecision, DoublesKeepTheirPrecisionAndFloatsTheirRange) {
  writeFile(path("double.ply"), asciiTriangle("double", "0.1 0 0\n0 0.2 0\n0 0 0.3\n"));
  std::vector<Eigen::Vector3d> vertices;
  std::vector<pcl_ms::Triangle> triangles;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(path("double.ply"), vertices, triangles, error)) << error;
  EXPECT_EQ(vertices[0].x(), 0.1);
  EXPECT_EQ(vertices[2].z(), 0.3);

  writeFile(path("overflow.ply"), asciiTriangle("float", "1e39 0 0\n0 1 0\n0 0 1\n"));
  EXPECT_FALSE(pcl_ms::loadMesh(path("overflow.ply"), vertices, triangles, error))
      << "a float property cannot hold 1e39";
  EXPECT_NE(error.find("PLY"), std::string::npos) << error;
}

} // namespace

// SPDX-License-Identifier: GPL-3.0-or-later
// The ROS-free layer under the ROS nodes (src/ros/cloud_meshing.h): layout
// checks, point-type choice, meshing, marker arrays. No ROS master needed.
#include "cloud_meshing.h"

// The fuzz target's body and its promises, for the corpus replay below.
#define PCL_MS_FUZZ_REPLAY
#include "../fuzz/cloud_message_fuzzer.cpp"

#include <gtest/gtest.h>

#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <utility>

using namespace pcl_ms::ros_bridge;

namespace {

pcl::PCLPointField makeField(const std::string &name, std::uint32_t offset,
                             std::uint8_t datatype = pcl::PCLPointField::FLOAT32) {
  pcl::PCLPointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = datatype;
  field.count = 1;
  return field;
}

// x y z rgb with 4 padding bytes per point and 8 per row, as drivers do.
struct ColoredPoint {
  float x, y, z;
  std::uint32_t rgb;
};

pcl::PCLPointCloud2 makeColoredCloud(std::uint32_t width, std::uint32_t height,
                                     const std::vector<ColoredPoint> &points) {
  pcl::PCLPointCloud2 cloud;
  cloud.width = width;
  cloud.height = height;
  cloud.fields = {makeField("x", 0), makeField("y", 4), makeField("z", 8),
                  makeField("rgb", 12, pcl::PCLPointField::UINT32)};
  cloud.point_step = 20;
  cloud.row_step = width * cloud.point_step + 8;
  cloud.is_dense = false;
  cloud.data.assign(static_cast<std::size_t>(cloud.row_step) * height, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t offset = (i / width) * cloud.row_step + (i % width) * cloud.point_step;
    std::memcpy(&cloud.data[offset], &points[i].x, 12);
    std::memcpy(&cloud.data[offset + 12], &points[i].rgb, 4);
  }
  return cloud;
}

// An organized 40 x 30 depth frame of a wavy surface seen along +z, with NaN
// pixels (a disc, as occlusions leave them), each pixel's colour encoding
// its column and row.
pcl::PCLPointCloud2 makeOrganizedFrame() {
  const std::uint32_t width = 40, height = 30;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<ColoredPoint> points;
  for (std::uint32_t row = 0; row < height; ++row)
    for (std::uint32_t column = 0; column < width; ++column) {
      const float u = (static_cast<float>(column) - 20.0f) * 0.01f;
      const float v = (static_cast<float>(row) - 15.0f) * 0.01f;
      const bool hole = (u - 0.08f) * (u - 0.08f) + v * v < 0.004f;
      const float depth = 1.0f + 0.05f * std::sin(10.0f * u) * std::cos(8.0f * v);
      const std::uint32_t rgb = (column * 6u) << 16 | (row * 8u) << 8 | 200u;
      points.push_back(hole ? ColoredPoint{nan, nan, nan, rgb}
                            : ColoredPoint{u * depth, v * depth, depth, rgb});
    }
  return makeColoredCloud(width, height, points);
}

// The same points with x, y, z as FLOAT64 (8 bytes each, then rgb), each
// coordinate plus `offset`.
pcl::PCLPointCloud2 withDoubleCoordinates(const pcl::PCLPointCloud2 &cloud,
                                          const std::array<double, 3> &offset = {0, 0, 0}) {
  pcl::PCLPointCloud2 wide;
  wide.width = cloud.width;
  wide.height = cloud.height;
  wide.fields = {makeField("x", 0, pcl::PCLPointField::FLOAT64),
                 makeField("y", 8, pcl::PCLPointField::FLOAT64),
                 makeField("z", 16, pcl::PCLPointField::FLOAT64),
                 makeField("rgb", 24, pcl::PCLPointField::UINT32)};
  wide.point_step = 28;
  wide.row_step = wide.width * wide.point_step;
  wide.is_dense = cloud.is_dense;
  wide.data.assign(static_cast<std::size_t>(wide.row_step) * wide.height, 0);
  for (std::size_t i = 0; i < static_cast<std::size_t>(cloud.width) * cloud.height; ++i) {
    const std::uint8_t *from =
        &cloud.data[(i / cloud.width) * cloud.row_step + (i % cloud.width) * cloud.point_step];
    std::uint8_t *to = &wide.data[i * wide.point_step];
    for (int k = 0; k < 3; ++k) {
      float value;
      std::memcpy(&value, from + 4 * k, sizeof value);
      const double widened = static_cast<double>(value) + offset[k];
      std::memcpy(to + 8 * k, &widened, sizeof widened);
    }
    std::memcpy(to + 24, from + 12, 4);
  }
  return wide;
}

std::size_t countFinitePoints(const pcl::PCLPointCloud2 &cloud) {
  std::size_t finite = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(cloud.width) * cloud.height; ++i) {
    float z;
    std::memcpy(
        &z,
        &cloud.data[(i / cloud.width) * cloud.row_step + (i % cloud.width) * cloud.point_step + 8],
        sizeof z);
    finite += std::isfinite(z) ? 1 : 0;
  }
  return finite;
}

// The corner indices of each polygon, in order.
std::vector<pcl::Indices> cornersOf(const std::vector<pcl::Vertices> &polygons) {
  std::vector<pcl::Indices> corners;
  for (const pcl::Vertices &polygon : polygons)
    corners.push_back(polygon.vertices);
  return corners;
}

// Edges used by more than two triangles.
std::size_t countNonManifoldEdges(const std::vector<pcl::Vertices> &polygons) {
  std::map<std::pair<pcl::index_t, pcl::index_t>, int> uses;
  for (const pcl::Vertices &polygon : polygons)
    for (std::size_t corner = 0; corner < 3; ++corner) {
      pcl::index_t a = polygon.vertices[corner], b = polygon.vertices[(corner + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::size_t non_manifold = 0;
  for (const auto &edge : uses)
    non_manifold += edge.second > 2 ? 1 : 0;
  return non_manifold;
}

} // namespace

TEST(RosBridgeLayout, AcceptsAPaddedOrganizedCloud) {
  EXPECT_EQ(checkCloudLayout(makeOrganizedFrame()), "");
}

TEST(RosBridgeLayout, RefusesEachBrokenLayoutWithItsReason) {
  const pcl::PCLPointCloud2 good = makeOrganizedFrame();

  pcl::PCLPointCloud2 empty = good;
  empty.width = 0;
  EXPECT_NE(checkCloudLayout(empty).find("empty"), std::string::npos);

  pcl::PCLPointCloud2 no_z = good;
  no_z.fields.erase(no_z.fields.begin() + 2);
  EXPECT_NE(checkCloudLayout(no_z).find("no 'z' field"), std::string::npos);

  pcl::PCLPointCloud2 integer_x = good;
  integer_x.fields[0].datatype = pcl::PCLPointField::INT32;
  EXPECT_NE(checkCloudLayout(integer_x).find("'x' is not FLOAT32 or FLOAT64"), std::string::npos);

  pcl::PCLPointCloud2 field_outside = good;
  field_outside.fields[3].offset = 18;
  EXPECT_NE(checkCloudLayout(field_outside).find("past point_step"), std::string::npos);

  pcl::PCLPointCloud2 short_rows = good;
  short_rows.row_step = good.width * good.point_step - 1;
  EXPECT_NE(checkCloudLayout(short_rows).find("row_step"), std::string::npos);

  pcl::PCLPointCloud2 short_data = good;
  short_data.data.resize(good.data.size() - 1);
  EXPECT_NE(checkCloudLayout(short_data).find("bytes"), std::string::npos);

  pcl::PCLPointCloud2 big_endian = good;
  big_endian.is_bigendian = true;
  EXPECT_NE(checkCloudLayout(big_endian).find("big-endian"), std::string::npos);
}

TEST(RosBridgePointType, NormalsOnlyWhenAskedForAndPresent) {
  const std::vector<pcl::PCLPointField> plain = {makeField("x", 0), makeField("y", 4),
                                                 makeField("z", 8)};
  std::vector<pcl::PCLPointField> with_normals = plain;
  with_normals.push_back(makeField("normal_x", 16));
  with_normals.push_back(makeField("normal_y", 20));
  with_normals.push_back(makeField("normal_z", 24));

  EXPECT_FALSE(hasNormalFields(plain));
  EXPECT_TRUE(hasNormalFields(with_normals));
  EXPECT_EQ(choosePointType(plain, true), MeshingPointType::xyz);
  EXPECT_EQ(choosePointType(with_normals, false), MeshingPointType::xyz);
  EXPECT_EQ(choosePointType(with_normals, true), MeshingPointType::xyz_normal);

  with_normals[4].datatype = pcl::PCLPointField::FLOAT64; // read as float
  EXPECT_EQ(choosePointType(with_normals, true), MeshingPointType::xyz_normal);
  with_normals[4].datatype = pcl::PCLPointField::INT16;
  EXPECT_EQ(choosePointType(with_normals, true), MeshingPointType::xyz);
}

TEST(RosBridgeMeshing, MeshesTheBunnyManifold) {
  pcl::PCLPointCloud2 bunny;
  ASSERT_EQ(pcl::io::loadPCDFile(PCL_MS_DATA_DIR "/bunny.pcd", bunny), 0);
  const MeshingOutcome outcome = meshCloud(bunny, pcl_ms::Parameters());
  ASSERT_EQ(outcome.error, "");
  EXPECT_EQ(outcome.finite_points, 35947u);
  // The reference surface has 69,451 triangles; the library keeps > 98 %.
  EXPECT_GT(outcome.polygons.size(), 68000u);
  EXPECT_EQ(countNonManifoldEdges(outcome.polygons), 0u);
  EXPECT_EQ(outcome.boundary_loops.size(), 5u); // the base's openings
  EXPECT_GT(outcome.median_circumradius, 0.0);
  EXPECT_GT(outcome.library_seconds, 0.0);
}

TEST(RosBridgeMeshing, OrganizedFrameWithNaNsIndexesOnlyFinitePoints) {
  const pcl::PCLPointCloud2 frame = makeOrganizedFrame();
  const std::size_t finite = countFinitePoints(frame);
  ASSERT_LT(finite, 1200u); // the disc of NaNs is there
  const MeshingOutcome outcome = meshCloud(frame, pcl_ms::Parameters());
  ASSERT_EQ(outcome.error, "");
  EXPECT_EQ(outcome.finite_points, finite);
  // A height field of n points has about 2n triangles.
  EXPECT_GT(outcome.polygons.size(), 3 * finite / 2);
  EXPECT_EQ(countNonManifoldEdges(outcome.polygons), 0u);
  EXPECT_GE(outcome.boundary_loops.size(), 2u); // the frame's border and the hole

  // Every corner is a finite pixel, so the marker keeps every triangle.
  const MarkerGeometry triangles = triangleListGeometry(frame, outcome.polygons);
  EXPECT_EQ(triangles.points.size(), 3 * outcome.polygons.size());
  ASSERT_EQ(triangles.colors.size(), triangles.points.size());
  // Colours come from each corner's own pixel: column * 6 in red, row * 8 in green.
  for (std::size_t t = 0; t < outcome.polygons.size(); t += 97) {
    const pcl::index_t pixel = outcome.polygons[t].vertices[0];
    EXPECT_FLOAT_EQ(triangles.colors[3 * t][0], static_cast<float>((pixel % 40) * 6) / 255.0f);
    EXPECT_FLOAT_EQ(triangles.colors[3 * t][1], static_cast<float>((pixel / 40) * 8) / 255.0f);
    EXPECT_FLOAT_EQ(triangles.colors[3 * t][2], 200.0f / 255.0f);
    EXPECT_FLOAT_EQ(triangles.colors[3 * t][3], 1.0f);
  }
}

// How many triangles face `viewpoint` (normal towards it, by winding).
static std::size_t countFacing(const pcl::PCLPointCloud2 &cloud,
                               const std::vector<pcl::Vertices> &polygons,
                               const std::array<float, 3> &viewpoint) {
  const MarkerGeometry corners = triangleListGeometry(cloud, polygons);
  std::size_t facing = 0;
  for (std::size_t t = 0; 3 * t + 2 < corners.points.size(); ++t) {
    const auto &a = corners.points[3 * t], &b = corners.points[3 * t + 1],
               &c = corners.points[3 * t + 2];
    const float ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float normal[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                             ab[0] * ac[1] - ab[1] * ac[0]};
    float dot = 0;
    for (int k = 0; k < 3; ++k)
      dot += normal[k] * (a[k] - viewpoint[k]);
    facing += dot < 0 ? 1 : 0;
  }
  return facing;
}

TEST(RosBridgeMeshing, OrganizedFrameFacesItsOriginOrTheGivenViewpoint) {
  const pcl::PCLPointCloud2 frame = makeOrganizedFrame();
  // A PointCloud2 has no sensor origin: the frame's origin stands for it.
  const MeshingOutcome from_origin = meshCloud(frame, pcl_ms::Parameters());
  ASSERT_EQ(from_origin.error, "");
  // A few triangles on steep slopes face away from any one point; the
  // orientation's sign shows in the rest.
  EXPECT_GT(countFacing(frame, from_origin.polygons, {0, 0, 0}),
            from_origin.polygons.size() * 95 / 100);

  pcl_ms::Parameters behind;
  behind.viewpoint = std::array<double, 3>{0.0, 0.0, 5.0};
  const MeshingOutcome from_behind = meshCloud(frame, behind);
  ASSERT_EQ(from_behind.error, "");
  EXPECT_GT(countFacing(frame, from_behind.polygons, {0, 0, 5}),
            from_behind.polygons.size() * 95 / 100);
}

TEST(RosBridgeMeshing, DoubleCoordinatesMeshAsTheirFloats) {
  // FLOAT64 x, y, z holding the frame's floats: read as float, the same
  // mesh and markers. Far from the origin (UTM-like), rounding to float
  // would move the pixels by much of their spacing: refused with the reason.
  const pcl::PCLPointCloud2 frame = makeOrganizedFrame();
  const pcl::PCLPointCloud2 wide = withDoubleCoordinates(frame);
  ASSERT_EQ(checkCloudLayout(wide), "");
  const MeshingOutcome narrow_outcome = meshCloud(frame, pcl_ms::Parameters());
  const MeshingOutcome wide_outcome = meshCloud(wide, pcl_ms::Parameters());
  ASSERT_EQ(wide_outcome.error, "");
  ASSERT_FALSE(wide_outcome.polygons.empty());
  EXPECT_EQ(cornersOf(wide_outcome.polygons), cornersOf(narrow_outcome.polygons));
  EXPECT_EQ(cornersOf(wide_outcome.boundary_loops), cornersOf(narrow_outcome.boundary_loops));
  const MarkerGeometry narrow_markers = triangleListGeometry(frame, narrow_outcome.polygons);
  const MarkerGeometry wide_markers = triangleListGeometry(wide, wide_outcome.polygons);
  EXPECT_EQ(wide_markers.points, narrow_markers.points);
  EXPECT_EQ(wide_markers.colors, narrow_markers.colors);

  const MeshingOutcome far =
      meshCloud(withDoubleCoordinates(frame, {512000.0, 5401000.0, 0.0}), pcl_ms::Parameters());
  EXPECT_NE(far.error.find("shift the cloud near the origin"), std::string::npos) << far.error;
  EXPECT_TRUE(far.polygons.empty());
}

TEST(RosBridgeMeshing, BadCloudsComeBackAsErrorsNotCrashes) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const pcl::PCLPointCloud2 all_nan =
      makeColoredCloud(4, 1, {{nan, nan, nan, 0}, {nan, 0, 0, 0}, {0, nan, 0, 0}, {0, 0, nan, 0}});
  EXPECT_NE(meshCloud(all_nan, pcl_ms::Parameters()).error, "");

  const pcl::PCLPointCloud2 collinear =
      makeColoredCloud(4, 1, {{0, 0, 0, 0}, {1, 1, 1, 0}, {2, 2, 2, 0}, {3, 3, 3, 0}});
  const MeshingOutcome collinear_outcome = meshCloud(collinear, pcl_ms::Parameters());
  EXPECT_NE(collinear_outcome.error, "");
  EXPECT_TRUE(collinear_outcome.polygons.empty());

  pcl::PCLPointCloud2 no_y = makeOrganizedFrame();
  no_y.fields.erase(no_y.fields.begin() + 1);
  EXPECT_NE(meshCloud(no_y, pcl_ms::Parameters()).error.find("no 'y' field"), std::string::npos);

  pcl_ms::Parameters bad_parameters;
  bad_parameters.fill_holes_max_edges = 2;
  EXPECT_NE(meshCloud(makeOrganizedFrame(), bad_parameters).error.find("fill_holes"),
            std::string::npos);
}

TEST(RosBridgeMeshing, WarnsWhenNormalsAreAskedForButAbsent) {
  pcl_ms::Parameters parameters;
  parameters.use_normals = true;
  const MeshingOutcome outcome = meshCloud(makeOrganizedFrame(), parameters);
  EXPECT_EQ(outcome.error, "");
  EXPECT_NE(outcome.warning.find("use_normals"), std::string::npos);
  EXPECT_FALSE(outcome.polygons.empty());
}

TEST(RosBridgeMeshing, UsesTheCloudsNormalsWhenAskedTo) {
  // A 30 x 20 height field with normal_x/y/z (all towards the camera) and an
  // intensity field between them, as a LiDAR driver might lay them out.
  pcl::PCLPointCloud2 cloud;
  cloud.width = 30;
  cloud.height = 20;
  cloud.fields = {makeField("x", 0),          makeField("y", 4),         makeField("z", 8),
                  makeField("intensity", 12), makeField("normal_x", 16), makeField("normal_y", 20),
                  makeField("normal_z", 24)};
  cloud.point_step = 28;
  cloud.row_step = cloud.width * cloud.point_step;
  cloud.data.resize(static_cast<std::size_t>(cloud.row_step) * cloud.height);
  for (std::uint32_t i = 0; i < cloud.width * cloud.height; ++i) {
    const float u = static_cast<float>(i % cloud.width) * 0.01f;
    const float v = static_cast<float>(i / cloud.width) * 0.01f;
    const float values[7] = {u,    v,    1.0f + 0.02f * std::sin(20.0f * u + 10.0f * v), 0.5f, 0.0f,
                             0.0f, -1.0f};
    std::memcpy(&cloud.data[i * cloud.point_step], values, sizeof values);
  }
  pcl_ms::Parameters parameters;
  parameters.use_normals = true;
  // The cloud has no curvature field, which a PointNormal has: PCL's
  // conversion would print a warning for it with every message.
  testing::internal::CaptureStderr();
  const MeshingOutcome outcome = meshCloud(cloud, parameters);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(outcome.error, "");
  EXPECT_EQ(outcome.warning, "");
  EXPECT_GT(outcome.polygons.size(), 900u); // about 2 per point
  EXPECT_EQ(countNonManifoldEdges(outcome.polygons), 0u);
}

TEST(RosBridgeMarkers, TriangleListSkipsUnusablePolygons) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const pcl::PCLPointCloud2 cloud = makeColoredCloud(5, 1,
                                                     {{0, 0, 0, 0xff0000},
                                                      {1, 0, 0, 0x00ff00},
                                                      {0, 1, 0, 0x0000ff},
                                                      {1, 1, 0, 0xffffff},
                                                      {nan, 0, 0, 0}});
  std::vector<pcl::Vertices> polygons(5);
  polygons[0].vertices = {0, 1, 2};
  polygons[1].vertices = {1, 3, 2};
  polygons[2].vertices = {0, 1, 7};    // outside the cloud
  polygons[3].vertices = {0, 1, 4};    // a NaN corner
  polygons[4].vertices = {0, 1, 3, 2}; // not a triangle
  const MarkerGeometry geometry = triangleListGeometry(cloud, polygons);
  ASSERT_EQ(geometry.points.size(), 6u);
  ASSERT_EQ(geometry.colors.size(), 6u);
  EXPECT_EQ(geometry.points[3], (std::array<float, 3>{1, 0, 0}));
  EXPECT_EQ(geometry.points[4], (std::array<float, 3>{1, 1, 0}));
  EXPECT_EQ(geometry.colors[0], (std::array<float, 4>{1, 0, 0, 1}));
  EXPECT_EQ(geometry.colors[2], (std::array<float, 4>{0, 0, 1, 1}));
  EXPECT_EQ(geometry.colors[4], (std::array<float, 4>{1, 1, 1, 1}));

  pcl::PCLPointCloud2 uncoloured = cloud;
  uncoloured.fields.pop_back();
  EXPECT_TRUE(triangleListGeometry(uncoloured, polygons).colors.empty());
}

TEST(RosBridgeMarkers, BoundaryLinesCloseEachLoop) {
  const pcl::PCLPointCloud2 cloud =
      makeColoredCloud(4, 1, {{0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {5, 5, 5, 0}});
  std::vector<pcl::Vertices> loops(2);
  loops[0].vertices = {0, 1, 2};
  loops[1].vertices = {3}; // too short to be an edge
  const MarkerGeometry geometry = boundaryLineGeometry(cloud, loops);
  ASSERT_EQ(geometry.points.size(), 6u);
  EXPECT_TRUE(geometry.colors.empty());
  EXPECT_EQ(geometry.points[0], (std::array<float, 3>{0, 0, 0}));
  EXPECT_EQ(geometry.points[1], (std::array<float, 3>{1, 0, 0}));
  // The closing edge runs from the last point back to the first.
  EXPECT_EQ(geometry.points[4], (std::array<float, 3>{0, 1, 0}));
  EXPECT_EQ(geometry.points[5], (std::array<float, 3>{0, 0, 0}));
}

// Every message of the fuzz corpus (seeds and fixed findings) is refused or
// meshed, with the fuzz target's promises kept (a broken one aborts).
TEST(RosBridgeFuzzCorpus, EveryMessageIsRefusedOrMeshed) {
  namespace fs = std::filesystem;
  const fs::path corpus =
      fs::path(PCL_MS_DATA_DIR) / ".." / "tests" / "fuzz" / "corpus" / "cloud_message";
  std::vector<fs::path> files;
  for (const auto &entry : fs::directory_iterator(corpus))
    files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());
  for (const fs::path &file : files) {
    SCOPED_TRACE(file.filename().string());
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(pcl_ms_fuzz::cloudMessageOneInput(
                  reinterpret_cast<const std::uint8_t *>(bytes.data()), bytes.size()),
              0);
  }
}

// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of src/tools/render_mesh.h (suites Render*): pictures are rendered
// off-screen (a private Xvfb when there is no DISPLAY), read back with VTK's
// PNG reader and checked pixel by pixel.
#include "render_mesh.h"

#include <pcl_ms/io.h>

#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pcl_ms::Triangle;
using pcl_ms_tools::RenderOptions;
using pcl_ms_tools::RenderView;

struct Rgb {
  int r, g, b;
  bool operator==(const Rgb &other) const { return r == other.r && g == other.g && b == other.b; }
};

bool isWhite(const Rgb &c) { return c.r >= 250 && c.g >= 250 && c.b >= 250; }
// The boundary colour (0, 51, 255) and the non-manifold colour (230, 0, 0),
// with room for antialiasing at the line sides.
bool isBlue(const Rgb &c) { return c.b >= 180 && c.r <= 60 && c.g <= 110; }
bool isRed(const Rgb &c) { return c.r >= 180 && c.g <= 60 && c.b <= 60; }
// A face: the neutral surface colour, lit to some shade of grey.
bool isShadedGrey(const Rgb &c) {
  return !isWhite(c) && std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b}) <= 12;
}

// A PNG read back with VTK; row 0 is the bottom row, as VTK stores it.
struct Picture {
  int width = 0;
  int height = 0;
  std::vector<Rgb> pixels;

  const Rgb &at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }

  int count(bool (*predicate)(const Rgb &), int x0, int y0, int x1, int y1) const {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x)
        n += predicate(at(x, y)) ? 1 : 0;
    return n;
  }
  int count(bool (*predicate)(const Rgb &)) const { return count(predicate, 0, 0, width, height); }
};

Picture readPicture(const std::string &path) {
  vtkNew<vtkPNGReader> reader;
  EXPECT_TRUE(reader->CanReadFile(path.c_str())) << path;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData *image = reader->GetOutput();
  Picture picture;
  const int *size = image->GetDimensions();
  picture.width = size[0];
  picture.height = size[1];
  const int channels = image->GetNumberOfScalarComponents();
  EXPECT_GE(channels, 3) << path;
  EXPECT_EQ(image->GetScalarType(), VTK_UNSIGNED_CHAR) << path;
  if (channels < 3 || image->GetScalarType() != VTK_UNSIGNED_CHAR)
    return picture;
  for (int y = 0; y < picture.height; ++y)
    for (int x = 0; x < picture.width; ++x) {
      const auto *p = static_cast<const std::uint8_t *>(image->GetScalarPointer(x, y, 0));
      picture.pixels.push_back({p[0], p[1], p[2]});
    }
  return picture;
}

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
};

Mesh tetrahedron() {
  return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
          {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
}

Mesh singleTriangle() { return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}}; }

// Three triangles on the edge 0-1, fanned out like the pages of a book.
Mesh threePagesOnOneEdge() {
  return {{{0, 0, 0}, {0, 1, 0}, {1, 0.5, 0}, {-0.5, 0.5, 0.87}, {-0.5, 0.5, -0.87}},
          {{0, 1, 2}, {0, 1, 3}, {0, 1, 4}}};
}

class RenderTest : public ::testing::Test {
protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    dir_ = fs::temp_directory_path() /
           ("pcl_ms_render_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::string path(const std::string &name) const { return (dir_ / name).string(); }

  // Renders `mesh` framed by its own vertices and reads the picture back.
  Picture render(const Mesh &mesh, const std::string &name, const RenderOptions &options = {}) {
    std::string error;
    const RenderView view = pcl_ms_tools::viewFramingPoints(mesh.vertices);
    EXPECT_TRUE(pcl_ms_tools::renderMeshPng(mesh.vertices, mesh.triangles, view, options,
                                            path(name), error))
        << error;
    EXPECT_TRUE(error.empty()) << error;
    return readPicture(path(name));
  }

  fs::path dir_;
};

TEST_F(RenderTest, RenderClosedTetrahedronIsShadedOnWhiteWithoutColouredEdges) {
  RenderOptions options;
  options.width = 320;
  options.height = 240;
  const Picture picture = render(tetrahedron(), "tetrahedron.png", options);
  ASSERT_EQ(picture.width, 320);
  ASSERT_EQ(picture.height, 240);
  for (const Rgb &corner :
       {picture.at(0, 0), picture.at(319, 0), picture.at(0, 239), picture.at(319, 239)})
    EXPECT_TRUE(isWhite(corner));
  // Most of the middle is covered by shaded faces.
  EXPECT_GT(picture.count(isShadedGrey, 80, 60, 240, 180), 160 * 120 / 2);
  EXPECT_EQ(picture.count(isBlue), 0);
  EXPECT_EQ(picture.count(isRed), 0);
}

TEST_F(RenderTest, RenderOpenTriangleHasBlueBoundary) {
  const Picture picture = render(singleTriangle(), "triangle.png");
  ASSERT_EQ(picture.width, 800);
  ASSERT_EQ(picture.height, 800);
  EXPECT_TRUE(isWhite(picture.at(0, 0)));
  EXPECT_GT(picture.count(isShadedGrey), 1000);
  // Three sides, each hundreds of pixels long and at least 2 wide.
  EXPECT_GT(picture.count(isBlue), 3 * 200);
  EXPECT_EQ(picture.count(isRed), 0);
}

TEST_F(RenderTest, RenderEdgeOfThreeTrianglesIsRed) {
  const Picture picture = render(threePagesOnOneEdge(), "pages.png");
  EXPECT_GT(picture.count(isRed), 100);
  EXPECT_GT(picture.count(isBlue), 100); // the pages' outer sides
}

TEST_F(RenderTest, RenderFlippedFacesAreShadedAlike) {
  // The same triangle seen from its front and from its back.
  const Mesh front = singleTriangle();
  Mesh back = front;
  back.triangles = {{0, 2, 1}};
  const RenderView view = pcl_ms_tools::viewFramingPoints(front.vertices);
  RenderOptions options;
  options.width = options.height = 200;
  std::string error;
  ASSERT_TRUE(pcl_ms_tools::renderMeshPng(front.vertices, front.triangles, view, options,
                                          path("front.png"), error))
      << error;
  ASSERT_TRUE(pcl_ms_tools::renderMeshPng(back.vertices, back.triangles, view, options,
                                          path("back.png"), error))
      << error;
  const Picture front_picture = readPicture(path("front.png"));
  const Picture back_picture = readPicture(path("back.png"));
  ASSERT_EQ(front_picture.pixels.size(), back_picture.pixels.size());
  int different = 0;
  for (std::size_t i = 0; i < front_picture.pixels.size(); ++i) {
    const Rgb &a = front_picture.pixels[i];
    const Rgb &b = back_picture.pixels[i];
    different += std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b) > 6 ? 1 : 0;
  }
  EXPECT_LT(different, 50);
  EXPECT_GT(front_picture.count(isShadedGrey), 500);
}

TEST_F(RenderTest, RenderSkipsTrianglesWithMissingVertices) {
  Mesh mesh = tetrahedron();
  mesh.triangles.push_back({0, 1, 4});
  mesh.triangles.push_back({7, 8, 4000000000u});
  const Picture picture = render(mesh, "invalid.png");
  EXPECT_GT(picture.count(isShadedGrey), 1000);
  // A skipped triangle leaves no boundary edges behind.
  EXPECT_EQ(picture.count(isBlue), 0);
}

TEST_F(RenderTest, RenderEmptyMeshIsWhite) {
  RenderOptions options;
  options.width = 64;
  options.height = 48;
  const Picture picture = render(Mesh{}, "empty.png", options);
  ASSERT_EQ(picture.width, 64);
  EXPECT_EQ(picture.count(isWhite), 64 * 48);
}

TEST_F(RenderTest, RenderCaptionIsDrawnAtTheTop) {
  RenderOptions options;
  options.width = 400;
  options.height = 300;
  const Picture plain = render(tetrahedron(), "plain.png", options);
  options.caption = "Tetrahedron";
  const Picture captioned = render(tetrahedron(), "captioned.png", options);
  const auto dark = [](const Rgb &c) { return c.r < 100 && c.g < 100 && c.b < 100; };
  // Top 6 % of the picture (VTK rows count from the bottom).
  EXPECT_EQ(plain.count(dark, 0, 282, 400, 300), 0);
  EXPECT_GT(captioned.count(dark, 0, 282, 400, 300), 50);
}

TEST_F(RenderTest, RenderRejectsBadRequests) {
  const Mesh mesh = tetrahedron();
  const RenderView view = pcl_ms_tools::viewFramingPoints(mesh.vertices);
  std::string error;
  RenderOptions tiny;
  tiny.width = 0;
  EXPECT_FALSE(pcl_ms_tools::renderMeshPng(mesh.vertices, mesh.triangles, view, tiny,
                                           path("tiny.png"), error));
  EXPECT_NE(error.find("size"), std::string::npos) << error;

  RenderView no_direction = view;
  no_direction.direction = Eigen::Vector3d::Zero();
  error.clear();
  EXPECT_FALSE(pcl_ms_tools::renderMeshPng(mesh.vertices, mesh.triangles, no_direction, {},
                                           path("dir.png"), error));
  EXPECT_FALSE(error.empty());
  EXPECT_FALSE(fs::exists(path("tiny.png")));
}

TEST_F(RenderTest, RenderUnwritablePathFailsWithError) {
  const Mesh mesh = singleTriangle();
  const std::string unwritable = path("no_such_directory/picture.png");
  std::string error;
  RenderOptions options;
  options.width = options.height = 64;
  EXPECT_FALSE(pcl_ms_tools::renderMeshPng(mesh.vertices, mesh.triangles,
                                           pcl_ms_tools::viewFramingPoints(mesh.vertices), options,
                                           unwritable, error));
  EXPECT_NE(error.find(unwritable), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST_F(RenderTest, RenderSideBySideAppendsPicturesInOrder) {
  RenderOptions options;
  options.height = 150;
  options.width = 200;
  const Picture left = render(tetrahedron(), "left.png", options);
  options.width = 120;
  const Picture right = render(singleTriangle(), "right.png", options);
  std::string error;
  ASSERT_TRUE(pcl_ms_tools::composeSideBySide({path("left.png"), path("right.png")},
                                              path("both.png"), error))
      << error;
  const Picture both = readPicture(path("both.png"));
  ASSERT_EQ(both.width, 320);
  ASSERT_EQ(both.height, 150);
  int mismatches = 0;
  for (int y = 0; y < 150; ++y) {
    for (int x = 0; x < 200; ++x)
      mismatches += both.at(x, y) == left.at(x, y) ? 0 : 1;
    for (int x = 0; x < 120; ++x)
      mismatches += both.at(200 + x, y) == right.at(x, y) ? 0 : 1;
  }
  EXPECT_EQ(mismatches, 0);
}

TEST_F(RenderTest, RenderSideBySideRejectsDifferentHeightsAndBadFiles) {
  RenderOptions options;
  options.width = 100;
  options.height = 100;
  render(tetrahedron(), "a.png", options);
  options.height = 90;
  render(tetrahedron(), "b.png", options);
  std::string error;
  EXPECT_FALSE(
      pcl_ms_tools::composeSideBySide({path("a.png"), path("b.png")}, path("ab.png"), error));
  EXPECT_NE(error.find("height"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(path("ab.png")));

  error.clear();
  EXPECT_FALSE(
      pcl_ms_tools::composeSideBySide({path("a.png"), path("missing.png")}, path("am.png"), error));
  EXPECT_NE(error.find(path("missing.png")), std::string::npos) << error;

  {
    std::ofstream garbage(path("garbage.png"));
    garbage << "not a png";
  }
  error.clear();
  EXPECT_FALSE(pcl_ms_tools::composeSideBySide({path("garbage.png")}, path("g.png"), error));
  EXPECT_NE(error.find(path("garbage.png")), std::string::npos) << error;

  // vtkPNGReader alone would crash on this one.
  {
    std::ifstream whole(path("a.png"), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(whole)), {});
    std::ofstream truncated(path("truncated.png"), std::ios::binary);
    truncated << bytes.substr(0, bytes.size() / 2);
  }
  error.clear();
  EXPECT_FALSE(pcl_ms_tools::composeSideBySide({path("a.png"), path("truncated.png")},
                                               path("at.png"), error));
  EXPECT_NE(error.find(path("truncated.png")), std::string::npos) << error;

  error.clear();
  EXPECT_FALSE(pcl_ms_tools::composeSideBySide({}, path("none.png"), error));
  EXPECT_FALSE(error.empty());

  error.clear();
  EXPECT_FALSE(
      pcl_ms_tools::composeSideBySide({path("a.png")}, path("no_such_directory/a.png"), error));
  EXPECT_NE(error.find("no_such_directory"), std::string::npos) << error;
}

TEST_F(RenderTest, RenderFromSeveralThreadsAtOnce) {
  const Mesh mesh = singleTriangle();
  const RenderView view = pcl_ms_tools::viewFramingPoints(mesh.vertices);
  RenderOptions options;
  options.width = options.height = 96;
  std::vector<std::string> errors(3);
  std::vector<char> rendered(3, 0);
  std::vector<std::thread> threads;
  for (int i = 0; i < 3; ++i)
    threads.emplace_back([&, i] {
      rendered[i] =
          pcl_ms_tools::renderMeshPng(mesh.vertices, mesh.triangles, view, options,
                                      path("thread" + std::to_string(i) + ".png"), errors[i]);
    });
  for (std::thread &thread : threads)
    thread.join();
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(rendered[i]) << errors[i];
    const Picture picture = readPicture(path("thread" + std::to_string(i) + ".png"));
    EXPECT_GT(picture.count(isBlue), 50);
  }
}

TEST(RenderView, RenderViewFramesEveryPointDeterministically) {
  const std::vector<Eigen::Vector3d> points{{-1, 0, 0}, {3, 1, 0}, {0, 2, -1}, {0.5, 0.5, 4}};
  const RenderView view = pcl_ms_tools::viewFramingPoints(points);
  const RenderView again = pcl_ms_tools::viewFramingPoints(points);
  EXPECT_EQ(view.look_at, again.look_at);
  EXPECT_EQ(view.direction, again.direction);
  EXPECT_EQ(view.distance, again.distance);
  EXPECT_NEAR(view.direction.norm(), 1, 1e-12);
  EXPECT_GT(view.distance, 0);
  // Every point is in front of the camera and inside its 30 degree field of
  // view, horizontally and vertically.
  const Eigen::Vector3d camera = view.look_at + view.distance * view.direction;
  const Eigen::Vector3d right = view.up.cross(view.direction).normalized();
  const Eigen::Vector3d camera_up = view.direction.cross(right);
  const double half_field = std::tan(15 * M_PI / 180);
  for (const Eigen::Vector3d &point : points) {
    const Eigen::Vector3d offset = point - camera;
    const double depth = -offset.dot(view.direction);
    ASSERT_GT(depth, 0);
    EXPECT_LT(std::abs(offset.dot(right)) / depth, half_field);
    EXPECT_LT(std::abs(offset.dot(camera_up)) / depth, half_field);
  }
  // Oblique: not along a coordinate axis.
  EXPECT_GT(view.direction.cwiseAbs().minCoeff(), 0.1);

  const RenderView fallback = pcl_ms_tools::viewFramingPoints({});
  EXPECT_GT(fallback.distance, 0);
  EXPECT_TRUE(fallback.look_at.allFinite());
}

// The reference bunny from the default view: recognisable size, and the
// holes in its base are seen (blue boundary loops).
TEST_F(RenderTest, RenderBunnyShowsBaseHoles) {
  Mesh bunny;
  std::string error;
  ASSERT_TRUE(pcl_ms::loadMesh(std::string(PCL_MS_DATA_DIR) + "/bun_zipper.ply", bunny.vertices,
                               bunny.triangles, error))
      << error;
  RenderOptions options;
  options.width = options.height = 400;
  const Picture picture = render(bunny, "bunny.png", options);
  const int covered = picture.count([](const Rgb &c) { return !isWhite(c); });
  EXPECT_GT(covered, 400 * 400 / 3);
  EXPECT_GT(picture.count(isBlue), 200);
  EXPECT_EQ(picture.count(isRed), 0);
}

// Renders one triangle and exits: status 0 with the error on stderr if the
// rendering failed, as the death tests below expect, 1 if it succeeded.
[[noreturn]] void renderOneTriangleAndExit() {
  const Mesh mesh = singleTriangle();
  std::string error;
  const bool rendered = pcl_ms_tools::renderMeshPng(
      mesh.vertices, mesh.triangles, pcl_ms_tools::viewFramingPoints(mesh.vertices), {},
      (fs::temp_directory_path() / "pcl_ms_render_never.png").string(), error);
  std::cerr << error << std::endl;
  std::exit(rendered ? 1 : 0);
}

// Runs in a fresh copy of the test program (threadsafe death test), so the
// display this process may already use does not count.
TEST(RenderDeathTest, RenderWithoutDisplayOrXvfbFailsWithPackageName) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto render_without_xvfb = [] {
    ::unsetenv("DISPLAY");
    ::setenv("PATH", "/nonexistent", 1);
    renderOneTriangleAndExit();
  };
  EXPECT_EXIT(render_without_xvfb(), ::testing::ExitedWithCode(0),
              "DISPLAY is not set, and Xvfb is not installed \\(Debian package xvfb\\)");
}

TEST(RenderDeathTest, RenderWithoutUsableOpenGLFailsInsteadOfCrashing) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto render_with_indirect_gl = [] {
    // Indirect GLX offers OpenGL 1.4 at most, and Xvfb refuses the context.
    ::unsetenv("DISPLAY");
    ::setenv("LIBGL_ALWAYS_INDIRECT", "1", 1);
    renderOneTriangleAndExit();
  };
  EXPECT_EXIT(render_with_indirect_gl(), ::testing::ExitedWithCode(0), "no OpenGL on");
}

} // namespace

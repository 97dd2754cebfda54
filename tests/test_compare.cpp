// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the pcl_ms_compare (suite CompareApp) and pcl_ms_evaluate (suite
// EvaluateApp) programs, run as a user would on the bundled data. Every file
// they write goes to a fresh temporary directory.
#include "program_test.h"

#include <pcl_ms/io.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace pcl_ms_test;

const std::string kDataDir = PCL_MS_DATA_DIR;
const std::string kCompare = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_compare";
const std::string kEvaluate = std::string(PCL_MS_BINARY_DIR) + "/pcl_ms_evaluate";
const std::vector<std::string> kMethods = {"pcl_ms", "gp3", "poisson", "afsr"};

/// One CSV record per line (the tools never put line breaks in fields);
/// quoted fields may hold commas and doubled quotes.
std::vector<std::string> splitCsvLine(const std::string &line) {
  std::vector<std::string> fields(1);
  bool in_quotes = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_quotes && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      fields.back() += '"';
      ++i;
    } else if (c == '"') {
      in_quotes = !in_quotes;
    } else if (c == ',' && !in_quotes) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

/// The rows of results.csv as column name -> value, in file order.
std::vector<std::map<std::string, std::string>> readCsv(const std::string &path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::map<std::string, std::string>> rows;
  if (!std::getline(in, line))
    return rows;
  const std::vector<std::string> header = splitCsvLine(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = splitCsvLine(line);
    EXPECT_EQ(fields.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < fields.size(); ++i)
      row[header[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

double number(const std::map<std::string, std::string> &row, const std::string &column) {
  const auto found = row.find(column);
  EXPECT_NE(found, row.end()) << column;
  if (found == row.end() || found->second.empty())
    return std::nan("");
  return std::strtod(found->second.c_str(), nullptr);
}

class ProgramTest : public TempDirTest {
protected:
  void SetUp() override {
    TempDirTest::SetUp();
    ASSERT_TRUE(fs::exists(kCompare)) << kCompare << " was not built";
    ASSERT_TRUE(fs::exists(kEvaluate)) << kEvaluate << " was not built";
  }

  int run(const std::string &program, const std::string &arguments) {
    return runProgram(program, arguments);
  }

  /// Failure means the given exit code and exactly one line "error: ..." on stderr.
  void expectFailure(const std::string &program, const std::string &arguments, int code,
                     const std::string &reason_part) {
    SCOPED_TRACE(arguments);
    EXPECT_EQ(run(program, arguments), code) << stdout_ << stderr_;
    EXPECT_EQ(stderr_.rfind("error: ", 0), 0u) << stderr_;
    EXPECT_EQ(std::count(stderr_.begin(), stderr_.end(), '\n'), 1) << stderr_;
    EXPECT_TRUE(contains(stderr_, reason_part)) << stderr_;
  }

  /// The program's standard output read as JSON; false if it is not JSON.
  bool readJsonOutput(boost::property_tree::ptree &json) const {
    std::istringstream text(stdout_);
    try {
      boost::property_tree::read_json(text, json);
      return true;
    } catch (const boost::property_tree::json_parser_error &) {
      return false;
    }
  }

  /// Every method's picture and the side-by-side one are PNG files, and no
  /// warning says otherwise. The renderer is required like in the Render*
  /// tests (a private Xvfb stands in for a missing display), so a missing
  /// picture is a broken renderer, not an environment to excuse.
  void expectPictures(const fs::path &out, const std::vector<std::string> &methods) {
    EXPECT_FALSE(contains(stderr_, "not written")) << stderr_;
    std::vector<std::string> pictures;
    for (const std::string &method : methods)
      pictures.push_back((out / (method + ".png")).string());
    pictures.push_back((out / "side_by_side.png").string());
    for (const std::string &picture : pictures)
      EXPECT_EQ(readFile(picture).substr(0, 8), "\x89PNG\r\n\x1a\n") << picture;
  }
};

class CompareApp : public ProgramTest {};
class EvaluateApp : public ProgramTest {};

TEST_F(CompareApp, Bun0WritesTablesMeshesAndProgress) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run(kCompare, quoted(kDataDir + "/bun0.pcd") + " -out " + quoted(out.string())), 0)
      << stdout_ << stderr_;
  // Progress per method and stage.
  EXPECT_TRUE(contains(stdout_, "[1/4] pcl_ms: ")) << stdout_;
  EXPECT_TRUE(contains(stdout_, "[2/4] PCL GP3: normals...")) << stdout_;
  EXPECT_TRUE(contains(stdout_, "[3/4] PCL Poisson: poisson...")) << stdout_;
  EXPECT_TRUE(contains(stdout_, "[4/4] CGAL AFSR: ")) << stdout_;
  expectPictures(out, kMethods);

  const auto rows = readCsv((out / "results.csv").string());
  ASSERT_EQ(rows.size(), kMethods.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto &row = rows[i];
    SCOPED_TRACE(kMethods[i]);
    EXPECT_EQ(row.at("method"), kMethods[i]);
    EXPECT_EQ(row.at("status"), "ok");
    // Without -gt the reference columns are there but empty.
    EXPECT_EQ(row.at("recall"), "");
    EXPECT_GT(number(row, "time_s"), 0);
    EXPECT_GT(number(row, "peak_mb"), 0);
    EXPECT_EQ(number(row, "input_points"), 397);
    EXPECT_EQ(number(row, "invalid_triangles"), 0);

    // The mesh file holds what the table describes.
    std::vector<Eigen::Vector3d> vertices;
    std::vector<pcl_ms::Triangle> triangles;
    std::string error;
    ASSERT_TRUE(
        pcl_ms::loadMesh((out / (kMethods[i] + ".ply")).string(), vertices, triangles, error))
        << error;
    EXPECT_EQ(static_cast<double>(triangles.size()), number(row, "triangles"));
    EXPECT_EQ(static_cast<double>(vertices.size()), number(row, "vertices"));
    if (kMethods[i] != "poisson") { // the interpolating methods mesh the input points
      EXPECT_EQ(vertices.size(), 397u);
      EXPECT_GT(number(row, "input_points_used_fraction"), 0.95);
    } else {
      EXPECT_EQ(number(row, "input_points_used"), 0);
    }
  }
  EXPECT_GT(number(rows[1], "triangles"), 100); // GP3 meshes bun0 (PCL's own test cloud)
  EXPECT_EQ(number(rows[0], "non_manifold_edges"), 0);
  EXPECT_EQ(number(rows[0], "non_manifold_vertices"), 0);

  const std::string md = readFile((out / "results.md").string());
  for (const char *part : {"| | pcl_ms | PCL GP3 | PCL Poisson | CGAL AFSR |", "non-manifold edges",
                           "## Configuration", "search radius", "depth 8"})
    EXPECT_TRUE(contains(md, part)) << part << "\n" << md;
}

TEST_F(CompareApp, BunnyAgainstReference) {
  const fs::path out = dir_ / "bunny";
  const std::string reference = kDataDir + "/bun_zipper.ply";
  ASSERT_EQ(run(kCompare, quoted(kDataDir + "/bunny.pcd") + " -gt " + quoted(reference) + " -out " +
                              quoted(out.string()) + " -q"),
            0)
      << stderr_;
  EXPECT_TRUE(stdout_.empty()) << stdout_;
  expectPictures(out, kMethods);

  const auto rows = readCsv((out / "results.csv").string());
  ASSERT_EQ(rows.size(), 4u);
  for (const auto &row : rows) {
    SCOPED_TRACE(row.at("method"));
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(number(row, "reference_triangles"), 69451);
    // Every method follows the bunny's surface closely (fractions of the diagonal).
    EXPECT_LT(number(row, "to_reference_mean"), 0.001);
    EXPECT_LT(number(row, "from_reference_mean"), 0.001);
    EXPECT_GT(number(row, "fscore_0_5"), 0.95);
  }
  EXPECT_GE(number(rows[0], "recall"), 0.88);
  EXPECT_GE(number(rows[0], "precision"), 0.85);
  EXPECT_EQ(number(rows[0], "non_manifold_edges"), 0);
  EXPECT_GE(number(rows[3], "recall"), 0.85); // AFSR interpolates too
  EXPECT_GT(number(rows[1], "triangles"), 50000);
  EXPECT_EQ(number(rows[2], "recall"), 0); // Poisson's vertices are new points
  EXPECT_EQ(number(rows[2], "precision"), 0);

  // pcl_ms_evaluate on the written mesh reports the same numbers.
  ASSERT_EQ(run(kEvaluate, quoted((out / "pcl_ms.ply").string()) + " -gt " + quoted(reference) +
                               " -points " + quoted(kDataDir + "/bunny.pcd") + " -json"),
            0)
      << stderr_;
  boost::property_tree::ptree json;
  ASSERT_TRUE(readJsonOutput(json)) << stdout_;
  for (const char *key : {"recall", "precision", "to_reference_max", "fscore_0_1"})
    EXPECT_EQ(json.get<std::string>(std::string("reference.") + key), rows[0].at(key)) << key;
  EXPECT_EQ(json.get<std::string>("topology.boundary_loops"), rows[0].at("boundary_loops"));
  EXPECT_EQ(json.get<std::string>("points.input_points_used"), rows[0].at("input_points_used"));
}

TEST_F(CompareApp, SameInputGivesSameMeshesAndNumbers) {
  const std::string input = quoted(kDataDir + "/bun0.pcd");
  ASSERT_EQ(run(kCompare, input + " -q -methods afsr,ours,gp3 -out " + quoted(path("a"))), 0)
      << stderr_;
  ASSERT_EQ(run(kCompare, input + " -q -methods afsr,ours,gp3 -out " + quoted(path("b"))), 0)
      << stderr_;
  for (const char *method : {"afsr", "pcl_ms", "gp3"}) {
    const std::string a = readFile(path("a/") + method + ".ply");
    EXPECT_FALSE(a.empty()) << method;
    EXPECT_EQ(a, readFile(path("b/") + method + ".ply")) << method;
  }
  EXPECT_FALSE(fs::exists(path("a/poisson.ply")));
  const auto first = readCsv(path("a/results.csv")), second = readCsv(path("b/results.csv"));
  ASSERT_EQ(first.size(), 3u);
  ASSERT_EQ(second.size(), 3u);
  EXPECT_EQ(first[0].at("method"), "afsr"); // in the order asked for
  EXPECT_EQ(first[1].at("method"), "pcl_ms");
  for (std::size_t i = 0; i < first.size(); ++i)
    for (const auto &[column, value] : first[i]) {
      if (column == "time_s" || column == "stage_times" || column.find("_mb") != std::string::npos)
        continue;
      EXPECT_EQ(value, second[i].at(column)) << first[i].at("method") << " " << column;
    }
}

TEST_F(CompareApp, NoMethodSucceedsStillWritesTables) {
  // One position repeated: nothing can be meshed.
  std::string same;
  for (int i = 0; i < 20; ++i)
    same += "1 2 3\n";
  writeFile(path("same.xyz"), same);
  EXPECT_EQ(run(kCompare, quoted(path("same.xyz")) + " -q -out " + quoted(path("out"))), 3);
  EXPECT_TRUE(contains(stderr_, "error: no method produced a mesh")) << stderr_;
  const auto rows = readCsv(path("out/results.csv"));
  ASSERT_EQ(rows.size(), 4u);
  for (const auto &row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_FALSE(row.at("error").empty());
    EXPECT_EQ(row.at("triangles"), "");
  }
  EXPECT_TRUE(fs::exists(path("out/results.md")));
}

TEST_F(CompareApp, HelpExitsCleanly) {
  EXPECT_EQ(run(kCompare, "-h"), 0);
  EXPECT_TRUE(contains(stdout_, "-methods")) << stdout_;
  EXPECT_TRUE(stderr_.empty()) << stderr_;
}

TEST_F(CompareApp, BadArgumentsFail) {
  const std::string input = quoted(kDataDir + "/bun0.pcd");
  const std::string out = " -out " + quoted(path("o"));
  expectFailure(kCompare, out, 1, "one input file");
  expectFailure(kCompare, input + " " + input + out, 1, "one input file");
  expectFailure(kCompare, input + " -colour" + out, 1, "-colour");
  expectFailure(kCompare, input + " -methods gp3,marching_cubes" + out, 1, "marching_cubes");
  expectFailure(kCompare, input + " -methods gp3,GP3" + out, 1, "twice");
  expectFailure(kCompare, input + " -methods ," + out, 1, "-methods");
  expectFailure(kCompare, input + out + " -gt", 1, "-gt needs a value");
  EXPECT_FALSE(fs::exists(path("o")));
}

TEST_F(CompareApp, UnreadableFilesFail) {
  const std::string input = quoted(kDataDir + "/bun0.pcd");
  expectFailure(kCompare, quoted(path("missing.pcd")) + " -out " + quoted(path("o")), 2,
                "missing.pcd");
  writeFile(path("garbage.ply"), "ply\nformat nonsense\n\x01\x02");
  expectFailure(kCompare, quoted(path("garbage.ply")) + " -out " + quoted(path("o")), 2,
                "garbage.ply");
  expectFailure(kCompare,
                input + " -gt " + quoted(path("garbage.ply")) + " -out " + quoted(path("o")), 2,
                "garbage.ply");
  writeFile(path("a_file"), "not a directory");
  expectFailure(kCompare, input + " -out " + quoted(path("a_file")), 2, "a_file");
  EXPECT_FALSE(fs::exists(path("o")));
}

TEST_F(EvaluateApp, ReferenceMeshAsJson) {
  const std::string reference = kDataDir + "/bun_zipper.ply";
  ASSERT_EQ(run(kEvaluate, quoted(reference) + " -gt " + quoted(reference) + " -points " +
                               quoted(kDataDir + "/bunny.pcd") + " -json"),
            0)
      << stderr_;
  EXPECT_TRUE(stderr_.empty()) << stderr_;
  boost::property_tree::ptree json;
  ASSERT_TRUE(readJsonOutput(json)) << stdout_;
  // Known facts of bun_zipper.ply (data/README.md).
  EXPECT_EQ(json.get<int>("topology.triangles"), 69451);
  EXPECT_EQ(json.get<int>("topology.vertices"), 35947);
  EXPECT_EQ(json.get<int>("topology.boundary_loops"), 5);
  EXPECT_EQ(json.get<int>("topology.non_manifold_edges"), 0);
  EXPECT_EQ(json.get<std::string>("topology.orientable"), "true");
  EXPECT_EQ(json.get_child("topology.boundary_loop_lengths").size(), 5u);
  // Against itself: everything recovered, no distance.
  EXPECT_EQ(json.get<double>("reference.recall"), 1.0);
  EXPECT_EQ(json.get<double>("reference.precision"), 1.0);
  EXPECT_EQ(json.get<double>("reference.hausdorff"), 0.0);
  // 1,113 of its vertices are used by no triangle.
  EXPECT_EQ(json.get<int>("points.input_points"), 35947);
  EXPECT_EQ(json.get<int>("points.input_points_used"), 35947 - 1113);
}

TEST_F(EvaluateApp, TableForPeople) {
  ASSERT_EQ(run(kEvaluate, quoted(kDataDir + "/bun_zipper.ply")), 0) << stderr_;
  EXPECT_TRUE(stderr_.empty()) << stderr_;
  for (const char *part : {"69,451 triangles", "boundary loops", "non-manifold edges",
                           "boundary loop lengths (edges)"})
    EXPECT_TRUE(contains(stdout_, part)) << part << "\n" << stdout_;
  EXPECT_FALSE(contains(stdout_, "recall")) << stdout_; // no -gt, no reference rows
}

TEST_F(EvaluateApp, ClosedMeshInOffAndObj) {
  // A tetrahedron: closed, orientable, Euler characteristic 2.
  writeFile(path("tet.off"), "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                             "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  writeFile(path("tet.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                             "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  for (const char *name : {"tet.off", "tet.obj"}) {
    SCOPED_TRACE(name);
    ASSERT_EQ(run(kEvaluate, quoted(path(name)) + " -json"), 0) << stderr_;
    boost::property_tree::ptree json;
    ASSERT_TRUE(readJsonOutput(json)) << stdout_;
    EXPECT_EQ(json.get<int>("topology.triangles"), 4);
    EXPECT_EQ(json.get<int>("topology.boundary_edges"), 0);
    EXPECT_EQ(json.get<int>("topology.euler_characteristic"), 2);
    EXPECT_EQ(json.get<int>("topology.inconsistently_oriented_edges"), 0);
    EXPECT_FALSE(json.get_child_optional("reference"));
  }
}

TEST_F(EvaluateApp, TextReferenceMatchesTheFloatPointsOfAMesh) {
  // The same tetrahedron twice: as doubles in an OFF file (0.1 is no
  // float) and as the floats of a PLY file, like the points that PCL reads
  // and pcl_ms meshes. Vertices are matched at single precision.
  const std::string corners = "0.1 0.2 0.3\n1.1 0.2 0.3\n0.1 1.3 0.3\n0.1 0.2 1.7\n";
  writeFile(path("tet.off"), "OFF\n4 4 0\n" + corners + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  writeFile(path("tet.ply"), "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 4\n"
                             "property list uchar int vertex_indices\nend_header\n" +
                                 corners + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  for (const auto &[mesh, other] :
       {std::pair<const char *, const char *>{"tet.ply", "tet.off"}, {"tet.off", "tet.ply"}}) {
    SCOPED_TRACE(mesh);
    ASSERT_EQ(run(kEvaluate, quoted(path(mesh)) + " -gt " + quoted(path(other)) + " -points " +
                                 quoted(path(other)) + " -json"),
              0)
        << stderr_;
    boost::property_tree::ptree json;
    ASSERT_TRUE(readJsonOutput(json)) << stdout_;
    EXPECT_EQ(json.get<double>("reference.recall"), 1.0);
    EXPECT_EQ(json.get<double>("reference.precision"), 1.0);
    EXPECT_EQ(json.get<int>("points.input_points_used"), 4);
  }
}

TEST_F(EvaluateApp, BadInputFails) {
  const std::string mesh = quoted(kDataDir + "/bun_zipper.ply");
  expectFailure(kEvaluate, "", 1, "one mesh file");
  expectFailure(kEvaluate, mesh + " " + mesh, 1, "one mesh file");
  expectFailure(kEvaluate, mesh + " -xml", 1, "-xml");
  expectFailure(kEvaluate, mesh + " -points", 1, "-points needs a value");
  expectFailure(kEvaluate, quoted(path("missing.ply")), 2, "missing.ply");
  writeFile(path("garbage.off"), "OFF\n3 1 0\n0 0 0\n1 0\n");
  expectFailure(kEvaluate, quoted(path("garbage.off")), 2, "garbage.off");
  writeFile(path("mesh.stl"), "solid nothing\nendsolid\n");
  expectFailure(kEvaluate, quoted(path("mesh.stl")), 2, "mesh.stl");
  expectFailure(kEvaluate, mesh + " -gt " + quoted(path("missing.obj")), 2, "missing.obj");
  expectFailure(kEvaluate, mesh + " -points " + quoted(path("missing.pcd")), 2, "missing.pcd");
}

} // namespace

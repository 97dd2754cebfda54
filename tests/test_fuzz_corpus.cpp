// SPDX-License-Identifier: GPL-3.0-or-later
// Replays the fuzz corpus (tests/fuzz/corpus: seeds, and every finding once
// fixed) in the ordinary test run, so that a fixed finding stays fixed in
// every build, including the sanitizer build, where CGAL's assertions are on.
#include "program_test.h"

#include <pcl_ms/io.h>

// The reconstruct and metrics targets' bodies and their promises, checked as
// they are while fuzzing (a broken promise aborts), without the entry point
// libFuzzer calls.
#define PCL_MS_FUZZ_REPLAY
#include "fuzz/binary_layout_fuzzer.cpp"
#include "fuzz/mesh_quality_fuzzer.cpp"
#include "fuzz/reconstruct_fuzzer.cpp"
#include "fuzz/reconstruct_inputs_fuzzer.cpp"
#include "fuzz/shared_reconstruct_fuzzer.cpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>

namespace {

using namespace pcl_ms_test;
namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(PCL_MS_DATA_DIR) / ".." / "tests" / "fuzz" / "corpus";

std::vector<fs::path> corpusFiles(const std::string &target) {
  std::vector<fs::path> files;
  for (const auto &entry : fs::directory_iterator(kCorpus / target))
    if (entry.is_regular_file())
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

/// Runs a target's body on every file of its corpus.
void replayCorpus(const std::string &target, int (*run)(const std::uint8_t *, std::size_t)) {
  const std::vector<fs::path> files = corpusFiles(target);
  ASSERT_FALSE(files.empty());
  for (const fs::path &file : files) {
    SCOPED_TRACE(file.filename().string());
    const std::string bytes = readFile(file.string());
    EXPECT_NO_THROW(run(reinterpret_cast<const std::uint8_t *>(bytes.data()), bytes.size()));
  }
}

TEST(FuzzCorpus, ReconstructRunsEveryInputToAMeshOrAnError) {
  replayCorpus("reconstruct", &pcl_ms_fuzz::reconstructOneInput);
}

TEST(FuzzCorpus, ReconstructWithEveryOptionalInputRunsToAMeshOrAnError) {
  replayCorpus("reconstruct_inputs", &pcl_ms_fuzz::reconstructInputsOneInput);
}

TEST(FuzzCorpus, ProcessesSharingACloudGiveOneProcessMeshOrError) {
  replayCorpus("shared_reconstruct", &pcl_ms_fuzz::sharedReconstructOneInput);
}

TEST(FuzzCorpus, MeshMetricsAreConsistentOnEveryPairOfMeshes) {
  replayCorpus("mesh_quality", &pcl_ms_fuzz::meshQualityOneInput);
}

TEST(FuzzCorpus, BinaryCloudsReadInPartsAreTheOrdinaryReadersPoints) {
  replayCorpus("binary_layout", &pcl_ms_fuzz::binaryLayoutOneInput);
}

class FuzzCorpusReaders : public TempDirTest {};

TEST_F(FuzzCorpusReaders, EveryReaderLoadsOrRejectsEveryInput) {
  // Target directory -> extension and reader, as in tests/fuzz/CMakeLists.txt.
  const std::map<std::string, std::pair<std::string, bool>> readers = {
      {"pcd", {".pcd", false}},     {"ply_cloud", {".ply", false}}, {"xyz", {".xyz", false}},
      {"mesh_ply", {".ply", true}}, {"mesh_obj", {".obj", true}},   {"mesh_off", {".off", true}},
      {"mesh_vtk", {".vtk", true}}, {"mesh_stl", {".stl", true}}};
  for (const auto &[target, reader] : readers) {
    const auto &[extension, is_mesh] = reader;
    const std::vector<fs::path> files = corpusFiles(target);
    EXPECT_FALSE(files.empty()) << target;
    for (const fs::path &file : files) {
      SCOPED_TRACE(target + "/" + file.filename().string());
      const std::string copy = path("input" + extension);
      writeFile(copy, readFile(file.string()));
      std::string error;
      bool loaded = false;
      if (is_mesh) {
        std::vector<Eigen::Vector3d> vertices;
        std::vector<pcl_ms::Triangle> triangles;
        loaded = pcl_ms::loadMesh(copy, vertices, triangles, error);
        if (loaded) {
          for (const pcl_ms::Triangle &triangle : triangles)
            for (pcl_ms::VertexIndex v : triangle)
              ASSERT_LT(v, vertices.size());
        }
      } else {
        pcl::PCLPointCloud2 cloud;
        loaded = pcl_ms::loadPointCloud(copy, cloud, error);
        if (loaded) {
          EXPECT_EQ(cloud.data.size(), std::size_t{cloud.row_step} * cloud.height);
        }
      }
      // Seeds are valid files; findings (named finding_*) are whatever the
      // fuzzer made of them: those must be rejected with a reason or loaded.
      if (file.filename().string().rfind("finding_", 0) != 0) {
        EXPECT_TRUE(loaded) << error;
      } else if (!loaded) {
        EXPECT_FALSE(error.empty());
      }
    }
  }
}

} // namespace

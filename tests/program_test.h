// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for tests that write files or run the built programs: a fresh
// temporary directory per test, file bytes in and out, and one way to run
// a program and keep what it printed.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace pcl_ms_test {

namespace fs = std::filesystem;

inline std::string readFile(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

inline void writeFile(const std::string &path, const std::string &bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

inline bool contains(const std::string &text, const std::string &part) {
  return text.find(part) != std::string::npos;
}

inline std::string quoted(const std::string &path) { return "'" + path + "'"; }

/// Each test gets its own directory under the system temp dir, removed afterwards.
class TempDirTest : public ::testing::Test {
protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    const ::testing::TestInfo *info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("pcl_ms_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
            std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir_);
    ASSERT_TRUE(fs::create_directories(dir_));
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::string path(const std::string &name) const { return (dir_ / name).string(); }

  /// Runs `program` with `arguments` (already quoted as needed); returns its
  /// exit code and keeps what it printed in stdout_ and stderr_.
  int runProgram(const std::string &program, const std::string &arguments) {
    const std::string command = quoted(program) + " " + arguments + " > " +
                                quoted(path("stdout.txt")) + " 2> " + quoted(path("stderr.txt"));
    const int status = std::system(command.c_str());
    stdout_ = readFile(path("stdout.txt"));
    stderr_ = readFile(path("stderr.txt"));
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  fs::path dir_;
  std::string stdout_, stderr_;
};

} // namespace pcl_ms_test

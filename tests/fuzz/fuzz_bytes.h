// SPDX-License-Identifier: GPL-3.0-or-later
// The fuzz targets' reader of the fuzzer's bytes, the bytes as a file for
// readers that take a path, how a target reports a broken promise (it
// aborts, which libFuzzer records as a finding), and its entry point.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace pcl_ms_fuzz {

/// Reads the fuzzer's bytes front to back; zeros once they run out.
class ByteReader {
public:
  ByteReader(const std::uint8_t *data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return position_ < size_ ? data_[position_++] : 0; }
  float rawFloat() {
    std::uint8_t bytes[4] = {byte(), byte(), byte(), byte()};
    float value;
    std::memcpy(&value, bytes, sizeof value);
    return value;
  }
  /// In [-1, 1] in steps of 1/127.
  float unit() { return (static_cast<int>(byte()) - 128) / 127.0f; }
  /// Two bytes, little-endian.
  std::uint32_t word() { return byte() | static_cast<std::uint32_t>(byte()) << 8; }
  /// The bytes not read yet, all of them.
  std::vector<std::uint8_t> rest() {
    std::vector<std::uint8_t> left(data_ + std::min(position_, size_), data_ + size_);
    position_ = size_;
    return left;
  }
  bool empty() const { return position_ >= size_; }

private:
  const std::uint8_t *data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

/// The bytes written to a file of this process (fuzzers may run side by
/// side) with the given extension, removed with the input so that runs and
/// replays leave nothing behind.
class ScratchFile {
public:
  ScratchFile(const std::string &extension, const std::uint8_t *data, std::size_t size)
      : path_("/tmp/pcl_ms_fuzz_" + std::to_string(::getpid()) + extension) {
    std::ofstream file(path_, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char *>(data), static_cast<std::streamsize>(size));
  }
  ScratchFile(const ScratchFile &) = delete;
  ScratchFile &operator=(const ScratchFile &) = delete;
  ~ScratchFile() { std::remove(path_.c_str()); }
  const std::string &path() const { return path_; }

private:
  std::string path_;
};

[[noreturn]] inline void broken(const char *promise) {
  std::fprintf(stderr, "broken promise: %s\n", promise);
  std::abort();
}

} // namespace pcl_ms_fuzz

// Each target's body is a named function, so that the tests can replay
// every corpus in one program: there (PCL_MS_FUZZ_REPLAY) the entry point
// that libFuzzer calls, one name for all targets, is left out.
#ifdef PCL_MS_FUZZ_REPLAY
#define PCL_MS_FUZZ_TARGET(body)
#else
#define PCL_MS_FUZZ_TARGET(body)                                                                   \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {              \
    return body(data, size);                                                                       \
  }
#endif

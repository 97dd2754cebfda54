// SPDX-License-Identifier: GPL-3.0-or-later
// The fuzz targets' reader of the fuzzer's bytes, how a target reports a
// broken promise (it aborts, which libFuzzer records as a finding), and its
// entry point.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

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

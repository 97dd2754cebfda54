// SPDX-License-Identifier: GPL-3.0-or-later
// Plain data between the processes of a ProcessGroup (docs/algorithm.md,
// "Across processes"): values travel as their bytes, and the counts and
// sums the processes agree on. Internal to the library: not installed.
#pragma once

#include <pcl_ms/process_group.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace pcl_ms {
namespace detail {

template <typename Value> std::vector<unsigned char> bytesOf(const Value *values, std::size_t n) {
  static_assert(std::is_trivially_copyable_v<Value>);
  std::vector<unsigned char> bytes(n * sizeof(Value));
  if (n > 0)
    std::memcpy(bytes.data(), values, bytes.size());
  return bytes;
}

template <typename Value> std::vector<unsigned char> bytesOf(const std::vector<Value> &values) {
  return bytesOf(values.data(), values.size());
}

template <typename Value> std::vector<Value> valuesOf(const std::vector<unsigned char> &bytes) {
  static_assert(std::is_trivially_copyable_v<Value>);
  std::vector<Value> values(bytes.size() / sizeof(Value));
  if (!values.empty())
    std::memcpy(values.data(), bytes.data(), values.size() * sizeof(Value));
  return values;
}

/// Each process's count, in process order, on every process.
inline std::vector<std::uint64_t> countsOf(std::uint64_t mine, ProcessGroup &group) {
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(group.processes()), 0);
  counts[static_cast<std::size_t>(group.process())] = mine;
  group.sum(counts);
  return counts;
}

inline std::uint64_t totalOver(std::uint64_t mine, ProcessGroup &group) {
  std::vector<std::uint64_t> total{mine};
  group.sum(total);
  return total[0];
}

inline std::uint64_t maximumOver(std::uint64_t mine, ProcessGroup &group) {
  std::vector<double> largest{static_cast<double>(mine)};
  group.maximum(largest);
  return static_cast<std::uint64_t>(largest[0]);
}

/// Where each run starts, then the list's length, from the runs' counts
/// (countsOf): runFirsts() for runs known to follow each other.
inline std::vector<std::uint64_t> firstsOf(const std::vector<std::uint64_t> &counts) {
  std::vector<std::uint64_t> firsts(counts.size() + 1, 0);
  for (std::size_t p = 0; p < counts.size(); ++p)
    firsts[p + 1] = firsts[p] + counts[p];
  return firsts;
}

/// Where each process's run of a list held in parts starts (this process's
/// run: `count` items from number `first` on), on every process, then the
/// whole list's length. Checked on the gathered figures, so that every
/// process throws alike (std::invalid_argument, naming `what`) when the runs
/// do not follow each other from item 0 in process order.
inline std::vector<std::uint64_t> runFirsts(std::uint64_t count, std::uint64_t first,
                                            ProcessGroup &group, const std::string &what) {
  const std::vector<std::uint64_t> firsts = firstsOf(countsOf(count, group));
  const std::vector<unsigned char> gathered = group.gatherAll(bytesOf(&first, 1));
  if (std::memcmp(gathered.data(), firsts.data(), gathered.size()) != 0)
    throw std::invalid_argument(what + ": the processes' runs do not follow each other from 0");
  return firsts;
}

/// The process whose run (from runFirsts) holds item `item`, below the
/// list's length: the last run starting at or before it, as runs before it
/// may be empty.
inline std::size_t runHolding(const std::vector<std::uint64_t> &firsts, std::uint64_t item) {
  return static_cast<std::size_t>(std::upper_bound(firsts.begin(), firsts.end(), item) -
                                  firsts.begin() - 1);
}

/// Sends outgoing[p] to process p (and empties it); calls take(value) for
/// every value sent here, in process order. The values are read straight
/// from the bytes received: no second copy of them is held.
template <typename Value, typename Take>
void deliver(std::vector<std::vector<Value>> &outgoing, ProcessGroup &group, const Take &take) {
  std::vector<std::vector<unsigned char>> bytes(outgoing.size());
  for (std::size_t p = 0; p < outgoing.size(); ++p) {
    bytes[p] = bytesOf(outgoing[p]);
    std::vector<Value>().swap(outgoing[p]);
  }
  const std::vector<unsigned char> received = group.exchange(bytes);
  bytes.clear();
  for (std::size_t at = 0; at + sizeof(Value) <= received.size(); at += sizeof(Value)) {
    Value value;
    std::memcpy(&value, received.data() + at, sizeof value);
    take(value);
  }
}

/// Every process gets process 0's `values` (the others' are replaced).
template <typename Value> void fromZeroToAll(std::vector<Value> &values, ProcessGroup &group) {
  std::vector<std::vector<Value>> outgoing(static_cast<std::size_t>(group.processes()));
  for (std::size_t p = 1; p < outgoing.size() && group.process() == 0; ++p)
    outgoing[p] = values;
  std::vector<Value> received;
  deliver(outgoing, group, [&](const Value &value) { received.push_back(value); });
  if (group.process() != 0)
    values = std::move(received);
}

/// Process 0 gets every process's `count` values (make(i) gives value i):
/// take(position, value) with the value's position in the processes'
/// order. Sent in rounds of at most a million values a process, so that
/// neither side holds all the bytes at once.
template <typename Value, typename Make, typename Take>
void gatherAtZero(std::size_t count, const Make &make, const Take &take, ProcessGroup &group) {
  constexpr std::size_t chunk = std::size_t{1} << 20;
  const std::vector<std::uint64_t> counts = countsOf(count, group);
  const std::vector<std::uint64_t> firsts = firstsOf(counts);
  std::uint64_t rounds = 0;
  for (std::uint64_t of_one : counts)
    rounds = std::max<std::uint64_t>(rounds, (of_one + chunk - 1) / chunk);
  for (std::uint64_t round = 0; round < rounds; ++round) {
    std::vector<std::vector<unsigned char>> outgoing(counts.size());
    const std::size_t begin = std::min<std::size_t>(count, round * chunk);
    const std::size_t end = std::min<std::size_t>(count, begin + chunk);
    outgoing[0].resize((end - begin) * sizeof(Value));
    for (std::size_t i = begin; i < end; ++i) {
      const Value value = make(i);
      std::memcpy(outgoing[0].data() + (i - begin) * sizeof(Value), &value, sizeof value);
    }
    const std::vector<unsigned char> received = group.exchange(outgoing);
    std::size_t at = 0;
    for (std::size_t p = 0; p < counts.size() && group.process() == 0; ++p) {
      const std::uint64_t from = std::min<std::uint64_t>(counts[p], round * chunk);
      const std::uint64_t to = std::min<std::uint64_t>(counts[p], from + chunk);
      for (std::uint64_t i = from; i < to; ++i, at += sizeof(Value)) {
        Value value;
        std::memcpy(&value, received.data() + at, sizeof value);
        take(static_cast<std::size_t>(firsts[p] + i), value);
      }
    }
  }
}

} // namespace detail
} // namespace pcl_ms

// SPDX-License-Identifier: GPL-3.0-or-later
// The greedy's priority queue (docs/algorithm.md section 3). In: (cost,
// candidate) entries, pushed again when a cost changes. Out: the entries
// cheapest first, ties by candidate index; the caller skips outdated ones.
// Internal to the library: not installed.
#pragma once

#include <pcl_ms/scaffold.h> // CandidateIndex

#include <boost/sort/spreadsort/integer_sort.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <vector>

namespace pcl_ms {
namespace detail {

/// A queued cost and its candidate packed into one integer that orders them
/// cheapest first, ties by candidate index: the cost's bits form the high
/// word, and costs are never negative (freshCost clamps at +0, NaN included),
/// so their IEEE bit patterns sort like the values. One integer comparison
/// per heap step instead of two float tests and a tie-break.
class QueueEntry {
public:
  QueueEntry() = default; // for the sort's buffers
  QueueEntry(float cost, CandidateIndex candidate)
      : key_(std::uint64_t{bitsOf(cost)} << 32 | candidate) {}
  float cost() const {
    const auto bits = static_cast<std::uint32_t>(key_ >> 32);
    float cost;
    std::memcpy(&cost, &bits, sizeof cost);
    return cost;
  }
  CandidateIndex candidate() const { return static_cast<CandidateIndex>(key_); }
  std::uint64_t key() const { return key_; }
  bool operator<(const QueueEntry &other) const { return key_ < other.key_; }

private:
  static std::uint32_t bitsOf(float cost) {
    std::uint32_t bits;
    std::memcpy(&bits, &cost, sizeof bits);
    return bits;
  }

  std::uint64_t key_ = 0;
};

/// A 4-ary min-heap of queue entries. Boost's d-ary heap finds a node's
/// cheapest child with a branch per child, which the unordered costs
/// mispredict about half the time: that search was two thirds of the pass
/// loop's own time on PCL's scans. Here the child is chosen by comparisons
/// that compile to conditional moves, and a pop takes the hole down to a
/// leaf before placing the last entry, which belongs near the bottom
/// (bench/README.md, "The heap without branches").
class EntryHeap {
public:
  bool empty() const { return entries_.empty(); }
  std::size_t size() const { return entries_.size(); }
  const QueueEntry &top() const { return entries_.front(); }
  std::vector<QueueEntry>::const_iterator begin() const { return entries_.begin(); }
  std::vector<QueueEntry>::const_iterator end() const { return entries_.end(); }
  void clear() { entries_.clear(); }
  void reserve(std::size_t count) { entries_.reserve(count); }

  void push(const QueueEntry &entry) {
    entries_.push_back(entry);
    placeFrom(entries_.size() - 1, entry);
  }

  void pop() {
    const QueueEntry last = entries_.back();
    entries_.pop_back();
    const std::size_t count = entries_.size();
    if (count == 0)
      return;
    std::size_t hole = 0;
    for (;;) {
      const std::size_t first = 4 * hole + 1;
      std::size_t child;
      if (first + 3 < count) {
        const QueueEntry *children = &entries_[first];
        const std::size_t low = children[1] < children[0] ? 1 : 0;
        const std::size_t high = children[3] < children[2] ? 3 : 2;
        child = first + (children[high] < children[low] ? high : low);
      } else if (first < count) {
        child = first;
        for (std::size_t other = first + 1; other < count; ++other)
          if (entries_[other] < entries_[child])
            child = other;
      } else {
        break;
      }
      entries_[hole] = entries_[child];
      hole = child;
    }
    placeFrom(hole, last);
  }

private:
  /// Puts `entry` into the hole at `hole`, or above it while its parent
  /// costs more.
  void placeFrom(std::size_t hole, const QueueEntry &entry) {
    while (hole > 0) {
      const std::size_t parent = (hole - 1) / 4;
      if (!(entry < entries_[parent]))
        break;
      entries_[hole] = entries_[parent];
      hole = parent;
    }
    entries_[hole] = entry;
  }

  std::vector<QueueEntry> entries_;
};

/// The queue of one pass. Most entries arrive together before the pass
/// pops any (the pass's initial costs): those are sorted once and read in
/// order, which costs far less than sifting each through a heap of millions
/// of entries, the greedy's main cost at 300,000 points. Entries pushed
/// while the pass runs (changed costs) go to a small heap, except delayed
/// candidates: their costs rise with the pass, so most of them extend a
/// second sorted run (bench/README.md, "Delayed candidates in a run of
/// their own"). The heap has no handles: a candidate whose cost changes is
/// pushed again and its outdated entry skipped when it surfaces (lazy
/// deletion). Entries are totally ordered, so the pops come in the same
/// order as from one heap.
class CandidateQueue {
public:
  void push(const QueueEntry &entry) { arrived_.push_back(entry); }
  /// push() of an entry likely to be no cheaper than the one pushed this way
  /// before it: appended to the delayed run when it keeps the run sorted.
  void pushDelayed(const QueueEntry &entry) {
    if (delayed_next_ == delayed_.size() || !(entry < delayed_.back()))
      delayed_.push_back(entry);
    else
      arrived_.push_back(entry);
  }
  bool empty() const { return size() == 0; }
  const QueueEntry &top() {
    settleArrivals();
    switch (cheapestSource()) {
    case Source::sorted:
      return sorted_[next_];
    case Source::delayed:
      return delayed_[delayed_next_];
    default:
      return heap_.top();
    }
  }
  void pop() {
    settleArrivals();
    switch (cheapestSource()) {
    case Source::sorted:
      ++next_;
      break;
    case Source::delayed:
      popDelayed();
      break;
    default:
      heap_.pop();
    }
  }
  std::size_t size() const {
    return sorted_.size() - next_ + delayed_.size() - delayed_next_ + heap_.size() +
           arrived_.size();
  }
  /// The candidate `steps` places further along the sorted run, if any: the
  /// pass fetches its data early, as the run visits candidates in no order
  /// of memory.
  const QueueEntry *sortedAhead(std::size_t steps) const {
    return next_ + steps < sorted_.size() ? &sorted_[next_ + steps] : nullptr;
  }

  /// The cheapest entry pushed while the pass runs, if any, arrivals not
  /// counted: the pass fetches its data while deciding the current
  /// candidate, as it may well be the next one popped.
  const QueueEntry *pushedTop() const {
    const QueueEntry *delayed =
        delayed_next_ < delayed_.size() ? &delayed_[delayed_next_] : nullptr;
    if (heap_.empty())
      return delayed;
    return delayed && *delayed < heap_.top() ? delayed : &heap_.top();
  }

  /// Drops the outdated entries.
  template <typename IsCurrent> void compact(const IsCurrent &is_current) {
    settleArrivals();
    std::vector<QueueEntry> current;
    std::copy_if(sorted_.begin() + static_cast<std::ptrdiff_t>(next_), sorted_.end(),
                 std::back_inserter(current), is_current);
    sorted_ = std::move(current);
    next_ = 0;
    current.clear();
    std::copy_if(delayed_.begin() + static_cast<std::ptrdiff_t>(delayed_next_), delayed_.end(),
                 std::back_inserter(current), is_current);
    delayed_ = std::move(current);
    delayed_next_ = 0;
    std::vector<QueueEntry> in_heap;
    for (auto it = heap_.begin(); it != heap_.end(); ++it)
      if (is_current(*it))
        in_heap.push_back(*it);
    heap_.clear();
    heap_.reserve(in_heap.size());
    for (const QueueEntry &entry : in_heap)
      heap_.push(entry);
  }

private:
  // A batch at least this large is sorted and merged into the sorted run
  // rather than pushed onto the heap one by one.
  static constexpr std::size_t min_sorted_batch = 1024;

  // Once this many entries of the delayed run are read, and they are at
  // least half of it, they are dropped from its front.
  static constexpr std::size_t min_delayed_read = 4096;

  enum class Source { sorted, delayed, heap };

  /// Where the cheapest entry is; the sorted run wins ties (equal keys are
  /// the same entry).
  Source cheapestSource() const {
    const QueueEntry *pushed = pushedTop();
    if (next_ < sorted_.size() && (!pushed || !(*pushed < sorted_[next_])))
      return Source::sorted;
    return !heap_.empty() && pushed == &heap_.top() ? Source::heap : Source::delayed;
  }

  void popDelayed() {
    ++delayed_next_;
    if (delayed_next_ == delayed_.size()) {
      delayed_.clear();
      delayed_next_ = 0;
    } else if (delayed_next_ >= min_delayed_read && 2 * delayed_next_ >= delayed_.size()) {
      delayed_.erase(delayed_.begin(),
                     delayed_.begin() + static_cast<std::ptrdiff_t>(delayed_next_));
      delayed_next_ = 0;
    }
  }

  void settleArrivals() {
    if (arrived_.empty())
      return;
    if (arrived_.size() < min_sorted_batch) {
      for (const QueueEntry &entry : arrived_)
        heap_.push(entry);
    } else {
      // The keys are integers: Boost's radix sort sorts them faster than
      // std::sort (bench/README.md, "The greedy's rings and queue").
      boost::sort::spreadsort::integer_sort(
          arrived_.begin(), arrived_.end(),
          [](const QueueEntry &entry, unsigned shift) { return entry.key() >> shift; },
          [](const QueueEntry &a, const QueueEntry &b) { return a < b; });
      if (next_ == sorted_.size()) { // nothing left to merge with: no copy
        sorted_.swap(arrived_);
        next_ = 0;
        arrived_.clear();
        return;
      }
      std::vector<QueueEntry> merged;
      merged.reserve(sorted_.size() - next_ + arrived_.size());
      std::merge(sorted_.begin() + static_cast<std::ptrdiff_t>(next_), sorted_.end(),
                 arrived_.begin(), arrived_.end(), std::back_inserter(merged));
      sorted_ = std::move(merged);
      next_ = 0;
    }
    arrived_.clear();
  }

  std::vector<QueueEntry> arrived_; // pushed, not yet placed
  std::vector<QueueEntry> sorted_;  // ascending from next_
  std::size_t next_ = 0;
  std::vector<QueueEntry> delayed_; // ascending from delayed_next_
  std::size_t delayed_next_ = 0;
  EntryHeap heap_;
};

} // namespace detail
} // namespace pcl_ms

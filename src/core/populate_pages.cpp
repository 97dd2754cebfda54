// SPDX-License-Identifier: GPL-3.0-or-later
// Pages faulted in ahead of a full write (populate_pages.h).
#include "populate_pages.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace pcl_ms {
namespace detail {

#if defined(__linux__)

namespace {
// Linux's value, which older headers lack.
constexpr int populate_write_advice = 23;

// Huge pages pay where a first write to a fresh 4 kB page costs more than
// this: about 15 µs on the machines where they made the triangulation
// faster, about 1 µs on one where they made it slower (bench/README.md, "The
// triangulation's store on huge pages where faults are slow").
constexpr double slow_first_write_seconds = 5e-6;
// Pages the probe writes: its median ignores a few preempted writes.
constexpr std::size_t probe_pages = 64;

/// The median time of a first write to a fresh 4 kB page; 0 where no memory
/// could be mapped.
double medianFirstWriteSeconds() {
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  void *mapped =
      mmap(nullptr, probe_pages * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapped == MAP_FAILED)
    return 0;
  madvise(mapped, probe_pages * page, MADV_NOHUGEPAGE);
  volatile char *bytes = static_cast<volatile char *>(mapped);
  std::array<double, probe_pages> seconds{};
  for (std::size_t i = 0; i < probe_pages; ++i) {
    const auto start = std::chrono::steady_clock::now();
    bytes[i * page] = 1;
    seconds[i] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  munmap(mapped, probe_pages * page);
  std::nth_element(seconds.begin(), seconds.begin() + probe_pages / 2, seconds.end());
  return seconds[probe_pages / 2];
}

std::atomic<HugePagesChoice> huge_pages_choice{HugePagesChoice::undecided};

/// The whole pages of size `page` inside [start, start + bytes), advised.
void advise(std::uintptr_t start, std::size_t bytes, std::uintptr_t page, int advice) noexcept {
  const std::uintptr_t first = (start + page - 1) & ~(page - 1);
  const std::uintptr_t last = (start + bytes) & ~(page - 1);
  if (last > first)
    madvise(reinterpret_cast<void *>(first), last - first, advice);
}
} // namespace

bool hugePagesPay() {
  HugePagesChoice chosen = huge_pages_choice.load(std::memory_order_acquire);
  if (chosen == HugePagesChoice::undecided) {
    // Threads that get here together may each measure; the first answer stored stays.
    auto undecided = HugePagesChoice::undecided;
    huge_pages_choice.compare_exchange_strong(undecided,
                                              medianFirstWriteSeconds() > slow_first_write_seconds
                                                  ? HugePagesChoice::pay
                                                  : HugePagesChoice::do_not_pay,
                                              std::memory_order_acq_rel);
    chosen = huge_pages_choice.load(std::memory_order_acquire);
  }
  return chosen == HugePagesChoice::pay;
}

HugePagesChoice hugePagesChoice() { return huge_pages_choice.load(std::memory_order_acquire); }

void setHugePagesChoice(HugePagesChoice choice) {
  huge_pages_choice.store(choice, std::memory_order_release);
}

void populateForWriting(const void *data, std::size_t bytes) noexcept {
  if (bytes < min_populated_bytes)
    return;
  static const std::uintptr_t page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto start = reinterpret_cast<std::uintptr_t>(data);
  // Where huge pages pay, the whole huge pages inside go on them, like the
  // triangulation's store (huge_page_allocator.h): one fault each instead
  // of 512. Shorter ranges hold none, and do not run the probe: a small
  // cloud's call never pays for it.
  if (bytes >= huge_page_bytes && hugePagesPay())
    advise(start, bytes, huge_page_bytes, MADV_HUGEPAGE);
  advise(start, bytes, page, populate_write_advice);
}

#else

bool hugePagesPay() { return false; }

HugePagesChoice hugePagesChoice() { return HugePagesChoice::do_not_pay; }

void setHugePagesChoice(HugePagesChoice) {}

void populateForWriting(const void *, std::size_t) noexcept {}

#endif

} // namespace detail
} // namespace pcl_ms

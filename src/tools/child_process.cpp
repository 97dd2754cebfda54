// SPDX-License-Identifier: GPL-3.0-or-later
#include "child_process.h"

#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace pcl_ms_tools {

namespace {

bool writeAll(int fd, const void *data, std::size_t size) {
  const char *bytes = static_cast<const char *>(data);
  while (size > 0) {
    const ssize_t count = write(fd, bytes, size);
    if (count < 0 && errno == EINTR)
      continue;
    if (count <= 0)
      return false;
    bytes += count;
    size -= static_cast<std::size_t>(count);
  }
  return true;
}

/// A "Vm...:" line of /proc/self/status in MiB, 0 where unknown.
double statusMb(const char *key) {
  std::ifstream status("/proc/self/status");
  const std::size_t length = std::strlen(key);
  std::string line;
  while (std::getline(status, line))
    if (line.compare(0, length, key) == 0)
      return std::strtod(line.c_str() + length, nullptr) / 1024.0; // the value is in kB
  return 0;
}

/// Child side: status byte, peak and start memory, length, bytes.
[[noreturn]] void childMain(int fd, const std::function<std::string()> &work) {
  const double start = residentMb();
  std::uint8_t status = 0;
  std::string bytes;
  try {
    bytes = work();
  } catch (const std::exception &exception) {
    status = 1;
    bytes = exception.what();
  } catch (...) {
    status = 1;
    bytes = "unknown exception";
  }
  const double peak = peakResidentMb();
  const std::uint64_t size = bytes.size();
  const bool written = writeAll(fd, &status, sizeof(status)) && writeAll(fd, &peak, sizeof(peak)) &&
                       writeAll(fd, &start, sizeof(start)) && writeAll(fd, &size, sizeof(size)) &&
                       writeAll(fd, bytes.data(), bytes.size());
  std::fflush(nullptr); // the work's own progress output; _exit does not flush
  _exit(written ? 0 : 1);
}

} // namespace

double peakResidentMb() { return statusMb("VmHWM:"); }

double residentMb() { return statusMb("VmRSS:"); }

ChildOutcome runInChild(const std::function<std::string()> &work) {
  ChildOutcome outcome;
  std::fflush(nullptr); // or the child would print the caller's buffered output again
#if defined(__GLIBC__)
  malloc_trim(0); // freed heap the caller still holds would hide part of the child's growth
#endif
  int channel[2];
  if (pipe(channel) != 0) {
    outcome.error = std::string("pipe: ") + std::strerror(errno);
    return outcome;
  }
  const pid_t child = fork();
  if (child < 0) {
    outcome.error = std::string("fork: ") + std::strerror(errno);
    close(channel[0]);
    close(channel[1]);
    return outcome;
  }
  if (child == 0) {
    close(channel[0]);
    childMain(channel[1], work);
  }
  close(channel[1]);
  // Read everything before waiting: a large payload fills the pipe.
  std::string received;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t count = read(channel[0], buffer, sizeof(buffer));
    if (count < 0 && errno == EINTR)
      continue;
    if (count <= 0)
      break;
    received.append(buffer, static_cast<std::size_t>(count));
  }
  close(channel[0]);
  int status = 0;
  rusage usage{};
  while (wait4(child, &status, 0, &usage) < 0 && errno == EINTR) {
  }

  const std::size_t header = sizeof(std::uint8_t) + 2 * sizeof(double) + sizeof(std::uint64_t);
  std::uint64_t size = 0;
  if (received.size() >= header)
    std::memcpy(&size, received.data() + sizeof(std::uint8_t) + 2 * sizeof(double), sizeof(size));
  if (received.size() < header || received.size() - header != size) {
    outcome.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0; // ru_maxrss is in KiB
    if (WIFSIGNALED(status))
      outcome.error = std::string("crashed (") + strsignal(WTERMSIG(status)) + ")";
    else
      outcome.error = "exited with status " + std::to_string(WEXITSTATUS(status)) +
                      " before reporting a result";
    return outcome;
  }
  std::memcpy(&outcome.peak_mb, received.data() + sizeof(std::uint8_t), sizeof(double));
  std::memcpy(&outcome.start_mb, received.data() + sizeof(std::uint8_t) + sizeof(double),
              sizeof(double));
  outcome.payload = received.substr(header);
  outcome.ok = received[0] == 0;
  if (!outcome.ok) {
    outcome.error = outcome.payload;
    outcome.payload.clear();
  }
  return outcome;
}

} // namespace pcl_ms_tools

// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpi_bucket_exchange.h"

#include <pcl_ms/deadline.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <future>
#include <limits>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <utility>

namespace pcl_ms_mpi {
namespace {

// Elements per MPI call: well below INT_MAX.
constexpr std::size_t max_piece = std::size_t(1) << 26;

constexpr int size_tag = 1601, data_tag = 1602;
// A message size that means "no more units".
constexpr std::uint64_t release_mark = std::numeric_limits<std::uint64_t>::max();

/// Flat byte buffers for tasks and outcomes: both ends are the same binary.
class Writer {
public:
  template <typename T> void value(const T &v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto *bytes = reinterpret_cast<const char *>(&v);
    buffer.insert(buffer.end(), bytes, bytes + sizeof(T));
  }
  template <typename T> void array(const std::vector<T> &values) {
    static_assert(std::is_trivially_copyable_v<T>);
    value<std::uint64_t>(values.size());
    const auto *bytes = reinterpret_cast<const char *>(values.data());
    buffer.insert(buffer.end(), bytes, bytes + values.size() * sizeof(T));
  }
  /// Eigen vectors, coordinate by coordinate (they are not trivially copyable).
  template <typename Vector> void vectors(const std::vector<Vector> &values) {
    value<std::uint64_t>(values.size());
    for (const Vector &v : values)
      for (int k = 0; k < 3; ++k)
        value(v[k]);
  }
  void flags(const std::vector<bool> &values) {
    value<std::uint64_t>(values.size());
    for (bool flag : values)
      buffer.push_back(flag ? 1 : 0);
  }
  std::vector<char> buffer;
};

class Reader {
public:
  explicit Reader(const std::vector<char> &buffer) : buffer_(buffer) {}
  template <typename T> T value() {
    T v;
    std::memcpy(&v, take(sizeof(T)), sizeof(T));
    return v;
  }
  template <typename T> std::vector<T> array() {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto count = value<std::uint64_t>();
    if (count > (buffer_.size() - at_) / std::max<std::size_t>(sizeof(T), 1))
      throw std::runtime_error("malformed unit message");
    std::vector<T> values(count);
    std::memcpy(values.data(), take(count * sizeof(T)), count * sizeof(T));
    return values;
  }
  template <typename Vector> std::vector<Vector> vectors() {
    using Scalar = typename Vector::Scalar;
    const auto count = value<std::uint64_t>();
    if (count > (buffer_.size() - at_) / (3 * sizeof(Scalar)))
      throw std::runtime_error("malformed unit message");
    std::vector<Vector> values(count);
    for (Vector &v : values)
      for (int k = 0; k < 3; ++k)
        v[k] = value<Scalar>();
    return values;
  }
  std::vector<bool> flags() {
    const auto count = value<std::uint64_t>();
    const char *bytes = take(count);
    std::vector<bool> values(count);
    for (std::size_t i = 0; i < count; ++i)
      values[i] = bytes[i] != 0;
    return values;
  }

private:
  const char *take(std::size_t bytes) {
    if (bytes > buffer_.size() - at_)
      throw std::runtime_error("malformed unit message");
    const char *start = buffer_.data() + at_;
    at_ += bytes;
    return start;
  }
  const std::vector<char> &buffer_;
  std::size_t at_ = 0;
};

std::vector<char> encodeTask(std::uint64_t unit, const pcl_ms::BucketTask &task) {
  Writer out;
  out.value(unit);
  out.vectors(task.points);
  out.vectors(task.normals);
  out.flags(task.core);
  out.array(task.fixed_triangles);
  out.flags(task.frozen);
  out.value(task.d_med);
  out.array(task.local_scale);
  return std::move(out.buffer);
}

pcl_ms::BucketTask decodeTask(const std::vector<char> &buffer, std::uint64_t &unit) {
  Reader in(buffer);
  pcl_ms::BucketTask task;
  unit = in.value<std::uint64_t>();
  task.points = in.vectors<Eigen::Vector3d>();
  task.normals = in.vectors<Eigen::Vector3f>();
  task.core = in.flags();
  task.fixed_triangles = in.array<pcl_ms::Triangle>();
  task.frozen = in.flags();
  task.d_med = in.value<double>();
  task.local_scale = in.array<float>();
  return task;
}

std::vector<char> encodeOutcome(std::uint64_t unit, const pcl_ms::BucketOutcome &outcome) {
  Writer out;
  out.value(unit);
  out.array(outcome.triangles);
  out.array(outcome.cut_vertices);
  out.value(outcome.d_med);
  out.array(outcome.local_scale);
  out.value(outcome.delaunay_seconds);
  out.value(outcome.scaffold_seconds);
  out.value(outcome.greedy_seconds);
  out.array(std::vector<char>(outcome.error.begin(), outcome.error.end()));
  return std::move(out.buffer);
}

pcl_ms::BucketOutcome decodeOutcome(const std::vector<char> &buffer, std::uint64_t &unit) {
  Reader in(buffer);
  pcl_ms::BucketOutcome outcome;
  unit = in.value<std::uint64_t>();
  outcome.triangles = in.array<pcl_ms::Triangle>();
  outcome.cut_vertices = in.array<pcl_ms::VertexIndex>();
  outcome.d_med = in.value<double>();
  outcome.local_scale = in.array<float>();
  outcome.delaunay_seconds = in.value<double>();
  outcome.scaffold_seconds = in.value<double>();
  outcome.greedy_seconds = in.value<double>();
  const std::vector<char> error = in.array<char>();
  outcome.error.assign(error.begin(), error.end());
  return outcome;
}

/// A size message, then the bytes.
std::size_t sendMessage(const std::vector<char> &buffer, int to, MPI_Comm communicator) {
  const std::uint64_t bytes = buffer.size();
  MPI_Send(&bytes, 1, MPI_UINT64_T, to, size_tag, communicator);
  sendBytes(buffer.data(), buffer.size(), to, communicator);
  return buffer.size();
}

/// From `from` (or any rank); false when it was the release mark.
bool receiveMessage(std::vector<char> &buffer, int &from, MPI_Comm communicator) {
  std::uint64_t bytes = 0;
  MPI_Status status;
  MPI_Recv(&bytes, 1, MPI_UINT64_T, from, size_tag, communicator, &status);
  from = status.MPI_SOURCE;
  if (bytes == release_mark)
    return false;
  buffer.resize(bytes);
  receiveBytes(buffer.data(), bytes, from, communicator);
  return true;
}

} // namespace

MpiUnitFarm::MpiUnitFarm(MPI_Comm communicator, const pcl_ms::Parameters &parameters,
                         std::function<void(const std::string &)> on_stage)
    : communicator_(communicator), parameters_(parameters),
      deadline_(parameters.time_limit_seconds), on_stage_(std::move(on_stage)) {
  parameters_.progress = {}; // units report through meshInBuckets, not here
  MPI_Comm_size(communicator_, &size_);
}

void MpiUnitFarm::stageDone(const std::string &stage) {
  if (on_stage_)
    on_stage_(stage);
}

void MpiUnitFarm::mesh(std::size_t count,
                       const std::function<pcl_ms::BucketTask(std::size_t)> &make,
                       const std::function<void(std::size_t, pcl_ms::BucketOutcome &&)> &done) {
  std::size_t next = 0, remote = 0;
  const auto sendNext = [&](int to) {
    bytes_sent_ += sendMessage(encodeTask(next, make(next)), to, communicator_);
    ++next;
    ++remote;
  };
  // One unit per rank at a time: the next goes to whichever finishes first.
  for (int rank = 1; rank < size_ && next < count; ++rank)
    sendNext(rank);
  std::future<pcl_ms::BucketOutcome> local;
  std::size_t local_unit = 0;
  std::vector<char> buffer;
  while (remote > 0 || local.valid() || next < count) {
    if (!local.valid() && next < count) {
      local_unit = next++;
      local = std::async(std::launch::async, [this, task = make(local_unit)] {
        return pcl_ms::meshBucket(task, parameters_, &deadline_);
      });
    }
    if (local.valid() && local.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      done(local_unit, local.get()); // rethrows the time limit
      continue;
    }
    // Polled, not a blocking receive: Open MPI's spins a core, which
    // rank 0's own unit needs.
    int waiting = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, size_tag, communicator_, &waiting, &status);
    if (!waiting) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    int from = status.MPI_SOURCE;
    if (!receiveMessage(buffer, from, communicator_))
      throw std::runtime_error("rank " + std::to_string(from) + " sent no outcome");
    bytes_received_ += buffer.size();
    --remote;
    std::uint64_t unit = 0;
    pcl_ms::BucketOutcome outcome = decodeOutcome(buffer, unit);
    if (unit >= count)
      throw std::runtime_error("malformed unit message");
    // The next task goes out before this outcome is taken in, so that its
    // rank does not wait for rank 0's bookkeeping.
    if (next < count)
      sendNext(from);
    done(unit, std::move(outcome));
  }
}

void MpiUnitFarm::release() {
  if (released_)
    return;
  released_ = true;
  for (int rank = 1; rank < size_; ++rank)
    MPI_Send(&release_mark, 1, MPI_UINT64_T, rank, size_tag, communicator_);
}

ServedUnits serveUnits(MPI_Comm communicator, const pcl_ms::Parameters &parameters) {
  ServedUnits served;
  const pcl_ms::Deadline deadline(parameters.time_limit_seconds);
  std::vector<char> buffer;
  for (;;) {
    // Waiting polls too: rank 0 finishes the surface while the others
    // wait for the release, and a spinning receive would take its core.
    for (int waiting = 0; !waiting;) {
      MPI_Iprobe(0, size_tag, communicator, &waiting, MPI_STATUS_IGNORE);
      if (!waiting)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    int from = 0;
    if (!receiveMessage(buffer, from, communicator))
      break;
    const auto start = std::chrono::steady_clock::now();
    served.bytes_received += buffer.size();
    std::uint64_t unit = 0;
    const pcl_ms::BucketTask task = decodeTask(buffer, unit);
    std::vector<char>().swap(buffer);
    const pcl_ms::BucketOutcome outcome = pcl_ms::meshBucket(task, parameters, &deadline);
    served.bytes_sent += sendMessage(encodeOutcome(unit, outcome), 0, communicator);
    ++served.units;
    served.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return served;
}

void broadcastBytes(void *data, std::size_t bytes, int root, MPI_Comm communicator) {
  char *bytes_data = static_cast<char *>(data);
  for (std::size_t begin = 0; begin < bytes; begin += max_piece)
    MPI_Bcast(bytes_data + begin, static_cast<int>(std::min(max_piece, bytes - begin)), MPI_BYTE,
              root, communicator);
}

void sendBytes(const void *data, std::size_t bytes, int to, MPI_Comm communicator) {
  const char *bytes_data = static_cast<const char *>(data);
  for (std::size_t begin = 0; begin < bytes; begin += max_piece)
    MPI_Send(bytes_data + begin, static_cast<int>(std::min(max_piece, bytes - begin)), MPI_BYTE, to,
             data_tag, communicator);
}

void receiveBytes(void *data, std::size_t bytes, int from, MPI_Comm communicator) {
  char *bytes_data = static_cast<char *>(data);
  for (std::size_t begin = 0; begin < bytes; begin += max_piece)
    MPI_Recv(bytes_data + begin, static_cast<int>(std::min(max_piece, bytes - begin)), MPI_BYTE,
             from, data_tag, communicator, MPI_STATUS_IGNORE);
}

} // namespace pcl_ms_mpi

// SPDX-License-Identifier: GPL-3.0-or-later
// The buckets and seam zones of one cloud meshed across the ranks of an MPI
// communicator (docs/algorithm.md, "Across processes"): rank 0 plans every
// unit and hands its task to a free rank; the other ranks mesh one unit at
// a time and send the outcome back, holding no more than that unit.
#pragma once

#include <pcl_ms/buckets.h>
#include <pcl_ms/deadline.h>

#include <mpi.h>

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace pcl_ms_mpi {

/// Rank 0's side: a pcl_ms::BucketExchange whose farm sends units to ranks
/// 1 .. N-1 and meshes one at a time itself, on a thread of its own (only
/// the calling thread calls MPI). With one rank there is no farm.
class MpiUnitFarm : public pcl_ms::BucketExchange, public pcl_ms::UnitFarm {
public:
  /// `parameters` mesh rank 0's own units (a copy is kept); `on_stage` runs
  /// after the buckets and after each seam level.
  MpiUnitFarm(MPI_Comm communicator, const pcl_ms::Parameters &parameters,
              std::function<void(const std::string &)> on_stage = {});

  pcl_ms::UnitFarm *farm() override { return size_ > 1 ? this : nullptr; }
  void stageDone(const std::string &stage) override;
  void pointsPrepared() override {
    if (on_prepared_)
      on_prepared_();
  }
  /// Runs once the points are prepared (the caller's cloud may go then).
  void onPointsPrepared(std::function<void()> on_prepared) {
    on_prepared_ = std::move(on_prepared);
  }
  void mesh(std::size_t count, const std::function<pcl_ms::BucketTask(std::size_t)> &make,
            const std::function<void(std::size_t, pcl_ms::BucketOutcome &&)> &done) override;
  /// Tells every other rank that no more units come; call once, at the end.
  void release();

  std::size_t bytesSent() const { return bytes_sent_; }
  std::size_t bytesReceived() const { return bytes_received_; }

private:
  MPI_Comm communicator_;
  pcl_ms::Parameters parameters_;
  pcl_ms::Deadline deadline_;
  int size_ = 1;
  std::function<void(const std::string &)> on_stage_;
  std::function<void()> on_prepared_;
  std::size_t bytes_sent_ = 0, bytes_received_ = 0;
  bool released_ = false;
};

/// What a rank other than 0 did in serveUnits.
struct ServedUnits {
  std::size_t units = 0, bytes_sent = 0, bytes_received = 0;
  double seconds = 0;
};

/// The other ranks' side: meshes the units rank 0 sends until it releases
/// them. A unit that throws (the time limit) is rethrown.
ServedUnits serveUnits(MPI_Comm communicator, const pcl_ms::Parameters &parameters);

/// MPI calls take int counts: these split a buffer into pieces that fit.
void broadcastBytes(void *data, std::size_t bytes, int root, MPI_Comm communicator);
void sendBytes(const void *data, std::size_t bytes, int to, MPI_Comm communicator);
void receiveBytes(void *data, std::size_t bytes, int from, MPI_Comm communicator);

} // namespace pcl_ms_mpi

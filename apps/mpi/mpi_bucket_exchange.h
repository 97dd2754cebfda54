// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms::BucketExchange over MPI: the buckets and seam zones of one cloud
// shared among the ranks of a communicator (docs/algorithm.md, "Across processes").
#pragma once

#include <pcl_ms/buckets.h>

#include <mpi.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace pcl_ms_mpi {

class MpiBucketExchange : public pcl_ms::BucketExchange {
public:
  /// `on_stage` runs on every rank after each stage (all ranks have passed
  /// the stage's collective call by then).
  explicit MpiBucketExchange(MPI_Comm communicator,
                             std::function<void(const std::string &)> on_stage = {});

  int processes() const override { return size_; }
  int process() const override { return rank_; }
  void maxOver(std::vector<float> &values) override;
  void maxOver(std::vector<std::uint8_t> &values) override;
  void sumOver(std::vector<double> &values) override;
  /// Transfers run one after the other in the given order, which every rank
  /// shares: the earliest unfinished one always has both ranks waiting on
  /// it, so the blocking sends cannot deadlock.
  void moveTriangles(const std::vector<Transfer> &transfers) override;
  void stageDone(const std::string &stage) override;

  /// Bytes of triangles this rank sent and received so far.
  std::size_t bytesSent() const { return bytes_sent_; }
  std::size_t bytesReceived() const { return bytes_received_; }

private:
  MPI_Comm communicator_;
  int size_ = 1, rank_ = 0;
  std::function<void(const std::string &)> on_stage_;
  std::size_t bytes_sent_ = 0, bytes_received_ = 0;
};

/// MPI calls take int counts: these split a buffer into pieces that fit.
void broadcastBytes(void *data, std::size_t bytes, int root, MPI_Comm communicator);
void sendBytes(const void *data, std::size_t bytes, int to, MPI_Comm communicator);
void receiveBytes(void *data, std::size_t bytes, int from, MPI_Comm communicator);

} // namespace pcl_ms_mpi

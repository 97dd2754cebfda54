// SPDX-License-Identifier: GPL-3.0-or-later
// pcl_ms::ProcessGroup over an MPI communicator: the collectives with which
// the ranks prepare a cloud that none of them holds whole
// (docs/algorithm.md, "Across processes").
#pragma once

#include <pcl_ms/process_group.h>

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pcl_ms_mpi {

class MpiProcessGroup : public pcl_ms::ProcessGroup {
public:
  explicit MpiProcessGroup(MPI_Comm communicator);
  int processes() const override { return size_; }
  int process() const override { return rank_; }
  void sum(std::vector<std::uint64_t> &values) override;
  void minimum(std::vector<double> &values) override;
  void maximum(std::vector<double> &values) override;
  std::vector<unsigned char> gatherAll(const std::vector<unsigned char> &mine) override;
  std::vector<unsigned char>
  exchange(const std::vector<std::vector<unsigned char>> &outgoing) override;

  /// Bytes this rank sent to and received from other ranks so far.
  std::size_t bytesSent() const { return bytes_sent_; }
  std::size_t bytesReceived() const { return bytes_received_; }

private:
  /// Returns once every rank has reached this point, without spinning.
  void arrive();
  void reduce(void *values, std::size_t count, MPI_Datatype type, MPI_Op operation);

  MPI_Comm communicator_;
  int rank_ = 0, size_ = 1;
  std::size_t bytes_sent_ = 0, bytes_received_ = 0;
};

} // namespace pcl_ms_mpi

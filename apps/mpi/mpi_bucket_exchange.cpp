// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpi_bucket_exchange.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <utility>

namespace pcl_ms_mpi {
namespace {

// Elements per MPI call: well below INT_MAX, and small enough that a piece
// of a reduction does not double a rank's memory.
constexpr std::size_t max_piece = std::size_t(1) << 26;

template <typename Value>
void allReduceInPlace(std::vector<Value> &values, MPI_Datatype type, MPI_Op operation,
                      MPI_Comm communicator) {
  for (std::size_t begin = 0; begin < values.size(); begin += max_piece) {
    const int count = static_cast<int>(std::min(max_piece, values.size() - begin));
    MPI_Allreduce(MPI_IN_PLACE, values.data() + begin, count, type, operation, communicator);
  }
}

constexpr int triangle_count_tag = 1601, triangle_data_tag = 1602;

} // namespace

MpiBucketExchange::MpiBucketExchange(MPI_Comm communicator,
                                     std::function<void(const std::string &)> on_stage)
    : communicator_(communicator), on_stage_(std::move(on_stage)) {
  MPI_Comm_size(communicator_, &size_);
  MPI_Comm_rank(communicator_, &rank_);
}

void MpiBucketExchange::maxOver(std::vector<float> &values) {
  allReduceInPlace(values, MPI_FLOAT, MPI_MAX, communicator_);
}

void MpiBucketExchange::maxOver(std::vector<std::uint8_t> &values) {
  allReduceInPlace(values, MPI_UINT8_T, MPI_MAX, communicator_);
}

void MpiBucketExchange::sumOver(std::vector<double> &values) {
  allReduceInPlace(values, MPI_DOUBLE, MPI_SUM, communicator_);
}

void MpiBucketExchange::moveTriangles(const std::vector<Transfer> &transfers) {
  for (const Transfer &transfer : transfers) {
    if (transfer.from == transfer.to)
      continue;
    std::vector<pcl_ms::Triangle> &triangles = *transfer.triangles;
    if (transfer.from == rank_) {
      const std::uint64_t count = triangles.size();
      MPI_Send(&count, 1, MPI_UINT64_T, transfer.to, triangle_count_tag, communicator_);
      sendBytes(triangles.data(), count * sizeof(pcl_ms::Triangle), transfer.to, communicator_);
      bytes_sent_ += count * sizeof(pcl_ms::Triangle);
      std::vector<pcl_ms::Triangle>().swap(triangles);
    } else if (transfer.to == rank_) {
      std::uint64_t count = 0;
      MPI_Recv(&count, 1, MPI_UINT64_T, transfer.from, triangle_count_tag, communicator_,
               MPI_STATUS_IGNORE);
      triangles.resize(count);
      receiveBytes(triangles.data(), count * sizeof(pcl_ms::Triangle), transfer.from,
                   communicator_);
      bytes_received_ += count * sizeof(pcl_ms::Triangle);
    }
  }
}

void MpiBucketExchange::stageDone(const std::string &stage) {
  if (on_stage_)
    on_stage_(stage);
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
             triangle_data_tag, communicator);
}

void receiveBytes(void *data, std::size_t bytes, int from, MPI_Comm communicator) {
  char *bytes_data = static_cast<char *>(data);
  for (std::size_t begin = 0; begin < bytes; begin += max_piece)
    MPI_Recv(bytes_data + begin, static_cast<int>(std::min(max_piece, bytes - begin)), MPI_BYTE,
             from, triangle_data_tag, communicator, MPI_STATUS_IGNORE);
}

} // namespace pcl_ms_mpi

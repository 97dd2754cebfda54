// SPDX-License-Identifier: GPL-3.0-or-later
// MpiProcessGroup: reductions with MPI_Allreduce (minimum and maximum with
// operations of our own, which give any order of ranks the same bits); byte
// exchanges pairwise, in pieces below MPI's int counts, so that a rank may
// send more than 2 GB.
// A rank that reaches a collective before the others waits for them asleep:
// Open MPI's blocking calls spin a core, which the ranks still meshing need
// when there are more ranks than cores.
#include "mpi_process_group.h"

#include <algorithm>
#include <chrono>
#include <thread>

namespace pcl_ms_mpi {
namespace {

constexpr std::size_t max_piece = std::size_t{1} << 30;
constexpr int exchange_tag = 31;

/// Completes `requests`, sleeping between tests once a short spin has not
/// done it: the others may be minutes away.
void waitAsleep(std::vector<MPI_Request> &requests) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int done = 0;
    MPI_Testall(static_cast<int>(requests.size()), requests.data(), &done, MPI_STATUSES_IGNORE);
    if (done)
      return;
    if (std::chrono::steady_clock::now() - start > std::chrono::microseconds(200))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

/// MPI_Op functions over MPI_DOUBLE: MPI_MIN and MPI_MAX leave NaN and
/// signed zeros to the order in which Open MPI meets the ranks' values.
template <double (*combine)(double, double)>
void combineDoubles(void *in, void *in_out, int *count, MPI_Datatype *) {
  const double *theirs = static_cast<const double *>(in);
  double *ours = static_cast<double *>(in_out);
  for (int i = 0; i < *count; ++i)
    ours[i] = combine(theirs[i], ours[i]);
}

/// An MPI_Op over a function, freed when it goes out of scope.
class CommutativeOp {
public:
  explicit CommutativeOp(MPI_User_function *function) { MPI_Op_create(function, 1, &op_); }
  ~CommutativeOp() { MPI_Op_free(&op_); }
  CommutativeOp(const CommutativeOp &) = delete;
  CommutativeOp &operator=(const CommutativeOp &) = delete;
  MPI_Op get() const { return op_; }

private:
  MPI_Op op_ = MPI_OP_NULL;
};

} // namespace

void MpiProcessGroup::arrive() {
  std::vector<MPI_Request> barrier(1);
  MPI_Ibarrier(communicator_, barrier.data());
  waitAsleep(barrier);
}

MpiProcessGroup::MpiProcessGroup(MPI_Comm communicator) : communicator_(communicator) {
  MPI_Comm_rank(communicator_, &rank_);
  MPI_Comm_size(communicator_, &size_);
}

void MpiProcessGroup::reduce(void *values, std::size_t count, MPI_Datatype type, MPI_Op operation) {
  arrive();
  char *data = static_cast<char *>(values);
  int type_size = 0;
  MPI_Type_size(type, &type_size);
  const std::size_t piece = max_piece / static_cast<std::size_t>(type_size);
  for (std::size_t begin = 0; begin < count; begin += piece)
    MPI_Allreduce(MPI_IN_PLACE, data + begin * static_cast<std::size_t>(type_size),
                  static_cast<int>(std::min(piece, count - begin)), type, operation, communicator_);
}

void MpiProcessGroup::sum(std::vector<std::uint64_t> &values) {
  reduce(values.data(), values.size(), MPI_UINT64_T, MPI_SUM);
}

void MpiProcessGroup::minimum(std::vector<double> &values) {
  const CommutativeOp minimum(&combineDoubles<pcl_ms::orderFreeMinimum>);
  reduce(values.data(), values.size(), MPI_DOUBLE, minimum.get());
}

void MpiProcessGroup::maximum(std::vector<double> &values) {
  const CommutativeOp maximum(&combineDoubles<pcl_ms::orderFreeMaximum>);
  reduce(values.data(), values.size(), MPI_DOUBLE, maximum.get());
}

std::vector<unsigned char> MpiProcessGroup::gatherAll(const std::vector<unsigned char> &mine) {
  std::vector<std::vector<unsigned char>> outgoing(static_cast<std::size_t>(size_), mine);
  return exchange(outgoing);
}

std::vector<unsigned char>
MpiProcessGroup::exchange(const std::vector<std::vector<unsigned char>> &outgoing) {
  arrive();
  // Sizes first, so that each rank knows where every sender's bytes go.
  std::vector<std::uint64_t> sending(static_cast<std::size_t>(size_)), receiving(sending.size());
  for (std::size_t p = 0; p < sending.size(); ++p)
    sending[p] = outgoing.at(p).size();
  MPI_Alltoall(sending.data(), 1, MPI_UINT64_T, receiving.data(), 1, MPI_UINT64_T, communicator_);
  std::vector<std::size_t> offset(receiving.size() + 1, 0);
  for (std::size_t p = 0; p < receiving.size(); ++p)
    offset[p + 1] = offset[p] + receiving[p];
  std::vector<unsigned char> received(offset.back());
  const auto own = static_cast<std::size_t>(rank_);
  std::copy(outgoing[own].begin(), outgoing[own].end(), received.begin() + offset[own]);
  // Round k: to rank + k, from rank - k; every pair meets once. Each side
  // counts the pieces from the size alone, so sender and receiver agree.
  for (int k = 1; k < size_; ++k) {
    const int to = (rank_ + k) % size_, from = (rank_ - k + size_) % size_;
    const std::vector<unsigned char> &bytes = outgoing[static_cast<std::size_t>(to)];
    const std::size_t expected = receiving[static_cast<std::size_t>(from)];
    unsigned char *into = received.data() + offset[static_cast<std::size_t>(from)];
    std::vector<MPI_Request> requests;
    for (std::size_t begin = 0; begin < expected; begin += max_piece) {
      requests.emplace_back();
      MPI_Irecv(into + begin, static_cast<int>(std::min(max_piece, expected - begin)), MPI_BYTE,
                from, exchange_tag, communicator_, &requests.back());
    }
    for (std::size_t begin = 0; begin < bytes.size(); begin += max_piece) {
      requests.emplace_back();
      MPI_Isend(bytes.data() + begin, static_cast<int>(std::min(max_piece, bytes.size() - begin)),
                MPI_BYTE, to, exchange_tag, communicator_, &requests.back());
    }
    waitAsleep(requests);
    bytes_sent_ += bytes.size();
    bytes_received_ += expected;
  }
  return received;
}

} // namespace pcl_ms_mpi

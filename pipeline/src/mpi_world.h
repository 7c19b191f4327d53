#pragma once
// The little of MPI the back-end needs, behind a header without <mpi.h>: whether this process was
// started by mpirun, the world (MPI_Init_thread .. MPI_Finalize, RAII), and byte messages between
// ranks. Only mpi_world.cpp includes <mpi.h>; a build without MPI compiles it to refusals.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tomorig::pipeline::mpi {

// True if a launcher (mpirun, or srun with PMI/PMIx) started this process as one of a job's
// ranks, from the environment it sets; without one, MPI is never initialised, so a plain
// `tomorig process` neither needs nor touches MPI.
bool launched_by_mpi();
// The job's size as the launcher's environment gives it; 0 if it says nothing.
int launched_size();
bool built_with_mpi();

// The tags of the back-end's messages (cluster_backend.cpp describes the exchange).
enum Tag : int {
  kSetupStatus = 1,  // rank -> 0: why the rank's set-up failed (text)
  kRequest = 2,      // worker -> 0: give me a set (no data)
  kAssign = 3,       // 0 -> worker: the set index to do, or -1: no more
  kResult = 4,       // worker -> 0: a finished set (set_result_codec.h)
  kDone = 5,         // worker -> 0: the worker has ended (its exit code and error text)
};

struct Message {
  int source = 0;
  int tag = 0;
  std::vector<char> bytes;
};

// MPI_Init_thread with MPI_THREAD_MULTIPLE (rank 0 runs a worker thread beside the coordinator,
// and a worker's reconstruction and correlation threads both talk to rank 0), MPI_Finalize at
// destruction. Throws tomorig::Error (runtime) if MPI cannot give that thread level, or in a
// build without MPI.
class World {
 public:
  World();
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  // Ranks on this node (MPI_COMM_TYPE_SHARED), to share its cores and memory among them.
  int local_size() const { return local_size_; }
  std::string host() const;
  // The ranks have gone through the whole exchange, so MPI_Finalize (collective) will not wait
  // for a rank that is gone. Without it the destructor calls MPI_Abort instead of hanging.
  void mark_exchange_complete() { complete_ = true; }
  // Ends every rank of the job now (MPI_Abort), with `exit_code` from mpirun.
  [[noreturn]] void abort_job(int exit_code) const;

  void send(int to, int tag, const std::vector<char>& bytes) const;
  void send_int64(int to, int tag, std::int64_t value) const;
  // Blocks for a message of `tag` from `from`.
  std::vector<char> receive(int from, int tag) const;
  std::int64_t receive_int64(int from, int tag) const;
  // A message from any rank, if one is waiting.
  std::optional<Message> try_receive() const;
  // Collectives over every rank.
  std::vector<std::int64_t> gather_int64(std::int64_t value) const;  // at rank 0; empty elsewhere
  std::vector<char> gather_fixed(const std::vector<char>& bytes) const;  // same size everywhere; at rank 0
  std::int64_t broadcast_int64(std::int64_t value) const;             // rank 0's value

 private:
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool complete_ = false;
  // Two duplicates of MPI_COMM_WORLD: messages to rank 0's coordinator, and set assignments to the
  // workers. Rank 0's coordinator receives from any source on the first, so it can never take an
  // assignment meant for the worker thread beside it.
  struct Comms;
  std::unique_ptr<Comms> comms_;
};

}  // namespace tomorig::pipeline::mpi

#include "mpi_world.h"

#include <cstdlib>
#include <string_view>

#include <fmt/core.h>

#include "tomorig/core/error.h"

#if TOMORIG_WITH_MPI
#define OMPI_SKIP_MPICXX 1  // the C API only: the C++ bindings are deprecated and not linked
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace tomorig::pipeline::mpi {
namespace {

int env_int(const char* name) {
  const char* text = std::getenv(name);
  return text ? std::atoi(text) : -1;
}

}  // namespace

bool launched_by_mpi() {
  // OpenMPI's mpirun sets OMPI_COMM_WORLD_*; srun and other PMI launchers set PMI_RANK or PMIX_RANK.
  return env_int("OMPI_COMM_WORLD_SIZE") >= 1 || env_int("PMIX_RANK") >= 0 || env_int("PMI_RANK") >= 0;
}

int launched_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_NTASKS"})
    if (const int n = env_int(name); n >= 1) return n;
  return 0;
}

bool built_with_mpi() { return TOMORIG_WITH_MPI != 0; }

#if TOMORIG_WITH_MPI

namespace {

void check(int code, std::string_view what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING] = {};
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw runtime_error(fmt::format("MPI {} failed: {}", what, std::string_view(text, length)));
}

}  // namespace

struct World::Comms {
  MPI_Comm to_coordinator = MPI_COMM_NULL;
  MPI_Comm to_workers = MPI_COMM_NULL;
  MPI_Comm for_tag(int tag) const { return tag == kAssign ? to_workers : to_coordinator; }
};

World::World() {
  int provided = 0;
  check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided), "initialisation");
  if (provided < MPI_THREAD_MULTIPLE) {
    MPI_Finalize();  // every rank stops here alike
    throw runtime_error(
        "this MPI library does not support MPI_THREAD_MULTIPLE, which `tomorig process` needs under mpirun (rank 0 "
        "runs a worker beside the coordinator); use OpenMPI >= 3 (Debian 12: libopenmpi-dev, openmpi-bin)");
  }
  // Errors come back as codes, which check() turns into tomorig::Error, instead of aborting the job.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node), "node split");
  MPI_Comm_size(node, &local_size_);
  MPI_Comm_free(&node);
  comms_ = std::make_unique<Comms>();
  check(MPI_Comm_dup(MPI_COMM_WORLD, &comms_->to_coordinator), "communicator set-up");
  check(MPI_Comm_dup(MPI_COMM_WORLD, &comms_->to_workers), "communicator set-up");
}

World::~World() {
  if (!complete_) MPI_Abort(MPI_COMM_WORLD, 1);  // a rank left the exchange early: never hang
  if (comms_) {
    MPI_Comm_free(&comms_->to_coordinator);
    MPI_Comm_free(&comms_->to_workers);
  }
  MPI_Finalize();
}

void World::abort_job(int exit_code) const {
  MPI_Abort(MPI_COMM_WORLD, exit_code);
  std::abort();  // MPI_Abort does not return; this is for the compiler
}

std::string World::host() const {
  char name[MPI_MAX_PROCESSOR_NAME] = {};
  int length = 0;
  MPI_Get_processor_name(name, &length);
  return std::string(name, length);
}

void World::send(int to, int tag, const std::vector<char>& bytes) const {
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, comms_->for_tag(tag)), "send");
}

void World::send_int64(int to, int tag, std::int64_t value) const {
  check(MPI_Send(&value, 1, MPI_INT64_T, to, tag, comms_->for_tag(tag)), "send");
}

std::vector<char> World::receive(int from, int tag) const {
  MPI_Status status;
  check(MPI_Probe(from, tag, comms_->for_tag(tag), &status), "probe");
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  std::vector<char> bytes(static_cast<std::size_t>(count));
  check(MPI_Recv(bytes.data(), count, MPI_BYTE, from, tag, comms_->for_tag(tag), MPI_STATUS_IGNORE), "receive");
  return bytes;
}

std::int64_t World::receive_int64(int from, int tag) const {
  std::int64_t value = 0;
  check(MPI_Recv(&value, 1, MPI_INT64_T, from, tag, comms_->for_tag(tag), MPI_STATUS_IGNORE), "receive");
  return value;
}

std::optional<Message> World::try_receive() const {
  int waiting = 0;
  MPI_Status status;
  check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comms_->to_coordinator, &waiting, &status), "probe");
  if (!waiting) return std::nullopt;
  Message m{.source = status.MPI_SOURCE, .tag = status.MPI_TAG};
  // Only this thread receives from any source, so the probed message is the one received.
  m.bytes = receive(m.source, m.tag);
  return m;
}

std::vector<std::int64_t> World::gather_int64(std::int64_t value) const {
  std::vector<std::int64_t> all(rank_ == 0 ? static_cast<std::size_t>(size_) : 0);
  check(MPI_Gather(&value, 1, MPI_INT64_T, all.data(), 1, MPI_INT64_T, 0, MPI_COMM_WORLD), "gather");
  return all;
}

std::vector<char> World::gather_fixed(const std::vector<char>& bytes) const {
  std::vector<char> all(rank_ == 0 ? bytes.size() * static_cast<std::size_t>(size_) : 0);
  const int n = static_cast<int>(bytes.size());
  check(MPI_Gather(bytes.data(), n, MPI_BYTE, all.data(), n, MPI_BYTE, 0, MPI_COMM_WORLD), "gather");
  return all;
}

std::int64_t World::broadcast_int64(std::int64_t value) const {
  check(MPI_Bcast(&value, 1, MPI_INT64_T, 0, MPI_COMM_WORLD), "broadcast");
  return value;
}

#else  // a build without MPI: launched_by_mpi() callers refuse before they get here

struct World::Comms {};

World::World() {
  throw bad_input("this tomorig was built without MPI, so it cannot run under mpirun; install libopenmpi-dev "
                  "(scripts/apt-packages.txt) and build again, or run `tomorig process` without mpirun");
}
World::~World() = default;
void World::abort_job(int) const { std::abort(); }
std::string World::host() const { return {}; }
void World::send(int, int, const std::vector<char>&) const {}
void World::send_int64(int, int, std::int64_t) const {}
std::vector<char> World::receive(int, int) const { return {}; }
std::int64_t World::receive_int64(int, int) const { return 0; }
std::optional<Message> World::try_receive() const { return std::nullopt; }
std::vector<std::int64_t> World::gather_int64(std::int64_t) const { return {}; }
std::vector<char> World::gather_fixed(const std::vector<char>&) const { return {}; }
std::int64_t World::broadcast_int64(std::int64_t value) const { return value; }

#endif

}  // namespace tomorig::pipeline::mpi

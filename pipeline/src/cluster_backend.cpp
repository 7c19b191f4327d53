// The back-end as an MPI job. Every rank opens the session (read-only) and sets up reconstruction
// and correlation exactly as a single process would; rank 0 alone owns the results file.
//
// The exchange:
//   1. Set-up, collective: each rank reports success or its error; rank 0 also opens (or resumes)
//      the results file. If any rank failed, all stop and rank 0 throws the first error, so a
//      worker that cannot read the session is reported by rank 0 with its rank and host.
//   2. Work: every rank, rank 0 included (a thread beside its coordinator), runs the single
//      process's produce/consume loop, except that the next set comes from rank 0 on request
//      (kRequest -> kAssign, -1 when none is left): dynamic load balancing, a fast rank simply asks
//      more often. A finished set goes to rank 0 as bytes (kResult); rank 0 adds it to the results
//      file, so crash safety, resume and the statistics are those of the single process. A worker
//      ends with kDone, carrying its error if it failed; rank 0 then hands out no more sets.
//   3. Rank 0 closes the file: the statistics are restated in set order (ResultsWriter::close),
//      so they are the single process's bit for bit.
// A rank that dies takes the job with it (OpenMPI aborts every rank); the file keeps every set
// rank 0 had written, and the same command started again resumes with the others.
#include "cluster_backend.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <exception>
#include <memory>
#include <optional>
#include <thread>

#include <fmt/core.h>

#include "backend_parts.h"
#include "memory_policy.h"
#include "mpi_world.h"
#include "set_result_codec.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/two_stage_pipeline.h"

namespace tomorig::pipeline {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// An error travelling between ranks: its kind as the exit code it maps to (0: none) and its text.
struct Failure {
  int code = 0;
  std::string message;
};

Failure failure_of(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const Error& e) {
    return {e.kind() == ErrorKind::bad_input ? 2 : 1, e.what()};
  } catch (const std::exception& e) {
    return {1, e.what()};
  }
}

std::vector<char> encode_failure(const Failure& f) {
  std::vector<char> bytes(sizeof f.code + f.message.size());
  std::memcpy(bytes.data(), &f.code, sizeof f.code);
  if (!f.message.empty()) std::memcpy(bytes.data() + sizeof f.code, f.message.data(), f.message.size());
  return bytes;
}

Failure decode_failure(const std::vector<char>& bytes) {
  Failure f;
  if (bytes.size() < sizeof f.code) return {1, "a worker rank sent a damaged end message"};
  std::memcpy(&f.code, bytes.data(), sizeof f.code);
  f.message.assign(bytes.begin() + sizeof f.code, bytes.end());
  return f;
}

[[noreturn]] void raise(const Failure& f) {
  throw Error(f.code == 2 ? ErrorKind::bad_input : ErrorKind::runtime, f.message);
}

// OpenMP threads per stage on this rank: as asked, else the cores the launcher bound this rank to,
// else the node's cores shared by the ranks on it (so N ranks on one node do not oversubscribe it).
int threads_for_rank(int asked, int local_ranks) {
  if (asked > 0) return asked;
  const int all = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) {
    const int mine = CPU_COUNT(&set);
    if (mine > 0 && mine < all) return mine;
  }
  return std::max(1, all / std::max(1, local_ranks));
}

// Who a rank is, gathered on rank 0 for the operator (which host, which pid to look at).
struct RankIdentity {
  std::int64_t pid = 0;
  std::int32_t threads = 0;
  char host[64] = {};
};

std::vector<BackendRankFigures> gather_identities(const mpi::World& world, int threads) {
  RankIdentity me;
  me.pid = static_cast<std::int64_t>(::getpid());
  me.threads = threads;
  const std::string host = world.host();
  std::memcpy(me.host, host.data(), std::min(host.size(), sizeof me.host - 1));
  std::vector<char> bytes(sizeof me);
  std::memcpy(bytes.data(), &me, sizeof me);
  const std::vector<char> all = world.gather_fixed(bytes);
  std::vector<BackendRankFigures> ranks;
  for (std::size_t r = 0; r * sizeof me < all.size(); ++r) {
    RankIdentity id;
    std::memcpy(&id, all.data() + r * sizeof me, sizeof me);
    ranks.push_back({.rank = static_cast<int>(r), .host = id.host, .pid = static_cast<long>(id.pid),
                     .threads = id.threads});
  }
  return ranks;
}

// Step 1's agreement: every rank's set-up outcome to rank 0, and whether all may go on. Rank 0
// learns the first failure (its own first, else the lowest failing rank's, named).
std::optional<Failure> agree_on_setup(const mpi::World& world, const Failure& mine,
                                      const std::vector<BackendRankFigures>& ranks) {
  const std::vector<std::int64_t> codes = world.gather_int64(mine.code);
  if (world.rank() != 0 && mine.code != 0) world.send(0, mpi::kSetupStatus, encode_failure(mine));
  std::optional<Failure> first;
  if (world.rank() == 0) {
    if (mine.code != 0) first = mine;
    for (int r = 1; r < world.size(); ++r) {
      if (codes[r] == 0) continue;
      Failure f = decode_failure(world.receive(r, mpi::kSetupStatus));
      if (!first) first = Failure{f.code, fmt::format("rank {} (on {}): {}", r, ranks[r].host, f.message)};
    }
  }
  const bool go = world.broadcast_int64(world.rank() == 0 ? (first ? 0 : 1) : 0) == 1;
  if (go) return std::nullopt;
  return first ? first : std::optional<Failure>(Failure{1, ""});
}

// Step 2 on any rank: the single process's produce/consume, with sets from rank 0. Never throws:
// its error goes to rank 0 in kDone.
void work(const mpi::World& world, BackendInputs& inputs, bool overlap, const std::function<bool()>& stop_requested) {
  Failure failure;
  try {
    const auto produce = [&](const std::function<bool()>& stop) -> std::optional<ReconstructedSet> {
      if (stop() || stop_requested()) return std::nullopt;
      world.send(0, mpi::kRequest, {});
      const std::int64_t index = world.receive_int64(0, mpi::kAssign);
      if (index < 0) return std::nullopt;
      return inputs.reconstruct(static_cast<std::uint64_t>(index));
    };
    const auto consume = [&](ReconstructedSet& r) -> bool {
      if (stop_requested()) return false;
      piv::CorrelationReport report;
      FinishedSet set;
      set.result = inputs.processor.correlate(r, report);
      set.vectors = report.valid + report.replaced + report.invalid;
      set.valid_fraction = report.valid_fraction();
      world.send(0, mpi::kResult, encode_finished_set(set));
      return !stop_requested();
    };
    if (overlap) {
      TwoStagePipeline<ReconstructedSet> stages(1);
      stages.run(produce, consume);
    } else {
      const std::function<bool()> never = [] { return false; };
      while (auto r = produce(never))
        if (!consume(*r)) break;
    }
  } catch (...) {
    failure = failure_of(std::current_exception());
  }
  world.send(0, mpi::kDone, encode_failure(failure));
}

// Step 2 on rank 0's main thread: hands out the sets, writes the results, until every worker
// (rank 0's own thread included) has ended. Returns the first failure, if any.
struct Coordinator {
  const mpi::World& world;
  storage::ResultsWriter& writer;
  const std::vector<std::uint64_t>& todo;
  const BackendHooks& hooks;
  BackendReport& report;
  double valid_sum = 0.0;

  std::optional<Failure> run(const std::function<bool()>& stop_requested) {
    const auto started = Clock::now();
    std::size_t next = 0;
    int ended = 0;
    bool stopping = false;
    std::optional<Failure> first;
    const auto fail = [&](Failure f) {
      if (!first) first = std::move(f);
      stopping = true;
    };
    while (ended < world.size()) {
      if (!stopping && stop_requested()) stopping = true;
      std::optional<mpi::Message> m = world.try_receive();
      if (!m) {
        // Nothing waiting. A blocking MPI receive would spin a core at 100 % (OpenMPI polls),
        // taking it from the worker thread on this rank, and would not see Ctrl-C; a set takes
        // seconds, so looking again after a millisecond costs nothing.
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      switch (m->tag) {
        case mpi::kRequest: {
          const std::int64_t index = !stopping && next < todo.size() ? static_cast<std::int64_t>(todo[next++]) : -1;
          world.send_int64(m->source, mpi::kAssign, index);
          break;
        }
        case mpi::kResult:
          try {
            add(m->source, decode_finished_set(m->bytes), started);
          } catch (...) {
            fail(failure_of(std::current_exception()));  // e.g. a full disk: no more sets
          }
          break;
        case mpi::kDone: {
          ++ended;
          Failure f = decode_failure(m->bytes);
          if (f.code != 0)
            fail({f.code, m->source == 0 ? f.message
                                         : fmt::format("rank {} (on {}): {}", m->source,
                                                       report.ranks[m->source].host, f.message)});
          break;
        }
        default:
          break;
      }
    }
    return first;
  }

  void add(int rank, const FinishedSet& set, Clock::time_point started) {
    writer.add(set.result);
    valid_sum += set.valid_fraction;
    ++report.sets_processed;
    BackendRankFigures& figures = report.ranks[rank];
    ++figures.sets;
    figures.busy_seconds += set.result.seconds;
    const double elapsed = std::chrono::duration<double>(Clock::now() - started).count();
    if (hooks.set_done)
      hooks.set_done({.index = set.result.set_index,
                      .vectors = set.vectors,
                      .valid_fraction = set.valid_fraction,
                      .seconds = set.result.seconds,
                      .rank = rank,
                      .rank_sets = figures.sets,
                      .rank_sets_per_second = elapsed > 0 ? figures.sets / elapsed : 0.0});
  }
};

}  // namespace

BackendReport run_backend_on_mpi(const fs::path& session_path, const BackendOptions& given,
                                 const BackendHooks& hooks) {
  const auto started = Clock::now();
  const auto stop_requested = [&] { return hooks.should_stop && hooks.should_stop(); };
  const auto notice = [&](const std::string& text) {
    if (hooks.notice) hooks.notice(text);
  };
  mpi::World world;
  const bool root = world.rank() == 0;
  BackendOptions options = given;
  options.threads = threads_for_rank(given.threads, world.local_size());
  std::vector<BackendRankFigures> ranks = gather_identities(world, options.threads);

  // Step 1: set-up on every rank, the results file on rank 0, then the agreement.
  std::unique_ptr<BackendInputs> inputs;
  std::unique_ptr<storage::ResultsWriter> writer;
  std::vector<std::uint64_t> todo;
  Failure setup_failure;
  try {
    options.validate();
    inputs = std::make_unique<BackendInputs>(session_path, options);
    if (root) {
      writer = open_results(*inputs);
      todo = sets_to_do(*writer, inputs->sets_asked);
    }
    inputs->prepare_preprocessing();
  } catch (...) {
    setup_failure = failure_of(std::current_exception());
  }
  if (const std::optional<Failure> failed = agree_on_setup(world, setup_failure, ranks)) {
    world.mark_exchange_complete();
    if (root) raise(*failed);
    return BackendReport{.worker_rank = true};  // rank 0 reports the failure
  }

  const recon::ReconstructionInput& input = inputs->processor.input();
  const bool overlap =
      !options.sequential && overlap_fits(input.grid, available_memory_bytes() / std::max(1, world.local_size()));
  if (!root) {
    work(world, *inputs, overlap, stop_requested);
    world.mark_exchange_complete();
    return BackendReport{.worker_rank = true};
  }

  BackendReport report = start_report(*inputs, *writer);
  report.ranks = std::move(ranks);
  report.overlapped = overlap;
  notice(fmt::format("MPI: {} ranks; rank 0 owns {} and hands out the sets; every rank, rank 0 included, "
                     "processes them",
                     world.size(), options.out.string()));
  for (const BackendRankFigures& r : report.ranks)
    notice(fmt::format("rank {}: pid {} on {}, {} threads", r.rank, r.pid, r.host, r.threads));
  if (writer->resumed_sets() > 0)
    notice(fmt::format("resuming {}: {} sets already finished, {} to do", options.out.string(), writer->resumed_sets(),
                       todo.size()));
  notice(fmt::format("processing {} sets of {} with {} on a {} x {} x {} grid ({}), {} cameras, {}", todo.size(),
                     session_path.string(), inputs->processor.reconstruction().algorithm, input.grid.nx, input.grid.ny,
                     input.grid.nz, inputs->processor.cameras().source, input.cameras.size(),
                     overlap ? "reconstruction and correlation overlapped on each rank" : "one set at a time per rank"));
  for (const std::string& warning : inputs->processor.cameras().warnings) notice("warning: " + warning);
  if (hooks.started) hooks.started(todo.size());

  // Step 2: rank 0's worker thread beside the coordinator.
  std::thread local_worker([&] { work(world, *inputs, overlap, stop_requested); });
  Coordinator coordinator{world, *writer, todo, hooks, report};
  std::optional<Failure> failed;
  try {
    failed = coordinator.run(stop_requested);
  } catch (const std::exception& e) {
    // MPI itself failed: the exchange cannot be finished, and the worker thread still uses what
    // this function owns, so the whole job ends here. The file holds every set written so far.
    notice(fmt::format("error: {}; ending the MPI job ('{}' holds {} sets; run the same command again to resume)",
                       e.what(), options.out.string(), writer->set_count()));
    world.abort_job(1);
  }
  local_worker.join();
  world.mark_exchange_complete();

  report.sets_in_file = writer->set_count();
  report.mean_valid_fraction = report.sets_processed > 0 ? coordinator.valid_sum / report.sets_processed : 0.0;
  if (failed) raise(*failed);  // the file keeps every finished set; the destructor closes it
  if (stop_requested()) {
    report.interrupted = true;
    report.seconds = std::chrono::duration<double>(Clock::now() - started).count();
    return report;
  }
  // Step 3.
  finish_results(*writer, options, report);
  report.seconds = std::chrono::duration<double>(Clock::now() - started).count();
  return report;
}

}  // namespace tomorig::pipeline

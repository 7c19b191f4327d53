// `mpirun -n 3 tomorig process` (issue 22) end to end, as a user runs it: the results file of three
// ranks equals the single process's bit for bit (every set's vectors, flags, peaks, and the stored
// statistics); rank 0 prints the ranks, per-set lines with the rank, progress with sets/s and ETA,
// and a per-rank summary; a job whose worker rank is killed (SIGKILL) leaves a valid file, and the
// same command started again finishes the other sets, none twice, to the same results.
//
// Both runs use --threads 1: the back-end splits its floating-point sums over the OpenMP threads,
// so a different thread count changes the last bits (docs/correlation.md, "Processing on a cluster").
// Small (8 sets, a 64 x 64 x 96 voxel sub-grid, 3 x 3 x 5 vectors) so that it takes seconds.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.h"
#include "cli_runner.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {
namespace fs = std::filesystem;

constexpr int kSets = 8;
constexpr const char* kMpirun = "/usr/bin/mpirun";  // Debian 12's openmpi-bin

std::vector<std::string> process_args(const std::string& session, const fs::path& out) {
  return {"process", "--session", session, "--calib", "truth", "--grid", "64,64,96,0.0195", "--window", "32,32,32",
          "--overlap", "0.5", "--deformation-passes", "1", "--threads", "1", "-o", out.string()};
}

// mpirun as the docs show it; --allow-run-as-root because CI and the build machine run as root.
std::vector<std::string> mpirun_args(int ranks, const std::vector<std::string>& tomorig_args) {
  std::vector<std::string> args{"--allow-run-as-root", "--oversubscribe", "-n", std::to_string(ranks), TOMORIG_BINARY};
  args.insert(args.end(), tomorig_args.begin(), tomorig_args.end());
  return args;
}

std::vector<char> stored_bytes(const fs::path& path, const char* dataset) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0) << path;
  const hid_t d = H5Dopen2(file, dataset, H5P_DEFAULT);
  EXPECT_GE(d, 0) << dataset;
  const hid_t space = H5Dget_space(d);
  std::vector<char> bytes(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)) * sizeof(double));
  EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()), 0);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(file);
  return bytes;
}

template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// Every set of `reference` is in `results` with the same bits, and so are the stored statistics.
void expect_identical_results(const fs::path& reference, const fs::path& results) {
  const storage::ResultsReader ref(reference), got(results);
  ASSERT_EQ(got.set_indices(), ref.set_indices());
  for (const std::uint64_t i : ref.set_indices()) {
    const storage::SetResult a = ref.read_set(i), b = got.read_set(i);
    EXPECT_EQ(a.dt_ns, b.dt_ns) << "set " << i;
    EXPECT_TRUE(same_bits(a.field.displacement, b.field.displacement)) << "set " << i << " displacement";
    EXPECT_TRUE(same_bits(a.field.status, b.field.status)) << "set " << i << " status";
    EXPECT_TRUE(same_bits(a.field.peak, b.field.peak)) << "set " << i << " peak";
  }
  for (const char* d : {"/statistics/mean_displacement_voxel", "/statistics/mean_velocity_m_s",
                        "/statistics/rms_velocity_m_s", "/statistics/reynolds_stress_m2_s2"})
    EXPECT_TRUE(stored_bytes(reference, d) == stored_bytes(results, d)) << d;
}

class ProcessMpi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!available()) return;
    dir_ = std::make_unique<TempDir>();
    session_ = (*dir_ / "s.h5").string();
    const CliResult sim =
        run_tomorig("simulate --sets " + std::to_string(kSets) + " --ppp 0.05 --seed 7 -o " + shell_quoted(session_));
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
    if (!TOMORIG_WITH_MPI) GTEST_SKIP() << "tomorig built without MPI (libopenmpi-dev missing)";
    if (!fs::exists(kMpirun)) GTEST_SKIP() << "mpirun missing (openmpi-bin)";
  }
  static bool available() { return tomorig_built() && TOMORIG_WITH_MPI && fs::exists(kMpirun); }
  // The single process's results, made at first use (ctest runs each test in its own process).
  static fs::path reference() {
    const fs::path path = *dir_ / "single.h5";
    if (single_err_.empty()) {
      TomorigProcess single(process_args(session_, path));
      EXPECT_EQ(single.wait(), 0) << single.err();
      single_err_ = single.err();
    }
    return path;
  }
  static std::unique_ptr<TempDir> dir_;
  static std::string session_, single_err_;
};
std::unique_ptr<TempDir> ProcessMpi::dir_;
std::string ProcessMpi::session_, ProcessMpi::single_err_;

TEST_F(ProcessMpi, ThreeRanksGiveTheSingleProcessResultsBitForBit) {
  const fs::path single = reference();
  // Without mpirun nothing of MPI shows: the plain command is unchanged.
  EXPECT_EQ(single_err_.find("MPI"), std::string::npos) << single_err_;
  EXPECT_EQ(single_err_.find("on rank"), std::string::npos) << single_err_;

  const fs::path out = *dir_ / "three.h5";
  std::vector<std::string> args = process_args(session_, out);
  args.push_back("--json");
  TomorigProcess job(mpirun_args(3, args), kMpirun);
  ASSERT_EQ(job.wait(), 0) << job.err();
  const std::string& err = job.err();
  EXPECT_NE(err.find("MPI: 3 ranks"), std::string::npos) << err;
  for (const char* rank : {"rank 0: pid", "rank 1: pid", "rank 2: pid"}) EXPECT_NE(err.find(rank), std::string::npos) << err;
  EXPECT_NE(err.find(" done on rank "), std::string::npos) << err;
  EXPECT_NE(err.find(std::to_string(kSets) + "/" + std::to_string(kSets) + " sets"), std::string::npos) << err;
  EXPECT_NE(err.find("sets/s  ETA"), std::string::npos) << err;

  const nlohmann::json summary = nlohmann::json::parse(job.out());  // rank 0 alone prints it
  EXPECT_EQ(summary["sets_in_file"], kSets);
  EXPECT_EQ(summary["sets_processed"], kSets);
  ASSERT_EQ(summary["mpi_ranks"].size(), 3u);
  std::uint64_t sets = 0;
  for (const nlohmann::json& r : summary["mpi_ranks"]) {
    sets += r["sets"].get<std::uint64_t>();
    EXPECT_GT(r["pid"].get<long>(), 0);
    EXPECT_EQ(r["threads"], 1);
  }
  EXPECT_EQ(sets, static_cast<std::uint64_t>(kSets));  // each set done once
  expect_identical_results(single, out);
}

TEST_F(ProcessMpi, AJobWithAKilledRankResumesToTheSameResults) {
  const fs::path out = *dir_ / "killed.h5";
  const std::vector<std::string> args = mpirun_args(3, process_args(session_, out));
  {
    TomorigProcess job(args, kMpirun);
    const std::optional<std::string> rank1 = job.wait_for_line("rank 1: pid ");
    ASSERT_TRUE(rank1) << job.err();
    long pid = 0;
    ASSERT_EQ(std::sscanf(rank1->c_str() + rank1->find("pid "), "pid %ld", &pid), 1) << *rank1;
    ASSERT_TRUE(job.wait_for_line(" done on rank ")) << job.err();
    ASSERT_TRUE(job.wait_for_line(" done on rank ")) << job.err();
    ASSERT_EQ(kill(static_cast<pid_t>(pid), SIGKILL), 0);  // 6 sets still to go: rank 1 is at work
    EXPECT_NE(job.wait(), 0) << job.err();  // OpenMPI ends the whole job when a rank dies
  }
  const std::vector<std::uint64_t> first = storage::ResultsReader(out).set_indices();  // a valid file
  ASSERT_GE(first.size(), 2u);
  ASSERT_LT(first.size(), static_cast<std::size_t>(kSets));
  std::vector<std::string> stamps;
  for (const std::uint64_t i : first) stamps.push_back(storage::ResultsReader(out).read_set(i).completed_utc);

  TomorigProcess again(args, kMpirun);  // the same command, as a Slurm requeue would run it
  ASSERT_EQ(again.wait(), 0) << again.err();
  EXPECT_NE(again.err().find("resuming " + out.string() + ": " + std::to_string(first.size()) + " sets already finished"),
            std::string::npos)
      << again.err();
  for (const std::uint64_t i : first)  // finished sets were not processed again
    EXPECT_EQ(again.err().find("set " + std::to_string(i) + " done"), std::string::npos) << again.err();
  const storage::ResultsReader done(out);
  for (std::size_t n = 0; n < first.size(); ++n) EXPECT_EQ(done.read_set(first[n]).completed_utc, stamps[n]);
  expect_identical_results(reference(), out);
}

// Bad input found on every rank (a bad option) or on rank 0 alone (a results file of another
// session): rank 0 says it once, the job exits 2 as a single process would, nothing is processed.
TEST_F(ProcessMpi, BadInputIsReportedOnceByRankZeroWithExitCode2) {
  std::vector<std::string> bad_dt = process_args(session_, *dir_ / "bad.h5");
  bad_dt.insert(bad_dt.end(), {"--dt-ns", "-5"});
  TomorigProcess dt_job(mpirun_args(3, bad_dt), kMpirun);
  EXPECT_EQ(dt_job.wait(), 2) << dt_job.err();
  const std::string dt_message = "error: --dt -5ns must be > 0";
  const std::size_t first = dt_job.err().find(dt_message);
  ASSERT_NE(first, std::string::npos) << dt_job.err();
  EXPECT_EQ(dt_job.err().find(dt_message, first + 1), std::string::npos) << dt_job.err();
  EXPECT_FALSE(fs::exists(*dir_ / "bad.h5"));

  const std::string other = (*dir_ / "other.h5").string();
  const fs::path foreign_file = *dir_ / "foreign.h5";  // one set of another session
  ASSERT_EQ(run_tomorig("simulate --sets 1 --ppp 0.05 --seed 8 -o " + shell_quoted(other)).exit_code, 0);
  TomorigProcess one(process_args(other, foreign_file));
  ASSERT_EQ(one.wait(), 0) << one.err();
  TomorigProcess foreign(mpirun_args(3, process_args(session_, foreign_file)), kMpirun);
  EXPECT_EQ(foreign.wait(), 2) << foreign.err();
  EXPECT_NE(foreign.err().find("belongs to another session"), std::string::npos) << foreign.err();
  EXPECT_EQ(foreign.err().find(" done"), std::string::npos) << foreign.err();
  EXPECT_EQ(storage::ResultsReader(foreign_file).set_indices().size(), 1u);  // untouched
}

// A set that cannot be processed (a frame lost in the recording) on whichever rank gets it: rank 0
// reports that error, naming the set, and exits 2 as a single process would; the ranks stop taking
// sets, and the file keeps every set finished before, valid for a run over the repaired session.
TEST_F(ProcessMpi, ASetThatFailsOnAnyRankStopsTheJobWithItsError) {
  const std::string broken = (*dir_ / "lost-frame.h5").string();
  {  // the session of the suite with frame A of the second camera of set 5 lost
    const storage::SessionReader from(session_);
    storage::SessionWriter to(broken, from.info());
    for (std::uint64_t i = 0; i < from.set_count(); ++i) {
      FrameSet set = from.read_set(i);
      if (i == 5) set.cameras[1].a.image = Image();
      to.append(set);
    }
    to.write_truth(from.truth());
    for (std::uint64_t i = 0; i < from.set_count(); ++i) to.write_truth_set(i, from.truth_set(i));
    to.finish();
  }
  const fs::path out = *dir_ / "lost-frame-results.h5";
  TomorigProcess job(mpirun_args(3, process_args(broken, out)), kMpirun);
  EXPECT_EQ(job.wait(), 2) << job.err();
  EXPECT_NE(job.err().find("set 5: frame A of camera"), std::string::npos) << job.err();
  EXPECT_NE(job.err().find("is missing"), std::string::npos) << job.err();
  const std::vector<std::uint64_t> kept = storage::ResultsReader(out).set_indices();  // valid
  EXPECT_EQ(std::count(kept.begin(), kept.end(), 5u), 0);
  EXPECT_LT(kept.size(), static_cast<std::size_t>(kSets));
}

}  // namespace
}  // namespace tomorig::testing

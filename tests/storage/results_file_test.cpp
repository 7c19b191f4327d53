// Results files: round trip of vector fields, ensemble statistics with physical units, resume,
// refusal of another session's file, and a write failure that must lose no finished set.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "temp_dir.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::testing {
namespace {
using storage::ResultsInfo;
using storage::ResultsReader;
using storage::ResultsWriter;
using storage::SetResult;

constexpr double kVoxelMm = 0.02;
constexpr std::int64_t kDtNs = 1000;  // 1 voxel per dt = 0.02 mm / 1 us = 20 m/s

ResultsInfo info(const std::string& identity = "session-1") {
  return {.session_path = "s.h5", .session_identity = identity, .parameters_json = R"({"window":32})",
          .voxel_size_mm = kVoxelMm};
}

// A 4 x 3 x 2 field with displacement (u, 2u, -u) everywhere, node 0 invalid, node 1 replaced.
SetResult set_with(std::uint64_t index, float u) {
  SetResult r;
  r.set_index = index;
  r.dt_ns = kDtNs;
  r.field = VectorField(4, 3, 2);
  r.field.origin = {-1.0, -0.5, 0.25};
  r.field.spacing = {0.16, 0.16, 0.32};
  for (std::size_t n = 0; n < r.field.count(); ++n) {
    r.field.displacement[n] = {u, 2 * u, -u};
    r.field.status[n] = VectorStatus::valid;
    r.field.peak[n] = 0.5f + 0.01f * static_cast<float>(n);
  }
  r.field.status[0] = VectorStatus::invalid;
  r.field.status[1] = VectorStatus::replaced;
  r.report_json = R"({"note":"test"})";
  r.seconds = 1.5;
  return r;
}

TEST(ResultsFile, RoundTripsFieldsFlagsPeaksAndNodePositions) {
  TempDir dir;
  const auto path = dir / "r.h5";
  {
    ResultsWriter w(path, info());
    w.add(set_with(3, 1.0f));
    w.add(set_with(5, 3.0f));
  }
  const ResultsReader r(path);
  EXPECT_EQ(r.info().session_identity, "session-1");
  EXPECT_EQ(r.info().parameters_json, R"({"window":32})");
  EXPECT_FALSE(r.info().software_version.empty());
  ASSERT_EQ(r.set_indices(), (std::vector<std::uint64_t>{3, 5}));
  const SetResult s = r.read_set(5);
  EXPECT_EQ(s.dt_ns, kDtNs);
  EXPECT_EQ(s.field.nx, 4);
  EXPECT_EQ(s.field.nz, 2);
  EXPECT_DOUBLE_EQ(s.field.origin.x, -1.0);
  EXPECT_DOUBLE_EQ(s.field.spacing.z, 0.32);
  EXPECT_FLOAT_EQ(s.field.displacement[7].y, 6.0f);
  EXPECT_EQ(s.field.status[0], VectorStatus::invalid);
  EXPECT_EQ(s.field.status[1], VectorStatus::replaced);
  EXPECT_FLOAT_EQ(s.field.peak[7], 0.57f);
  EXPECT_FALSE(s.completed_utc.empty());
  EXPECT_EQ(s.report_json, R"({"note":"test"})");
  EXPECT_THROW(r.read_set(4), Error);

  const std::string xdmf = read_text_file(ResultsWriter::sidecar_path(path));
  EXPECT_NE(xdmf.find("r.h5:/sets/000005/velocity_m_s"), std::string::npos);
  EXPECT_NE(xdmf.find("r.h5:/statistics/mean_velocity_m_s"), std::string::npos);
  EXPECT_NE(xdmf.find("Dimensions=\"2 3 4 3\""), std::string::npos);
}

TEST(ResultsFile, StatisticsInMetresPerSecond) {
  TempDir dir;
  const auto path = dir / "r.h5";
  {
    ResultsWriter w(path, info());
    w.add(set_with(0, 1.0f));
    w.add(set_with(1, 3.0f));
  }
  const storage::EnsembleStatistics s = ResultsReader(path).statistics();
  EXPECT_EQ(s.sets, 2u);
  EXPECT_EQ(s.valid_count[0], 0u);  // invalid in both sets
  EXPECT_TRUE(std::isnan(s.mean_velocity[0].x));
  EXPECT_EQ(s.valid_count[1], 2u);  // replaced vectors count
  // u = 1 and 3 voxel -> 20 and 60 m/s: mean 40, fluctuation +-20 m/s.
  EXPECT_NEAR(s.mean_displacement_voxel[5].x, 2.0, 1e-12);
  EXPECT_NEAR(s.mean_velocity[5].x, 40.0, 1e-9);
  EXPECT_NEAR(s.mean_velocity[5].y, 80.0, 1e-9);
  EXPECT_NEAR(s.rms_velocity[5].x, 20.0, 1e-9);
  EXPECT_NEAR(s.rms_velocity[5].z, 20.0, 1e-9);
  EXPECT_NEAR(s.reynolds_stress[5][0], 400.0, 1e-6);   // u'u'
  EXPECT_NEAR(s.reynolds_stress[5][3], 800.0, 1e-6);   // u'v' = (20)(40)
  EXPECT_NEAR(s.reynolds_stress[5][4], -400.0, 1e-6);  // u'w'
  EXPECT_NEAR(s.reynolds_stress[5][5], -800.0, 1e-6);  // v'w'
}

TEST(ResultsFile, ResumesFinishedSetsAndRefusesAnotherSession) {
  TempDir dir;
  const auto path = dir / "r.h5";
  ResultsWriter(path, info()).add(set_with(0, 1.0f));
  const std::string stamp = ResultsReader(path).read_set(0).completed_utc;

  ResultsWriter resumed(path, info());
  EXPECT_EQ(resumed.resumed_sets(), 1u);
  EXPECT_TRUE(resumed.has_set(0));
  EXPECT_FALSE(resumed.has_set(1));
  EXPECT_THROW(resumed.add(set_with(0, 2.0f)), Error);  // already there
  resumed.add(set_with(1, 2.0f));
  EXPECT_EQ(ResultsReader(path).read_set(0).completed_utc, stamp);  // kept, not recomputed

  try {
    ResultsWriter other(path, info("session-2"));
    FAIL() << "another session's results file was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("belongs to another session"), std::string::npos) << e.what();
  }
  ResultsInfo changed = info();
  changed.parameters_json = R"({"window":16})";
  EXPECT_THROW(ResultsWriter(path, changed), Error);
  ResultsWriter fresh(path, info("session-2"), {.overwrite = true});
  EXPECT_EQ(fresh.resumed_sets(), 0u);
}

TEST(ResultsFile, RefusesBadSets) {
  TempDir dir;
  ResultsWriter w(dir / "r.h5", info());
  SetResult no_dt = set_with(0, 1.0f);
  no_dt.dt_ns = 0;
  EXPECT_THROW(w.add(no_dt), Error);
  w.add(set_with(1, 1.0f));
  SetResult other_shape = set_with(2, 1.0f);
  other_shape.field = VectorField(2, 2, 2);
  EXPECT_THROW(w.add(other_shape), Error);
  EXPECT_EQ(ResultsReader(dir / "r.h5").set_indices().size(), 1u);
  EXPECT_THROW(ResultsReader(dir / "missing.h5"), Error);
  EXPECT_THROW(ResultsWriter(dir / "r.h5", {.session_identity = "x", .voxel_size_mm = 0}), Error);
}

// A real write failure part-way through the file: the file-size limit (what a full disk looks
// like to the writer: write() fails) is set just above the size of the file with one set.
TEST(ResultsFile, WriteFailureMidFileLosesNoFinishedSet) {
  TempDir dir;
  const auto path = dir / "r.h5";
  ResultsWriter w(path, info());
  w.add(set_with(0, 1.0f));
  const auto size = std::filesystem::file_size(path);

  struct sigaction ignore {}, previous {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &ignore, &previous);
  rlimit old{};
  getrlimit(RLIMIT_FSIZE, &old);
  rlimit limited = old;
  limited.rlim_cur = size + 512;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  bool threw = false;
  try {
    SetResult big = set_with(1, 2.0f);
    w.add(std::move(big));
  } catch (const Error& e) {
    threw = true;
    EXPECT_EQ(e.kind(), ErrorKind::runtime);
    EXPECT_NE(std::string(e.what()).find("unchanged"), std::string::npos) << e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  sigaction(SIGXFSZ, &previous, nullptr);
  EXPECT_TRUE(threw);
  EXPECT_FALSE(std::filesystem::exists(dir / "r.h5.partial"));
  const ResultsReader r(path);
  EXPECT_EQ(r.set_indices(), std::vector<std::uint64_t>{0});
  EXPECT_FLOAT_EQ(r.read_set(0).field.displacement[3].x, 1.0f);
  // The writer stays usable once space is back.
  w.add(set_with(1, 2.0f));
  EXPECT_EQ(ResultsReader(path).set_indices().size(), 2u);
}

}  // namespace
}  // namespace tomorig::testing

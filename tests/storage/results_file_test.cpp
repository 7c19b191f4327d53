// Results files: round trip of vector fields, ensemble statistics with physical units, resume,
// refusal of another session's file, and a write failure that must lose no finished set.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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
  // Set 5 is row 1 of the /sets datasets: a hyperslab starting there.
  EXPECT_NE(xdmf.find("set 000005"), std::string::npos);
  EXPECT_NE(xdmf.find("1 0 0 0 0 1 1 1 1 1 1 2 3 4 3</DataItem>"), std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find("r.h5:/sets/velocity_m_s"), std::string::npos);
  EXPECT_NE(xdmf.find("r.h5:/statistics/mean_velocity_m_s"), std::string::npos);
  EXPECT_NE(xdmf.find("Dimensions=\"2 3 4 3\""), std::string::npos);
  // Issue 23: Xdmf3 (ParaView's Xdmf3ReaderS/T) loads ItemType="HyperSlab" items as empty arrays;
  // it reads the row from the HDF5 path's hyperslab suffix (start:stride:count:dataspace) instead.
  EXPECT_EQ(xdmf.find("ItemType=\"HyperSlab\""), std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find("r.h5:/sets/velocity_m_s|1 0 0 0 0:1 1 1 1 1:1 2 3 4 3:2 2 3 4 3\n"), std::string::npos) << xdmf;
}

// Issue 23: `nodes` was float64, so numpy's reshape(nz, ny, nx, 3) with it raised a TypeError.
TEST(ResultsFile, NodeCountsAreIntegersAsAnOutsideToolReadsThem) {
  TempDir dir;
  const auto path = dir / "r.h5";
  {
    ResultsWriter w(path, info());
    w.add(set_with(0, 1.0f));
  }
  const SetResult expected = ResultsReader(path).read_set(0);
  for (const char* group : {"/sets", "/statistics"}) {
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    const hid_t attr = H5Aopen_by_name(file, group, "nodes", H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(attr, 0) << group;
    const hid_t type = H5Aget_type(attr);
    EXPECT_EQ(H5Tget_class(type), H5T_INTEGER) << group;
    int nodes[3] = {0, 0, 0};
    EXPECT_GE(H5Aread(attr, H5T_NATIVE_INT, nodes), 0);
    EXPECT_EQ(nodes[0], expected.field.nx) << group;
    EXPECT_EQ(nodes[1], expected.field.ny) << group;
    EXPECT_EQ(nodes[2], expected.field.nz) << group;
    H5Tclose(type);
    H5Aclose(attr);
    H5Fclose(file);
  }
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

  {
    ResultsWriter resumed(path, info());
    EXPECT_EQ(resumed.resumed_sets(), 1u);
    EXPECT_TRUE(resumed.has_set(0));
    EXPECT_FALSE(resumed.has_set(1));
    EXPECT_THROW(resumed.add(set_with(0, 2.0f)), Error);  // already there
    resumed.add(set_with(1, 2.0f));
    EXPECT_EQ(ResultsReader(path).read_set(0).completed_utc, stamp);  // kept, not recomputed
  }  // one writer per file: the next ones open it after this one is done

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

// A larger field (40 x 40 x 20 nodes, ~0.9 MB per set in the file) whose x displacement is
// the set index, so that every set can be recognised after a crash.
SetResult big_set(std::uint64_t index) {
  SetResult r;
  r.set_index = index;
  r.dt_ns = kDtNs;
  r.field = VectorField(40, 40, 20);
  r.field.spacing = {0.1, 0.1, 0.1};
  for (std::size_t n = 0; n < r.field.count(); ++n) {
    r.field.displacement[n] = {static_cast<float>(index), 0.5f, -0.25f};
    r.field.status[n] = VectorStatus::valid;
    r.field.peak[n] = 0.7f;
  }
  r.report_json = "{\"set\":" + std::to_string(index) + "}";
  return r;
}

// A real write failure part-way through a set: the file-size limit (what a full disk looks
// like to the writer: write() fails) is set to the size of the file with one set.
TEST(ResultsFile, WriteFailureMidFileLosesNoFinishedSet) {
  TempDir dir;
  const auto path = dir / "r.h5";
  ResultsWriter w(path, info());
  w.add(big_set(0));
  const auto size = std::filesystem::file_size(path);

  struct sigaction ignore {}, previous {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &ignore, &previous);
  rlimit old{};
  getrlimit(RLIMIT_FSIZE, &old);
  rlimit limited = old;
  limited.rlim_cur = size;  // the set is appended in place: growing the file by a set fails
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  bool threw = false;
  try {
    w.add(big_set(1));
  } catch (const Error& e) {
    threw = true;
    EXPECT_EQ(e.kind(), ErrorKind::runtime);
    EXPECT_NE(std::string(e.what()).find("holds the 1 sets finished before"), std::string::npos) << e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  sigaction(SIGXFSZ, &previous, nullptr);
  EXPECT_TRUE(threw);
  EXPECT_FALSE(w.has_set(1));
  EXPECT_FALSE(std::filesystem::exists(dir / "r.h5.partial"));
  {
    const ResultsReader r(path);
    EXPECT_EQ(r.set_indices(), std::vector<std::uint64_t>{0});
    EXPECT_FLOAT_EQ(r.read_set(0).field.displacement[3].y, 0.5f);
  }
  // The writer stays usable once space is back.
  w.add(big_set(1));
  w.close();
  const ResultsReader r(path);
  EXPECT_EQ(r.set_indices(), (std::vector<std::uint64_t>{0, 1}));
  EXPECT_FLOAT_EQ(r.read_set(1).field.displacement[3].x, 1.0f);
}

// The disk fills between the writer's room check and HDF5's write (another program, say): the
// write fails inside HDF5, the file is abandoned, and the process must still end normally
// (HDF5 1.10 crashed at exit closing such a file) with every finished set readable.
TEST(ResultsFile, DiskFillingAfterTheRoomCheckLosesNoSetAndExitsCleanly) {
  TempDir dir;
  const auto path = dir / "r.h5";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigaction(SIGXFSZ, &ignore, nullptr);
    storage::ResultsWriterOptions options;
    bool fill = false;
    options.after_room_check = [&] {
      if (!fill) return;
      rlimit limited{};
      getrlimit(RLIMIT_FSIZE, &limited);
      limited.rlim_cur = std::filesystem::file_size(path);  // not one more byte
      setrlimit(RLIMIT_FSIZE, &limited);
    };
    int code = 0;
    try {
      ResultsWriter w(path, info(), options);
      w.add(big_set(0));
      fill = true;
      try {
        w.add(big_set(1));
        code = 3;  // the write should have failed
      } catch (const Error& e) {
        if (std::string(e.what()).find("holds the 1 sets finished before") == std::string::npos) code = 4;
      }
    } catch (...) {
      code = 5;
    }
    std::exit(code);  // runs the atexit handlers, HDF5's among them
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the writer's process died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const ResultsReader r(path);
  EXPECT_EQ(r.set_indices(), std::vector<std::uint64_t>{0});
  EXPECT_FLOAT_EQ(r.read_set(0).field.displacement[3].y, 0.5f);
}

// File address and bytes of set 0's displacement chunk (one set per chunk).
std::pair<haddr_t, std::string> first_chunk(const std::filesystem::path& path) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0);
  const hid_t d = H5Dopen2(file, "/sets/displacement_voxel", H5P_DEFAULT);
  EXPECT_GE(d, 0);
  const hsize_t origin[5] = {0, 0, 0, 0, 0};
  unsigned mask = 0;
  haddr_t address = HADDR_UNDEF;
  hsize_t size = 0;
  EXPECT_GE(H5Dget_chunk_info_by_coord(d, origin, &mask, &address, &size), 0);
  H5Dclose(d);
  H5Fclose(file);
  std::string bytes(size, '\0');
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(address));
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  return {address, bytes};
}

// O(set) appends: each set grows the file by about one set's size whatever the number of sets
// before it, and set 0's data stays where and as it was written.
TEST(ResultsFile, AppendingASetDoesNotRewriteEarlierSets) {
  TempDir dir;
  const auto path = dir / "r.h5";
  const double set_bytes = 40.0 * 40 * 20 * (12 + 12 + 1 + 4);
  ResultsWriter w(path, info());
  w.add(big_set(0));
  const auto [address, bytes] = first_chunk(path);
  ASSERT_NE(address, HADDR_UNDEF);
  std::vector<double> growth;
  auto size = std::filesystem::file_size(path);
  for (std::uint64_t i = 1; i <= 8; ++i) {
    w.add(big_set(i));
    const auto now = std::filesystem::file_size(path);
    growth.push_back(static_cast<double>(now) - static_cast<double>(size));
    size = now;
  }
  for (const double g : growth) {
    EXPECT_GT(g, 0.9 * set_bytes);
    EXPECT_LT(g, 1.2 * set_bytes);  // a rewrite would grow by all the sets before
  }
  const auto [address_after, bytes_after] = first_chunk(path);
  EXPECT_EQ(address_after, address);
  EXPECT_TRUE(bytes_after == bytes);
  w.close();
  const ResultsReader r(path);
  EXPECT_EQ(r.format_version(), 2);
  EXPECT_EQ(r.set_indices().size(), 9u);
  EXPECT_FLOAT_EQ(r.read_set(7).field.displacement[100].x, 7.0f);
  EXPECT_EQ(r.read_set(7).report_json, "{\"set\":7}");
}

// A writer killed (SIGKILL) at whatever point of an append it has reached: the file opens and
// holds every set whose add() returned, and a new writer resumes it. Three rounds on one file,
// each killed after a different number of sets.
TEST(ResultsFile, SigkillMidAppendKeepsEveryFinishedSet) {
  TempDir dir;
  const auto path = dir / "r.h5";
  std::uint64_t next = 0;
  for (int round = 1; round <= 3; ++round) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const std::uint64_t first = next;
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {  // appends sets until killed, telling the parent after each one
      close(fds[0]);
      try {
        ResultsWriter w(path, info());
        for (std::uint64_t i = first;; ++i) {
          w.add(big_set(i));
          const char done = 1;
          if (write(fds[1], &done, 1) != 1) _exit(3);
        }
      } catch (...) {
        _exit(2);
      }
    }
    close(fds[1]);
    std::uint64_t finished = 0;
    char done = 0;
    while (finished < static_cast<std::uint64_t>(round) && read(fds[0], &done, 1) == 1) ++finished;
    kill(child, SIGKILL);  // the child is somewhere in the next add()
    int status = 0;
    waitpid(child, &status, 0);
    while (read(fds[0], &done, 1) == 1) ++finished;  // sets it finished before the signal landed
    close(fds[0]);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the writer failed by itself, status " << status;
    // The child may finish a set or two more between the parent's last read and the signal
    // (a loaded machine); every one it reported must be in the file.
    ASSERT_GE(finished, static_cast<std::uint64_t>(round));

    const ResultsReader r(path);  // opens although its writer died
    const auto indices = r.set_indices();
    ASSERT_GE(indices.size(), first + finished);  // every finished set (perhaps the one being written too)
    for (std::uint64_t i = 0; i < first + finished; ++i) {
      ASSERT_TRUE(std::binary_search(indices.begin(), indices.end(), i)) << "set " << i << " lost";
      EXPECT_FLOAT_EQ(r.read_set(i).field.displacement[5].x, static_cast<float>(i));
    }
    next = indices.back() + 1;
  }
  ResultsWriter resumed(path, info());
  EXPECT_EQ(resumed.resumed_sets(), next);
  resumed.add(big_set(next));
  resumed.close();
  const ResultsReader r(path);
  EXPECT_EQ(r.set_indices().size(), next + 1);
  const auto s = r.statistics();
  EXPECT_NEAR(s.mean_displacement_voxel[0].x, static_cast<double>(next) / 2.0, 1e-9);  // mean of 0 .. next
}

// A results file written by hand in layout version 1 (one group per set), or with a version
// from the future.
void write_string_attr(hid_t object, const char* name, const std::string& value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  const char* text = value.c_str();
  H5Awrite(a, type, &text);
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
}
void write_number_attr(hid_t object, const char* name, hid_t type, const void* value, hsize_t n = 1) {
  const hid_t space = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
  const hid_t a = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, type, value);
  H5Aclose(a);
  H5Sclose(space);
}
void write_array(hid_t group, const char* name, hid_t type, std::vector<hsize_t> dims, const void* data) {
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t d = H5Dcreate2(group, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
  H5Dclose(d);
  H5Sclose(space);
}
void write_string_dataset(hid_t group, const char* name, const std::string& value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t d = H5Dcreate2(group, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const char* text = value.c_str();
  H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text);
  H5Dclose(d);
  H5Sclose(space);
  H5Tclose(type);
}

void write_old_file(const std::filesystem::path& path, int version) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  write_string_attr(file, "format", "tomorig-results");
  write_number_attr(file, "format_version", H5T_NATIVE_INT, &version);
  write_string_attr(file, "software_version", "0.1.0");
  write_string_attr(file, "session_path", "s.h5");
  write_string_attr(file, "session_identity", "session-1");
  const double voxel = kVoxelMm;
  write_number_attr(file, "voxel_size_mm", H5T_NATIVE_DOUBLE, &voxel);
  write_string_dataset(file, "parameters", R"({"window":32})");
  const hid_t sets = H5Gcreate2(file, "sets", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  for (const std::uint64_t index : {2u, 4u}) {
    const SetResult r = set_with(index, static_cast<float>(index));
    const std::string name = index == 2 ? "000002" : "000004";
    const hid_t g = H5Gcreate2(sets, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const double nodes[3] = {4, 3, 2}, origin[3] = {-1.0, -0.5, 0.25}, spacing[3] = {0.16, 0.16, 0.32};
    write_number_attr(g, "nodes", H5T_NATIVE_DOUBLE, nodes, 3);
    write_number_attr(g, "origin_mm", H5T_NATIVE_DOUBLE, origin, 3);
    write_number_attr(g, "spacing_mm", H5T_NATIVE_DOUBLE, spacing, 3);
    write_number_attr(g, "set_index", H5T_NATIVE_UINT64, &index);
    write_number_attr(g, "dt_ns", H5T_NATIVE_INT64, &r.dt_ns);
    write_number_attr(g, "seconds", H5T_NATIVE_DOUBLE, &r.seconds);
    write_string_attr(g, "completed_utc", "2026-01-02T03:04:05Z");
    write_array(g, "displacement_voxel", H5T_NATIVE_FLOAT, {2, 3, 4, 3}, r.field.displacement.data());
    write_array(g, "status", H5T_NATIVE_UINT8, {2, 3, 4}, r.field.status.data());
    write_array(g, "peak", H5T_NATIVE_FLOAT, {2, 3, 4}, r.field.peak.data());
    write_string_dataset(g, "report", "{}");
    const std::uint8_t complete = index == 2 ? 1 : 0;  // set 4 was never finished
    write_number_attr(g, "complete", H5T_NATIVE_UINT8, &complete);
    H5Gclose(g);
  }
  H5Gclose(sets);
  H5Fclose(file);
}

TEST(ResultsFile, ReadsAndResumesVersion1AndRefusesNewerVersions) {
  TempDir dir;
  const auto old = dir / "v1.h5";
  write_old_file(old, 1);
  {
    const ResultsReader r(old);
    EXPECT_EQ(r.format_version(), 1);
    ASSERT_EQ(r.set_indices(), std::vector<std::uint64_t>{2});  // set 4 has no completion marker
    EXPECT_FLOAT_EQ(r.read_set(2).field.displacement[3].y, 4.0f);
    EXPECT_EQ(r.read_set(2).completed_utc, "2026-01-02T03:04:05Z");
  }
  {  // resuming converts it once to version 2, keeping its set
    ResultsWriter w(old, info());
    EXPECT_EQ(w.resumed_sets(), 1u);
    w.add(set_with(4, 1.0f));
  }
  const ResultsReader r(old);
  EXPECT_EQ(r.format_version(), 2);
  EXPECT_EQ(r.set_indices(), (std::vector<std::uint64_t>{2, 4}));
  EXPECT_EQ(r.read_set(2).completed_utc, "2026-01-02T03:04:05Z");

  const auto future = dir / "v3.h5";
  write_old_file(future, 3);
  try {
    ResultsReader{future};
    FAIL() << "a version-3 file was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("format version 3 is not supported"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tomorig::testing

namespace tomorig::testing {
namespace {

// A set whose displacement differs from node to node and set to set in its last bits, so that the
// order in which sets enter Welford's update shows in the statistics' last bits.
SetResult uneven_set(std::uint64_t index) {
  SetResult r = set_with(index, 0.0f);
  for (std::size_t n = 0; n < r.field.count(); ++n) {
    const float u = 0.1f * static_cast<float>(index + 1) + 0.013f * static_cast<float>(n * n % 7) + 1e-3f / (index + 3);
    r.field.displacement[n] = {u, u * u - 0.3f, 1.0f / (u + 1.7f)};
  }
  return r;
}

std::vector<double> stored_doubles(const std::filesystem::path& path, const char* dataset) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0);
  const hid_t d = H5Dopen2(file, dataset, H5P_DEFAULT);
  EXPECT_GE(d, 0);
  const hid_t space = H5Dget_space(d);
  std::vector<double> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(file);
  return values;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// Sets from several MPI ranks (or a resumed file's gaps) arrive out of index order; the file's
// /statistics must still be those of one run adding them in order, bit for bit.
TEST(ResultsFile, StatisticsOfSetsAddedOutOfOrderAreThoseOfTheSetOrder) {
  const std::vector<std::uint64_t> arrival{4, 1, 6, 0, 3, 5, 2};
  storage::EnsembleAccumulator in_order(kVoxelMm), as_arrived(kVoxelMm);
  for (std::uint64_t i = 0; i < arrival.size(); ++i) in_order.add(uneven_set(i));
  for (const std::uint64_t i : arrival) as_arrived.add(uneven_set(i));
  const auto flat = [](const std::vector<Vec3d>& v) {
    std::vector<double> out;
    for (const Vec3d& x : v) out.insert(out.end(), {x.x, x.y, x.z});
    return out;
  };
  // The premise: the arrival order alone changes the last bits of the running statistics.
  ASSERT_FALSE(same_bits(flat(in_order.result().rms_velocity), flat(as_arrived.result().rms_velocity)) &&
               same_bits(flat(in_order.result().mean_velocity), flat(as_arrived.result().mean_velocity)));

  TempDir dir;
  const auto path = dir / "r.h5";
  {
    ResultsWriter w(path, info());
    w.add(uneven_set(arrival[0]));
    w.add(uneven_set(arrival[1]));
    w.add(uneven_set(arrival[2]));
  }
  {  // resumed, the rest still out of order
    ResultsWriter w(path, info());
    for (std::size_t k = 3; k < arrival.size(); ++k) w.add(uneven_set(arrival[k]));
    w.close();
    EXPECT_TRUE(same_bits(flat(w.statistics().mean_velocity), flat(in_order.result().mean_velocity)));
  }
  const storage::EnsembleStatistics expected = in_order.result();
  EXPECT_TRUE(same_bits(stored_doubles(path, "/statistics/mean_velocity_m_s"), flat(expected.mean_velocity)));
  EXPECT_TRUE(same_bits(stored_doubles(path, "/statistics/rms_velocity_m_s"), flat(expected.rms_velocity)));
  EXPECT_TRUE(same_bits(stored_doubles(path, "/statistics/mean_displacement_voxel"),
                        flat(expected.mean_displacement_voxel)));
  std::vector<double> reynolds;
  for (const auto& r : expected.reynolds_stress) reynolds.insert(reynolds.end(), r.begin(), r.end());
  EXPECT_TRUE(same_bits(stored_doubles(path, "/statistics/reynolds_stress_m2_s2"), reynolds));
  EXPECT_EQ(stored_doubles(path, "/statistics/sets"), std::vector<double>{7.0});
}

}  // namespace
}  // namespace tomorig::testing

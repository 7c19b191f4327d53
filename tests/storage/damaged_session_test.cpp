// Damaged session files (issue 14, defect 3): every reader must end with the session read or a
// bad-input error (exit code 2), never with a signal or a hang. A fuzz corpus made of two small
// sessions written by the tomorig binary, one by `simulate` (written in one go) and one by `run`
// (a live SWMR recording, newest HDF5 format with metadata checksums), damaged by deterministic
// single-bit flips and truncations, each read through inspect's code path (SessionReader,
// summarize) plus every frame and truth set, in a forked child so that a crash is seen as one.
//
// Also the two sessions of format version 1 in tests/storage/data (variable-length strings,
// whose damaged heap references crashed libhdf5 1.10 in H5HG_read).
//
// Sizes: 50 flips and 10 truncations per session by default (seconds). For the figures of
// docs/reliability.md set TOMORIG_FUZZ_FLIPS=1000 TOMORIG_FUZZ_TRUNCATIONS=200.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "storage_test_support.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/session_summary.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using tomorig::testing::TempDir;

// How a reading child ended: an exit code, or the signal that killed it.
struct Outcome {
  int exit_code = -1;
  int signal = 0;
};

// What a command does with a session: open and summarize it (inspect), read every frame
// (replay, reconstruct, process) and the truth (accuracy checks). Exit code as tomorig's.
int read_everything(const fs::path& path) {
  try {
    const SessionReader reader(path);
    summarize(reader);
    for (std::uint64_t k = 0; k < reader.set_count(); ++k) reader.read_set(k);
    if (reader.has_truth()) {
      reader.truth();
      for (std::uint64_t k = 0; k < reader.set_count(); ++k)
        if (reader.has_truth_set(k)) reader.truth_set(k);
    }
    return 0;
  } catch (const Error& e) {
    return e.kind() == ErrorKind::bad_input ? 2 : 1;
  } catch (const std::exception&) {
    return 3;  // a bare std::exception (bad_alloc, length_error): exit 1 without a message
  }
}

// Reads in a forked child, so that a crash or a hang of the library ends the child only.
Outcome read_in_child(const fs::path& path) {
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    alarm(30);  // a hang ends as SIGALRM (the reader's own CPU limit is 8 s)
    _exit(read_everything(path));
  }
  int status = 0;
  waitpid(child, &status, 0);
  if (WIFSIGNALED(status)) return {-1, WTERMSIG(status)};
  return {WEXITSTATUS(status), 0};
}

std::size_t env_count(const char* name, std::size_t fallback) {
  const char* text = std::getenv(name);
  return text != nullptr && *text != '\0' ? static_cast<std::size_t>(std::strtoull(text, nullptr, 10)) : fallback;
}

// A small session and where its bulk data lie (frame chunks, particle arrays): flips there only
// change pixel or particle values, so most flips go elsewhere, into HDF5's metadata, the
// attributes and the per-set records, where damage can confuse a reader.
struct Corpus {
  std::string name;
  std::vector<char> bytes;
  std::vector<std::pair<haddr_t, hsize_t>> bulk;  // [address, size)
};

void collect_bulk(hid_t location, const std::string& path, std::vector<std::pair<haddr_t, hsize_t>>& bulk) {
  H5O_info_t info{};
  if (H5Oget_info_by_name2(location, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) return;
  if (info.type == H5O_TYPE_GROUP) {
    const hid_t group = H5Gopen2(location, path.c_str(), H5P_DEFAULT);
    H5G_info_t g{};
    H5Gget_info(group, &g);
    for (hsize_t i = 0; i < g.nlinks; ++i) {
      char name[256] = {};
      H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT);
      collect_bulk(group, name, bulk);
    }
    H5Gclose(group);
    return;
  }
  if (info.type != H5O_TYPE_DATASET) return;
  const std::string leaf = path.substr(path.find_last_of('/') + 1);
  if (leaf != "frames" && leaf != "particles_a" && leaf != "particles_b") return;
  const hid_t dataset = H5Dopen2(location, path.c_str(), H5P_DEFAULT);
  const haddr_t contiguous = H5Dget_offset(dataset);
  if (contiguous != HADDR_UNDEF) {
    bulk.emplace_back(contiguous, H5Dget_storage_size(dataset));
  } else {
    const hid_t space = H5Dget_space(dataset);
    hsize_t chunks = 0;
    H5Dget_num_chunks(dataset, space, &chunks);
    for (hsize_t i = 0; i < chunks; ++i) {
      hsize_t offset[4] = {};
      unsigned mask = 0;
      haddr_t address = HADDR_UNDEF;
      hsize_t size = 0;
      if (H5Dget_chunk_info(dataset, space, i, offset, &mask, &address, &size) >= 0) bulk.emplace_back(address, size);
    }
    H5Sclose(space);
  }
  H5Dclose(dataset);
}

Corpus load_corpus(const std::string& name, const fs::path& file) {
  Corpus c;
  c.name = name;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  std::ifstream in(file, std::ios::binary);
  c.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f >= 0) {
    collect_bulk(f, "/", c.bulk);
    H5Fclose(f);
  }
  return c;
}

bool in_bulk(const Corpus& c, std::uint64_t offset) {
  return std::any_of(c.bulk.begin(), c.bulk.end(),
                     [&](const auto& r) { return offset >= r.first && offset < r.first + r.second; });
}

// A default rig with 64 x 48 cameras: the same structure as the default session, small enough
// that its metadata is a large part of the file and a case takes milliseconds.
std::string small_rig_text() {
  const tomorig::testing::CliResult r = tomorig::testing::run_tomorig("config default");
  std::string text = r.out;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"width = 512", "width = 64"},
                                 std::pair<std::string, std::string>{"height = 512", "height = 48"}})
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at))
      text.replace(at, from.size(), to);
  return text;
}

class DamagedSession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!tomorig::testing::tomorig_built()) return;
    dir_ = std::make_unique<TempDir>();
    const fs::path rig = dir_->write("small.toml", small_rig_text());
    const std::string config = " --config " + tomorig::testing::shell_quoted(rig.string());
    const fs::path simulated = *dir_ / "simulated.h5";
    const fs::path live = *dir_ / "live.h5";
    const auto sim = tomorig::testing::run_tomorig("simulate --sets 2" + config + " -o " +
                                                   tomorig::testing::shell_quoted(simulated.string()));
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    const auto run = tomorig::testing::run_tomorig("run --sets 2 --pace max --status none" + config + " -o " +
                                                   tomorig::testing::shell_quoted(live.string()));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const fs::path v1 = fs::path(TOMORIG_SOURCE_DIR) / "tests/storage/data";
    corpora_ = {load_corpus("simulate", simulated), load_corpus("run (live)", live),
                load_corpus("simulate, format 1", v1 / "session-v1-simulate.h5"),
                load_corpus("run (live), format 1", v1 / "session-v1-run.h5")};
  }
  static void TearDownTestSuite() {
    corpora_.clear();
    dir_.reset();
  }
  void SetUp() override {
    if (!tomorig::testing::tomorig_built()) GTEST_SKIP() << "tomorig binary not built: " << TOMORIG_BINARY;
  }

  // Writes `bytes` as a damaged copy and reads it; records the outcome under `label`.
  static Outcome try_damaged(const std::vector<char>& bytes, const TempDir& dir) {
    const fs::path path = dir / "damaged.h5";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return read_in_child(path);
  }

  static void expect_clean(const Outcome& o, const std::string& what, std::map<std::string, int>& tally) {
    if (o.signal != 0) {
      ++tally["signal"];
      ADD_FAILURE() << what << ": the reader was killed by signal " << o.signal << " (" << strsignal(o.signal) << ")";
    } else if (o.exit_code == 0) {
      ++tally["read"];
    } else if (o.exit_code == 2) {
      ++tally["refused (exit 2)"];
    } else {
      ++tally["other"];
      ADD_FAILURE() << what << ": the reader ended with exit code " << o.exit_code
                    << (o.exit_code == 3 ? " (a bare std::exception)" : "");
    }
  }

  static void report(const std::string& what, const std::map<std::string, int>& tally) {
    std::cout << "[ figures  ] " << what << ":";
    for (const auto& [k, n] : tally) std::cout << " " << k << " " << n << ";";
    std::cout << std::endl;
  }

  static std::unique_ptr<TempDir> dir_;
  static std::vector<Corpus> corpora_;
};
std::unique_ptr<TempDir> DamagedSession::dir_;
std::vector<Corpus> DamagedSession::corpora_;

TEST_F(DamagedSession, TheUndamagedSessionsReadCompletely) {
  ASSERT_EQ(corpora_.size(), 4u);
  TempDir dir;
  for (const Corpus& c : corpora_) {
    EXPECT_GE(c.bulk.size(), 4u * 2 * 2) << c.name << ": frame chunks not found";  // cameras x exposures x sets
    const Outcome o = try_damaged(c.bytes, dir);
    EXPECT_EQ(o.signal, 0) << c.name;
    EXPECT_EQ(o.exit_code, 0) << c.name;
  }
}

TEST_F(DamagedSession, BitFlipsNeverCrashOrHangAReader) {
  const std::size_t flips = env_count("TOMORIG_FUZZ_FLIPS", 50);
  TempDir dir;
  for (const Corpus& c : corpora_) {
    std::map<std::string, int> tally;
    std::vector<char> damaged = c.bytes;
    for (std::size_t seed = 0; seed < flips; ++seed) {
      std::mt19937_64 rng(seed);
      // Nine flips in ten land outside the bulk data, where they can confuse a reader.
      std::uint64_t offset = rng() % c.bytes.size();
      for (int tries = 0; rng() % 10 != 0 && in_bulk(c, offset) && tries < 1000; ++tries)
        offset = rng() % c.bytes.size();
      const int bit = static_cast<int>(rng() % 8);
      damaged[offset] = static_cast<char>(damaged[offset] ^ (1 << bit));
      expect_clean(try_damaged(damaged, dir), c.name + ": bit " + std::to_string(bit) + " of byte " +
                                                  std::to_string(offset) + " flipped (seed " + std::to_string(seed) + ")",
                   tally);
      damaged[offset] = c.bytes[offset];
    }
    report(c.name + ", " + std::to_string(flips) + " bit flips", tally);
  }
}

// The crash of issue 14: a variable-length string is a (length, heap address, index) record,
// and libhdf5 1.10 looks the index up in the global heap without checking it. Every such record
// of the format-1 sessions, its index made huge: refused, never a crash.
TEST_F(DamagedSession, DamagedHeapIndexOfAVariableLengthStringIsRefused) {
  TempDir dir;
  int records = 0;
  std::map<std::string, int> tally;
  for (const Corpus& c : corpora_) {
    // Global heap collections start with "GCOL"; records point at them by file address.
    std::vector<std::uint64_t> heaps;
    for (std::size_t at = 0; at + 4 <= c.bytes.size(); ++at)
      if (std::equal(c.bytes.begin() + static_cast<std::ptrdiff_t>(at), c.bytes.begin() + static_cast<std::ptrdiff_t>(at) + 4, "GCOL"))
        heaps.push_back(at);
    for (const std::uint64_t heap : heaps)
      for (std::size_t at = 4; at + 12 <= c.bytes.size(); ++at) {
        std::uint64_t address = 0;
        std::memcpy(&address, c.bytes.data() + at, 8);  // little-endian file, little-endian host
        std::uint32_t length = 0, index = 0;
        std::memcpy(&length, c.bytes.data() + at - 4, 4);
        std::memcpy(&index, c.bytes.data() + at + 8, 4);
        if (address != heap || index == 0 || index > 1000 || length > 100000) continue;
        std::vector<char> damaged = c.bytes;
        damaged[at + 11] = static_cast<char>(damaged[at + 11] ^ 1);  // index + 2^24
        ++records;
        expect_clean(try_damaged(damaged, dir), c.name + ": heap index at byte " + std::to_string(at + 8) + " damaged",
                     tally);
      }
  }
  EXPECT_GE(records, 8) << "the format-1 sessions hold variable-length strings";
  EXPECT_EQ(tally["read"], 0) << "a string whose heap index points nowhere was read";
  report(std::to_string(records) + " damaged heap indices", tally);
}

// The hang of issue 14: a metadata checksum that fails makes a SWMR reader (how tomorig opens a
// file a plain open refuses) read the block again and again, sleeping twice as long each time;
// with HDF5's default of 100 attempts that is forever. Here the superblock of the live
// recording (newest format, checksummed) points its root group 2 KiB off.
TEST_F(DamagedSession, FailedChecksumIsRefusedWithoutWaiting) {
  TempDir dir;
  const Corpus& live = corpora_.at(1);
  std::vector<char> damaged = live.bytes;
  damaged[37] = static_cast<char>(damaged[37] ^ (1 << 3));  // root group object header address + 0x800
  const Outcome o = try_damaged(damaged, dir);
  EXPECT_EQ(o.signal, 0) << "killed by " << strsignal(o.signal) << " (SIGALRM: the reader hung)";
  EXPECT_EQ(o.exit_code, 2);
}

// Names whose terminating NUL is gone (issue 14 saw a heap over-read in H5MM_xstrdup, where
// libhdf5 copies names out of the file): every attribute or link name of the four sessions, its
// NUL padding overwritten. libhdf5 itself crashes on some of these (in H5Aexists and
// H5Aiterate), before tomorig sees a type; the reader must end with the file read or refused.
TEST_F(DamagedSession, NamesWithoutTheirTerminatorNeverCrashAReader) {
  // All names are about 60 to 100 per session; by default every few of them (set
  // TOMORIG_FUZZ_NAMES=0 for all).
  const std::size_t per_corpus = env_count("TOMORIG_FUZZ_NAMES", 25);
  TempDir dir;
  int names = 0;
  std::map<std::string, int> tally;
  const auto is_name_char = [](char ch) { return (ch >= 'a' && ch <= 'z') || ch == '_'; };
  for (const Corpus& c : corpora_) {
    const std::vector<char>& b = c.bytes;
    std::vector<std::array<std::size_t, 3>> found;  // name start, name end, end of its NUL padding
    for (std::size_t at = 0; at < b.size();) {
      std::size_t end = at;
      while (end < b.size() && is_name_char(b[end])) ++end;
      std::size_t nul = end;
      while (nul < b.size() && b[nul] == '\0') ++nul;
      if (end - at >= 3 && end - at <= 40 && nul > end && (at == 0 || !is_name_char(b[at - 1])) && !in_bulk(c, at))
        found.push_back({at, end, nul});
      at = std::max(end, at + 1);
    }
    const std::size_t stride = per_corpus == 0 ? 1 : std::max<std::size_t>(1, (found.size() + per_corpus - 1) / per_corpus);
    for (std::size_t i = 0; i < found.size(); i += stride) {
      const auto [at, end, nul] = found[i];
      std::vector<char> damaged = b;
      std::fill(damaged.begin() + static_cast<std::ptrdiff_t>(end), damaged.begin() + static_cast<std::ptrdiff_t>(nul), 'x');
      ++names;
      expect_clean(try_damaged(damaged, dir),
                   c.name + ": name '" + std::string(b.data() + at, end - at) + "' at byte " + std::to_string(at) +
                       " without its terminator",
                   tally);
    }
  }
  EXPECT_GE(names, 40) << "the sessions hold names";
  report(std::to_string(names) + " names without their terminator", tally);
}

TEST_F(DamagedSession, TruncationsNeverCrashOrHangAReader) {
  const std::size_t truncations = env_count("TOMORIG_FUZZ_TRUNCATIONS", 10);
  TempDir dir;
  for (const Corpus& c : corpora_) {
    std::map<std::string, int> tally;
    std::mt19937_64 rng(4242);
    for (std::size_t k = 0; k < truncations; ++k) {
      // A few fixed lengths (empty, inside the superblock, one byte short), then random ones.
      const std::size_t fixed[] = {0, 7, 96, c.bytes.size() - 1};
      const std::size_t length = k < std::size(fixed) ? fixed[k] : rng() % c.bytes.size();
      const std::vector<char> cut(c.bytes.begin(), c.bytes.begin() + static_cast<std::ptrdiff_t>(length));
      expect_clean(try_damaged(cut, dir), c.name + ": truncated to " + std::to_string(length) + " bytes", tally);
    }
    report(c.name + ", " + std::to_string(truncations) + " truncations", tally);
  }
}

}  // namespace
}  // namespace tomorig::storage

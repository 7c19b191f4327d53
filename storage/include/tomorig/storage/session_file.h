#pragma once
// HDF5 session files: everything needed to reprocess a run (frames, timestamps, trigger
// events, rig config, truth for simulated sessions). Layout: docs/file-formats.md.
//
// Writing goes to "<path>.partial" and is renamed to <path> by finish(), so an interrupted
// or failed write never leaves a half-written file under the final name.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/core/frame_set.h"
#include "tomorig/core/geometry.h"
#include "tomorig/core/pixel_format.h"
#include "tomorig/storage/quicklook_record.h"

namespace tomorig::storage {

enum class Compression : std::uint8_t {
  none,            // raw chunks
  bitshuffle_lz4,  // HDF5 filter 32008 (Debian package "bitshuffle")
};
std::string_view to_string(Compression c);
std::optional<Compression> parse_compression(std::string_view name);

struct SessionCamera {
  std::string id;
  int width = 0;
  int height = 0;
  PixelFormat pixel_format = PixelFormat::Mono16;
  double pixel_pitch_um = 0.0;
};

// Pinhole parameters of a simulated camera, as recorded in /truth/cameras.
struct TruthCamera {
  std::string id;
  std::string model = "pinhole";
  Mat3d K{};       // intrinsics, pixels
  Mat3d R{};       // world -> camera rotation
  Vec3d t;         // world -> camera translation, mm
  int width = 0, height = 0;
};

// Ground truth of a simulated session, one entry per set.
struct TruthSet {
  std::vector<Vec3d> particles_a;  // world mm, exposure A
  std::vector<Vec3d> particles_b;  // world mm, exposure B
};

struct SessionTruth {
  std::string case_name;          // e.g. "tpiv-thesis"
  std::string flow_name;          // e.g. "taylor-green"
  std::string flow_parameters;    // JSON object text, e.g. {"A_voxel":5,"p_voxel":256}
  std::uint64_t seed = 0;
  double ppp = 0.0;
  std::vector<TruthCamera> cameras;
};

struct SessionInfo {
  std::vector<SessionCamera> cameras;
  std::string rig_config_toml;    // the rig config the session was taken with
  std::string software_version;
  std::string created_utc;        // ISO 8601
  Compression compression = Compression::none;
};

// The per-set records of a session without the pixels: what /sets holds for one set.
struct SetRecord {
  std::uint64_t trigger_index = 0;
  std::int64_t trigger_timestamp_ns = 0;
  std::int64_t dt_ns = 0;
  // One entry per camera, in session order; [0] is exposure A, [1] exposure B.
  std::vector<std::array<std::int64_t, 2>> frame_timestamp_ns;
  std::vector<std::array<bool, 2>> frame_present;
  // false: a free-running camera's frame (frame_present = 2 in the file), not of this event.
  std::vector<std::array<bool, 2>> frame_synchronised;
};

// SessionInfo::software_version and created_utc are filled in by the writer when empty;
// SessionInfo::compression is ignored on writing (the options decide).
// When a live recording makes its sets visible and durable (HDF5 flush): when the set count
// reaches a multiple of `every_sets` (sets 10, 20, ... by default, whatever the clock did in
// between, so "set 10 is on disk" holds at set 10), and whenever `every_seconds` passed since
// the last flush. A flush costs a few metadata writes; after a crash or SIGKILL, every set
// before the last flush is intact.
struct FlushPolicy {
  std::uint64_t every_sets = 10;
  double every_seconds = 1.0;
};

// Thrown by SessionWriter::append() when the disk holding the session has no room for the set
// (see SessionWriterOptions::disk_reserve_bytes). Nothing of the set was written and the writer
// stays usable: finish() closes a complete, valid session with every set appended before.
class DiskFullError : public Error {
 public:
  explicit DiskFullError(const std::string& message) : Error(ErrorKind::runtime, message) {}
};

struct SessionWriterOptions {
  Compression compression = Compression::none;
  // Replace an existing file at the final path. Never a left-over "<path>.partial": that is
  // what a writer that did not finish left behind (a live one's recorded sets), and the
  // constructor refuses to start while it exists.
  bool overwrite = false;
  // Live recording (the recorder of a running rig): the file is written with HDF5 SWMR, so
  // `tomorig inspect <path>.partial` reads it while it grows, it is flushed by `flush`, and a
  // writer abandoned without finish() (a full disk, Ctrl-C, a crash) keeps "<path>.partial"
  // with every set written so far instead of deleting it. Truth is held in memory and written
  // by finish(). Without `live`, an unfinished file is deleted: nothing half-written remains.
  bool live = false;
  FlushPolicy flush;
  // Space the disk must keep free, in bytes, beyond the set being appended and the truth held
  // for finish(). When the next set would eat into it, append() throws DiskFullError before
  // writing, so the session can still be finished cleanly (HDF5 itself cannot recover from a
  // write that hits a full disk: such a failure leaves only "<path>.partial", valid up to its
  // last flush). 0: no check.
  std::uint64_t disk_reserve_bytes = 0;
};

class SessionWriter {
 public:
  // Locks the name for this writer (see "One writer per file" in docs/file-formats.md) and
  // creates "<path>.partial". Throws tomorig::Error (bad_input), having changed nothing, if
  // the folder is not writable, the file exists and overwrite is false, another writer holds
  // the name, or "<path>.partial" exists (the message gives the commands to recover it).
  SessionWriter(const std::filesystem::path& path, const SessionInfo& info,
                const SessionWriterOptions& options = {});
  ~SessionWriter();  // without finish(): closes and removes the partial file
  SessionWriter(const SessionWriter&) = delete;
  SessionWriter& operator=(const SessionWriter&) = delete;

  // Appends one set. Frames must match the camera sizes and formats; a missing frame
  // (empty image) is recorded as missing, not as zeros. Cameras are matched by id; a session
  // camera absent from the set counts as two missing frames. set.set_index is ignored: sets
  // are numbered in the order they are appended. A wrong frame throws bad_input before
  // anything is written; an HDF5 failure throws runtime and the writer refuses further use.
  void append(const FrameSet& set);
  // Truth of simulated sessions: write_truth once, write_truth_set once per set index.
  void write_truth(const SessionTruth& truth);
  void write_truth_set(std::uint64_t set_index, const TruthSet& truth);
  // Quick-look numbers of one set (/quicklook, quicklook_record.h), e.g. from a quick-look
  // stage: safe to call from another thread while append() runs. Records may come late, skip
  // sets and arrive out of order; each names its set, and several may name the same set (what
  // is not measured in one is NaN there; quicklook() merges them). In a live recording they become visible
  // with the next flush. Throws bad_input for a record whose camera count is not the
  // session's; an HDF5 failure throws runtime, as append() does.
  void append_quicklook(const QuickLookRecord& record);
  // Flushes, closes and renames the partial file to the final path.
  void finish();

  std::uint64_t sets_written() const;
  const std::filesystem::path& path() const;          // the final path
  const std::filesystem::path& partial_path() const;  // "<path>.partial"

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class SessionReader {
 public:
  // Opens and validates the layout, types and declared sizes before reading anything (see
  // "Reading safely" in docs/file-formats.md). Throws tomorig::Error (bad_input) naming the
  // file and what is wrong: missing, not HDF5, not a tomorig session, wrong sizes or types,
  // truncated datasets, damaged. The open pass runs first in a forked child process, so a
  // libhdf5 crash or endless loop on a damaged file ends the child, not the caller: open
  // readers before starting threads that use HDF5 (a child may inherit a lock they hold).
  explicit SessionReader(const std::filesystem::path& path);
  ~SessionReader();
  SessionReader(const SessionReader&) = delete;
  SessionReader& operator=(const SessionReader&) = delete;

  const SessionInfo& info() const;
  const std::filesystem::path& path() const;
  int format_version() const;
  std::uint64_t set_count() const;
  // Pixels and records of one set; bad_input if set_index >= set_count(), or if the file turns
  // out to be corrupt while reading.
  FrameSet read_set(std::uint64_t set_index) const;
  // The records of one set without reading pixels (cheap: held in memory).
  SetRecord set_record(std::uint64_t set_index) const;
  int missing_frames() const;     // over the whole session
  int incomplete_sets() const;
  // False for a live recording still being written, or one that was interrupted (its
  // "<name>.partial" file): then set_count() is the sets that were completely written.
  bool recording_complete() const;
  bool has_truth() const;
  SessionTruth truth() const;                              // bad_input if !has_truth()
  bool has_truth_set(std::uint64_t set_index) const;
  std::uint64_t truth_set_count() const;                   // sets with /truth/sets/<index>
  TruthSet truth_set(std::uint64_t set_index) const;       // bad_input if absent
  // The quick-look numbers stored with the session, one record per set in set order (rows of
  // the same set, e.g. its statistics and, later, its preview volume, merged: measured figures
  // fill unmeasured ones, flags take the worse); empty if none (sessions recorded without a
  // quick-look, or before tomorig stored them).
  std::vector<QuickLookRecord> quicklook() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::storage

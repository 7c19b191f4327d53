#pragma once
// The lossless recorder of a rig: FrameSets in, a live HDF5 session file out (SWMR: readable
// while it grows, every flushed set survives a crash). One class serves `tomorig run` (sets
// from the in-process rig) and `tomorig record` (sets from the stream).
//
//   rig::Recorder recorder({.out = "s.h5", .cameras = rig.session_cameras()});
//   for (...) if (recorder.add(set) == rig::Recorder::Outcome::stopped) break;  // disk full
//   const rig::RecorderReport& report = recorder.finish();
//
// A session needs its camera list before its first set. When the caller does not know it (a
// stream announces none; an Aravis camera without an ROI has no size until it sends), the first
// set that can define it does; every later set must match it. A set that does not is refused:
// counted and never written, so one bad sender cannot corrupt the session.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

struct RecorderOptions {
  std::filesystem::path out;  // the session file; "<out>.partial" while it is written
  storage::Compression compression = storage::Compression::none;
  bool overwrite = false;  // replace an existing `out`; without it an existing file is refused
  // Stop cleanly (Outcome::stopped, the session complete) when the disk would keep less than
  // this many MB free after the next set.
  double disk_reserve_mb = 64.0;
  // The largest set the recorder takes, in MB of pixels (both frames of every camera): a set
  // that would start a session past it is refused, so one absurd message cannot make the
  // recorder create a file sized for it. Later sets must match the first one's cameras.
  double max_set_mb = 4096.0;
  // The session's cameras, when known: then the file is created by the constructor. A camera of
  // width or height 0 gets its size from the first set (its id and pixel pitch are kept); empty:
  // the first set that can define them says which cameras there are.
  std::vector<storage::SessionCamera> cameras;
  std::string rig_config_toml;                // stored as the session's /config
  // Who made the session and when, if not this program now: a recorder of a stream keeps what
  // the sender's session start says. Empty: this program's version / the time the file opens.
  std::string software_version;
  std::string created_utc;
  std::optional<storage::SessionTruth> truth;  // simulated rigs: the truth written with the session

  // Throws tomorig::Error (bad_input) naming the option: an empty out, a negative reserve.
  void validate() const;
};

// "none" or "bitshuffle-lz4"; bad_input naming --compression otherwise.
storage::Compression parse_compression_option(const std::string& text);

// Why a session of `cameras` cannot be recorded with `options`: more cameras than a session
// holds, an id the camera-id rule refuses, a duplicate id, a size of 0 or past 65536, a set
// past options.max_set_mb. Empty if it can. Touches no file; quick for any list.
std::string why_not_recordable(const std::vector<storage::SessionCamera>& cameras, const RecorderOptions& options);

// What the Recorder's constructor checks first, for callers that must refuse a bad output
// before building anything else: validates, refuses an existing `out` without `overwrite`,
// creates the output folder. Throws tomorig::Error (bad_input) naming -o/--out.
void prepare_output(const RecorderOptions& options);

struct RecorderReport {
  std::filesystem::path out;
  std::uint64_t written = 0;  // sets in the session
  std::uint64_t bytes = 0;    // pixel bytes of the sets written (before compression)
  std::uint64_t refused = 0;  // sets that could not start the session (why_not_recordable) or did not match it
  std::uint64_t quicklook_rows = 0;      // quick-look records stored (add_quicklook)
  std::uint64_t quicklook_failures = 0;  // quick-look records the file did not take
  std::string disk_full;      // why the disk stopped the recording; empty if it did not
  bool finished = false;      // the session is complete under its final name

  // "recorded 12 sets (41.9 MB of pixels) to s.h5"
  std::string brief() const;
};

class Recorder {
 public:
  // Validates the options, refuses an existing `out` without `overwrite`, creates the output
  // folder and, when the cameras are known, the session. Throws tomorig::Error (bad_input).
  explicit Recorder(RecorderOptions options);
  ~Recorder();  // without finish(): the live writer keeps "<out>.partial" with every set written
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  enum class Outcome {
    written,
    refused,  // not written; `why` says which camera or size differs
    stopped,  // the disk is full: nothing of this set was written, and no later set will be
  };
  // Writes `set`, and `truth` (the simulator's particles of this set) when given. A failure of
  // the file throws runtime_error saying how many sets were written and where they are.
  Outcome add(const FrameSet& set, const storage::TruthSet* truth = nullptr, std::string* why = nullptr);

  // Stores quick-look numbers of a set with the session (storage::SessionWriter::append_quicklook):
  // safe from a quick-look stage's threads while add() runs. Ignored before the session exists
  // and after finish(); a failure is counted in the report (quicklook_failures), never thrown,
  // so the quick-look cannot stop the recording.
  void add_quicklook(const storage::QuickLookRecord& record);

  // Closes the session complete and returns the report. Throws runtime_error if no set ever
  // started the session ("nothing was recorded"); a recorder stopped by the disk finishes too.
  const RecorderReport& finish();

  bool started() const { return writer_ != nullptr; }  // the session file exists
  const RecorderReport& report() const { return report_; }
  const std::vector<storage::SessionCamera>& cameras() const { return info_.cameras; }

 private:
  void open();

  RecorderOptions options_;
  storage::SessionInfo info_;
  std::unique_ptr<storage::SessionWriter> writer_;
  RecorderReport report_;
  std::mutex quicklook_mutex_;  // add_quicklook() against finish() and itself
};

}  // namespace tomorig::rig

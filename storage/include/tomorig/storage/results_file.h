#pragma once
// Results files: the validated 3-D3C vector fields of a processed session, one per set, with
// ensemble statistics, in HDF5 with an XDMF sidecar for ParaView. Layout in
// docs/correlation.md ("Results file").
//
// Crash safety (format version 2): the file is created with its layout through "<path>.partial"
// and a rename, then ResultsWriter::add() appends each set in place (HDF5 SWMR, one row of
// growing datasets) and flushes; the set's completion byte is written and flushed last. So an
// append costs O(set), and whatever happens (Ctrl-C, SIGKILL, a full disk) the file under the
// final name opens and holds every set finished so far; a row without its completion byte is
// ignored. A run started again with the same session and parameters skips the sets it finds.
//
//   ResultsWriter out("r.h5", {.session_path = "s.h5", .session_identity = id, ...});
//   if (!out.has_set(7)) out.add({.set_index = 7, .dt_ns = 1000, .field = field});
//   out.close();
//   ResultsReader in("r.h5");  EnsembleStatistics s = in.statistics();
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/core/vector_field.h"

namespace tomorig::storage {

struct ResultsInfo {
  std::string session_path;      // the session processed (for people; not used to match)
  std::string session_identity;  // fingerprint of that session; a file of another one is refused
  std::string parameters_json;   // processing parameters, a JSON object ("" if none)
  double voxel_size_mm = 0.0;    // of the reconstruction grid: displacement voxel -> mm
  std::string software_version;  // filled in by the writer
};

struct SetResult {
  std::uint64_t set_index = 0;
  std::int64_t dt_ns = 0;        // pulse separation of the set, > 0
  VectorField field;             // displacement in voxels, nodes in world mm
  std::string report_json;       // correlation / reconstruction report, a JSON object ("" if none)
  double seconds = 0.0;          // processing time of the set
  std::string completed_utc;     // when the set was finished; filled in by the writer
};

// Statistics over all sets, per node. A vector counts if its status is valid or replaced.
// Velocities in m/s from each set's dt and the voxel size; NaN where no set contributed.
struct EnsembleStatistics {
  int nx = 0, ny = 0, nz = 0;
  Vec3d origin, spacing;                      // mm, as the fields
  std::uint64_t sets = 0;
  std::vector<std::uint32_t> valid_count;     // vectors that contributed
  std::vector<Vec3d> mean_displacement_voxel;
  std::vector<Vec3d> mean_velocity;           // m/s
  std::vector<Vec3d> rms_velocity;            // m/s, RMS of the fluctuations u' = u - mean
  // <u'u'>, <v'v'>, <w'w'>, <u'v'>, <u'w'>, <v'w'> in m^2/s^2 (population averages).
  std::vector<std::array<double, 6>> reynolds_stress;

  // Throws tomorig::Error (bad_input) if the sets' fields differ in shape or a dt is not > 0.
  static EnsembleStatistics compute(const std::vector<SetResult>& sets, double voxel_size_mm);
};

// The statistics of EnsembleStatistics, one set at a time (Welford's update: numerically as
// safe as two passes, with O(nodes) memory whatever the number of sets).
class EnsembleAccumulator {
 public:
  explicit EnsembleAccumulator(double voxel_size_mm) : voxel_size_mm_(voxel_size_mm) {}
  // Throws tomorig::Error (bad_input) if the set's field has another shape than the first
  // set's, its arrays do not match its nodes, or its dt is not > 0. Nothing changes then.
  void check(const SetResult& set) const;
  void add(const SetResult& set);  // check() first
  std::uint64_t sets() const { return sets_; }
  EnsembleStatistics result() const;

 private:
  double voxel_size_mm_;
  std::uint64_t sets_ = 0;
  std::uint64_t first_set_ = 0;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  Vec3d origin_, spacing_;
  std::vector<std::uint32_t> count_;
  std::vector<Vec3d> mean_displacement_, mean_velocity_;
  std::vector<std::array<double, 6>> comoment_;  // sums of u'u', v'v', w'w', u'v', u'w', v'w'
};

// Velocity (m/s) of a displacement of `voxels` over dt_ns nanoseconds.
double velocity_m_per_s(double voxels, double voxel_size_mm, std::int64_t dt_ns);

struct ResultsWriterOptions {
  bool overwrite = false;  // start afresh even if the file exists (else: resume it)
  // For tests: called in add() after the room check and before HDF5 writes the set, where a
  // test makes the disk fill up as another program would.
  std::function<void()> after_room_check;
};

class ResultsWriter {
 public:
  // A new file, or resumes an existing one: then its finished sets are kept (has_set()) and
  // the statistics rebuilt, reading one set at a time. Throws tomorig::Error (bad_input) if the
  // existing file is not a results file, belongs to another session (different identity) or was
  // made with different parameters; or if the folder is missing or the path is a folder; or if
  // another writer (in this or another process) has the file: a writer holds the file's lock
  // ("<path>.lock", see docs/file-formats.md) from construction to destruction.
  // Nothing is written before write() or the first add(), except that a version-1 file is
  // converted to version 2 at once; a file left by a killed writer is copied at the first add().
  ResultsWriter(const std::filesystem::path& path, const ResultsInfo& info, const ResultsWriterOptions& options = {});
  ~ResultsWriter();
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;

  bool has_set(std::uint64_t set_index) const;
  std::uint64_t set_count() const;                  // sets in the file (resumed ones included)
  std::vector<std::uint64_t> set_indices() const;   // ascending
  std::uint64_t resumed_sets() const;               // sets found in the existing file
  EnsembleStatistics statistics() const;            // over every set in the file
  // Appends a finished set in place (O(set): earlier sets are not rewritten) and updates the
  // statistics; the XDMF sidecar follows at most every few seconds and at close(). Throws
  // bad_input for a set already present, a field of another shape or dt <= 0; runtime if
  // writing fails, e.g. a full disk: the set is not added, the file keeps every earlier set,
  // and a later add() reopens it.
  void add(const SetResult& set);
  // Creates the file now if it does not exist yet (an empty, valid results file).
  void write();
  // Flushes, writes the sidecar and closes the file (the destructor does the same, silently).
  // If a set was added after one of a higher index (resumed gaps, sets from several MPI ranks),
  // the statistics are first recomputed reading the sets in index order (O(file) once), so they
  // are bit-identical to those of one uninterrupted run over the same sets.
  void close();

  const std::filesystem::path& path() const;
  static std::filesystem::path sidecar_path(const std::filesystem::path& results_file);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class ResultsReader {
 public:
  // Throws tomorig::Error (bad_input) naming the file for a missing, corrupt or foreign file.
  explicit ResultsReader(const std::filesystem::path& path);
  ~ResultsReader();

  const ResultsInfo& info() const;
  int format_version() const;                      // 1 (one group per set) or 2 (rows)
  std::vector<std::uint64_t> set_indices() const;  // ascending
  SetResult read_set(std::uint64_t set_index) const;  // bad_input if absent
  std::vector<SetResult> read_all_sets() const;     // all in memory: prefer read_set in a loop
  bool has_statistics() const;                        // false with no set
  // Recomputed from the sets, reading one at a time. bad_input if there is no set.
  EnsembleStatistics statistics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::storage

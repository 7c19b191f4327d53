#pragma once
// Results files: the validated 3-D3C vector fields of a processed session, one per set, with
// ensemble statistics, in HDF5 with an XDMF sidecar for ParaView. Layout in
// docs/correlation.md ("Results file").
//
// Crash safety: ResultsWriter::add() writes the whole file to "<path>.partial", flushes it and
// renames it over <path>. The file under the final name is therefore always complete and holds
// every set finished so far, whatever happens afterwards (Ctrl-C, SIGKILL, a full disk). A run
// that is started again with the same session and parameters skips the sets it finds.
//
//   ResultsWriter out("r.h5", {.session_path = "s.h5", .session_identity = id, ...});
//   if (!out.has_set(7)) out.add({.set_index = 7, .dt_ns = 1000, .field = field});
//   ResultsReader in("r.h5");  EnsembleStatistics s = in.statistics();
#include <array>
#include <cstdint>
#include <filesystem>
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

// Velocity (m/s) of a displacement of `voxels` over dt_ns nanoseconds.
double velocity_m_per_s(double voxels, double voxel_size_mm, std::int64_t dt_ns);

struct ResultsWriterOptions {
  bool overwrite = false;  // start afresh even if the file exists (else: resume it)
};

class ResultsWriter {
 public:
  // A new file, or resumes an existing one: then its sets are loaded (has_set()) and kept.
  // Throws tomorig::Error (bad_input) if the existing file is not a results file, belongs to
  // another session (different identity) or was made with different parameters; or if the
  // folder is missing or the path is a folder. Nothing is written before the first add().
  ResultsWriter(const std::filesystem::path& path, const ResultsInfo& info, const ResultsWriterOptions& options = {});
  ~ResultsWriter();
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;

  bool has_set(std::uint64_t set_index) const;
  const std::vector<SetResult>& sets() const;  // in the order added (resumed ones first)
  std::uint64_t resumed_sets() const;          // sets found in the existing file
  // Adds a finished set and rewrites the file (statistics and XDMF sidecar included),
  // atomically. Throws bad_input for a set already present, a field of another shape or dt <= 0;
  // runtime (file left as it was, the set not added) if writing fails, e.g. a full disk.
  void add(SetResult set);
  // Rewrites the file with what it holds (e.g. to create an empty results file).
  void write();

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
  std::vector<std::uint64_t> set_indices() const;  // ascending
  SetResult read_set(std::uint64_t set_index) const;  // bad_input if absent
  std::vector<SetResult> read_all_sets() const;
  bool has_statistics() const;                        // false with no set
  EnsembleStatistics statistics() const;              // bad_input if none

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::storage

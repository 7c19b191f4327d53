#pragma once
// Volume files: reconstructed (or ground-truth) volumes in HDF5 with an XDMF sidecar, so that
// ParaView opens them directly. Layout in docs/file-formats.md ("Volume file").
//
//   VolumeFileWriter out("v.h5", {.source_session = "s.h5", .set_index = 0});
//   out.add("a", sparse_a, {.algorithm = "fmart", .report_json = report});
//   out.finish();             // writes v.h5 and v.xdmf, atomically
//   VolumeFileReader in("v.h5");
//   DenseVolume a = in.read_dense("a");
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/core/volume.h"

namespace tomorig::storage {

struct VolumeFileInfo {
  std::string source_session;   // session the volumes came from ("" if none)
  std::uint64_t set_index = 0;  // set of that session
  std::string parameters_json;  // processing parameters, a JSON object ("" if none)
};

struct VolumeFileOptions {
  bool overwrite = false;
  // Also store each sparse volume densely (ParaView reads only the dense form). Dense data is
  // deflate-compressed, which every HDF5 build (and so ParaView and MATLAB) can read.
  bool dense_export = true;
};

struct VolumeAttributes {
  std::string algorithm;    // "fmart", "mlos", "truth", ...
  std::string exposure;     // "A", "B" or ""
  std::string report_json;  // the reconstruction report, a JSON object ("" if none)
};

class VolumeFileWriter {
 public:
  // Checks that the destination can be written; nothing is created under the final name
  // before finish(). Throws tomorig::Error (bad_input) for an existing file without
  // overwrite, a missing folder, or a name that is a folder.
  VolumeFileWriter(const std::filesystem::path& path, const VolumeFileInfo& info,
                   const VolumeFileOptions& options = {});
  ~VolumeFileWriter();  // without finish(): removes the partial file
  VolumeFileWriter(const VolumeFileWriter&) = delete;
  VolumeFileWriter& operator=(const VolumeFileWriter&) = delete;

  // `name` becomes /volumes/<name>; letters, digits, '_', '-' and '.' only; unique.
  void add(const std::string& name, const SparseVolume& volume, const VolumeAttributes& attributes);
  void add(const std::string& name, const DenseVolume& volume, const VolumeAttributes& attributes);
  // Closes the file, writes the XDMF sidecar (<stem>.xdmf) if any volume has dense data, and
  // renames both into place.
  void finish();

  static std::filesystem::path sidecar_path(const std::filesystem::path& volume_file);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct StoredVolume {
  std::string name;
  VoxelGrid grid;
  VolumeAttributes attributes;
  bool has_sparse = false;
  bool has_dense = false;
};

class VolumeFileReader {
 public:
  // Throws tomorig::Error (bad_input) naming the file and the problem for a missing, corrupt
  // or foreign file.
  explicit VolumeFileReader(const std::filesystem::path& path);
  ~VolumeFileReader();

  const VolumeFileInfo& info() const;
  const std::vector<StoredVolume>& volumes() const;
  // Throws bad_input listing the stored names if `name` is not stored.
  const StoredVolume& volume(const std::string& name) const;
  DenseVolume read_dense(const std::string& name) const;
  // The sparse form if stored, else the non-zero voxels of the dense form.
  SparseVolume read_sparse(const std::string& name) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::storage

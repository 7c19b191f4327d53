#pragma once
// The PSF file: each camera's PSF over depth as `tomorig optics psf --psf-out` measures it
// from chessboard calibration images (voxel_psf.h), and as `tomorig reconstruct --psf` /
// `tomorig process --psf` read it into the reconstruction's depth-varying PSF
// (reconstruction/psf_model.h: sigma_px per depth). TOML, docs/spray.md:
//
//   kind = "psf-table"         # tells it from an optics set-up file (optional on reading)
//   voxel_mm = 0.0306          # the voxel planes the images were back-projected onto
//   axis = "y"                 # the spread measured across the board lines along x
//   [[cameras]]
//   id = "cam1"
//   z_mm = [-4.5, 0.0, 4.5]
//   chi_um = [60.1, 42.0, 56.3]        # the camera's PSF half-width, object um (visibility)
//   chi_voxel_um = [65.0, 48.0, 61.2]  # as measured in the voxel planes (thesis Fig. 6.15)
//   sigma_px = [1.02, 0.66, 0.95]      # the reconstruction's weight sigma, pixels
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tomorig::optics {

struct PsfTableCamera {
  std::string id;
  std::vector<double> z_mm;          // ascending
  std::vector<double> chi_um;        // per depth
  std::vector<double> chi_voxel_um;  // per depth
  std::vector<double> sigma_px;      // per depth
};

struct PsfTable {
  double voxel_mm = 0;
  std::string axis = "y";
  std::vector<PsfTableCamera> cameras;
  // Throws bad_input naming the camera and field: no cameras, array lengths differ, z not
  // strictly ascending, a chi or sigma not > 0, voxel_mm not > 0.
  void validate() const;
  // The camera with this id, or nullptr.
  const PsfTableCamera* find(const std::string& id) const;
};

// `header` (comment lines without the '#') goes on top.
std::string psf_table_toml(const PsfTable& table, const std::string& header);
// Throws bad_input naming the file, key path and line.
PsfTable parse_psf_table(std::string_view toml_text, const std::string& source);
PsfTable read_psf_table(const std::filesystem::path& path);

// Whether a file given to `--psf` is a PSF table rather than an optics set-up file: its `kind`
// says so, or (files written before `kind` existed) its first camera has `sigma_px`. A file
// that cannot be read or parsed is not one: the set-up reader then names what is wrong.
bool is_psf_table_file(const std::filesystem::path& path);

}  // namespace tomorig::optics

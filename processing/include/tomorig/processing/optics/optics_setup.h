#pragma once
// The optics set-up file of `tomorig optics visibility --setup FILE` (docs/spray.md): the liquid,
// the LED spectrum and, per camera, f-number, magnification, bright-field noise and the PSF
// half-width chi over depth (e.g. from `tomorig optics psf`).
//
//   liquid = "kerosene"            # water | kerosene
//   [led]                          # optional; default the thesis's green LED (514 nm, 37 nm)
//   peak_nm = 514
//   fwhm_nm = 37
//   [[cameras]]
//   id = "cam1"
//   f_number = 22
//   magnification = 0.85
//   noise = 0.010                  # sigma of the flat-fielded bright field, or threshold = 0.980
//   z_mm = [-4.5, 0.0, 4.5]
//   chi_um = [62.0, 40.0, 60.0]
#include <filesystem>
#include <string>
#include <string_view>

#include "tomorig/processing/optics/visibility.h"

namespace tomorig::optics {

// Throws bad_input naming the file, key path and line, and what is allowed.
VisibilitySetup parse_optics_setup(std::string_view toml_text, const std::string& source);
VisibilitySetup read_optics_setup(const std::filesystem::path& path);

}  // namespace tomorig::optics

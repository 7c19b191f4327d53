#pragma once
// Illumination across the light sheet: a factor in [0, 1] on each particle's peak intensity,
// as a function of world z (the sheet normal of every built-in case).
#include <optional>
#include <string>
#include <string_view>

#include "tomorig/simulators/scene.h"

namespace tomorig::sim {

enum class LightSheetProfile {
  uniform,   // every particle fully lit
  gaussian,  // exp(-dz^2 / 2 s^2) with 4 s = thickness: the slab faces get 13.5 %
  tophat,    // flat inside, erf edges of width `edge_mm` (1 sigma), 50 % at the slab faces
};
// The rig file's words for the profiles ([simulation] light_sheet) are config's
// (config::LightSheetProfile); rig/ maps one onto the other.

struct LightSheet {
  LightSheetProfile profile = LightSheetProfile::uniform;
  double centre_z_mm = 0.0;
  double thickness_mm = 0.0;  // full thickness (gaussian: 4 sigma; tophat: between 50 % points)
  double edge_mm = 0.0;       // tophat only: 1-sigma width of each soft edge

  // A sheet that fills `slab` in z; the tophat edge is 5 % of the thickness.
  static LightSheet for_slab(LightSheetProfile profile, const Slab& slab);
  // Relative intensity at world z (mm), in [0, 1].
  double intensity(double z_mm) const;
};

}  // namespace tomorig::sim

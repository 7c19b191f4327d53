#include "tomorig/simulators/light_sheet.h"

#include <cmath>
#include <numbers>

namespace tomorig::sim {

LightSheet LightSheet::for_slab(LightSheetProfile profile, const Slab& slab) {
  LightSheet sheet;
  sheet.profile = profile;
  sheet.centre_z_mm = slab.centre().z;
  sheet.thickness_mm = slab.size().z;
  sheet.edge_mm = 0.05 * sheet.thickness_mm;
  return sheet;
}

double LightSheet::intensity(double z_mm) const {
  const double dz = z_mm - centre_z_mm;
  switch (profile) {
    case LightSheetProfile::uniform: return 1.0;
    case LightSheetProfile::gaussian: {
      if (!(thickness_mm > 0)) return 1.0;
      const double s = thickness_mm / 4.0;
      return std::exp(-dz * dz / (2 * s * s));
    }
    case LightSheetProfile::tophat: {
      const double half = thickness_mm / 2.0;
      if (!(edge_mm > 0)) return std::abs(dz) <= half ? 1.0 : 0.0;
      // Product of two erf steps: 1 well inside, 1/2 at each face, smooth on a scale edge_mm.
      const double a = 1.0 / (std::numbers::sqrt2 * edge_mm);
      return 0.25 * (1 + std::erf((half - dz) * a)) * (1 + std::erf((half + dz) * a));
    }
  }
  return 1.0;
}

}  // namespace tomorig::sim

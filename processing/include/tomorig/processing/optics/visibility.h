#pragma once
// The smallest visible droplet (thesis Sect. 6.4, 7.3.3). After flat-fielding, the bright field
// is 1 +- sigma; a droplet is visible to a camera where its shadow's minimum intensity (Eq. 6.6,
// with the camera's PSF half-width chi at that depth and the droplet's transmission tau) falls to
// the threshold 1 - 2 sigma. A droplet missing in one view is missing in the reconstruction, so
// the set-up's limit at each depth is the largest of the cameras' limits (Fig. 6.16, 7.10).
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/optics/transmission.h"

namespace tomorig::optics {

struct ChiSample {
  double z_mm = 0;    // depth
  double chi_um = 0;  // PSF half-width there, object space
};

struct CameraOptics {
  std::string id;
  double f_number = 22.0;
  double magnification = 0.9;
  double noise_sigma = 0.01;    // sigma of the flat-fielded bright field
  std::vector<ChiSample> chi;   // ascending z, at least one sample
  double threshold() const { return 1.0 - 2.0 * noise_sigma; }
  // chi at depth z by linear interpolation; NaN outside the sampled range.
  double chi_at(double z_mm) const;
};

struct VisibilitySetup {
  Liquid liquid = Liquid::kerosene();
  LedSpectrum spectrum;
  std::vector<CameraOptics> cameras;
  double d_max_um = 200.0;  // droplets larger than this are not searched ("none" beyond)

  // Throws bad_input naming the camera and field: no cameras, f# or M <= 0, noise outside
  // (0, 0.5), no chi samples, z not ascending, chi <= 0, d_max outside (1, 2000].
  void validate() const;
};

// tau(d) of one aperture on a grid (0.5 um steps to 50 um, 1 um beyond), linearly interpolated:
// the visibility search asks for thousands of diameters.
class TransmissionTable {
 public:
  TransmissionTable(const TransmissionModel& model, double na, double d_max_um);
  double na() const { return na_; }
  double d_max() const { return d_.back(); }
  double tau(double d_um) const;

 private:
  double na_;
  std::vector<double> d_, tau_;
};

// The smallest diameter (um) whose minimum intensity reaches `threshold` for this chi; +inf if
// none up to the table's d_max. Found on the table's grid, refined by bisection to 0.01 um.
double smallest_visible_diameter(const TransmissionTable& table, double chi_um, double threshold);

struct VisibilityRow {
  double z_mm = 0;
  std::vector<double> chi_um;    // per camera (NaN: outside its samples)
  std::vector<double> d_min_um;  // per camera (+inf: none visible; NaN: chi unknown)
  double setup_d_min_um = 0;     // max over the cameras
};

// One row per depth in the union of the cameras' z samples, ascending.
std::vector<VisibilityRow> visibility_table(const VisibilitySetup& setup);

// sigma of flat-fielded bright-field frames (Sect. 6.4: 200 frames without spray): each frame is
// divided by the pixelwise mean of all frames and sigma is the spread of the result over every
// pixel, corrected for the mean's own noise by sqrt(N / (N - 1)). Needs >= 2 frames of one size;
// throws bad_input otherwise or if a pixel's mean is <= 0.
double bright_field_noise(std::span<const Image> frames);

inline constexpr double kNotVisible = std::numeric_limits<double>::infinity();

}  // namespace tomorig::optics

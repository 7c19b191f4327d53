// size-thesis-spray: the problem size of the thesis's hollow-cone spray reconstruction
// (Sect. 6.5, Table 6.1), exactly as ../shared/benchmarks/README.md defines it. It is a speed
// and memory case: particle images at 0.03 ppp stand in for the spray, so that the times and
// peak memory compare with the thesis's (timed on a double exposure).
#include "tomorig/simulators/cases.h"
#include "tomorig/simulators/taylor_green.h"

namespace tomorig::sim {

CaseDefinition size_thesis_spray_case() {
  CaseDefinition c;
  c.name = "size-thesis-spray";
  c.description = "thesis spray problem size, Sect. 6.5: 4 cameras of 1600 x 1200 px at yaw 45/15/-15/-45 deg, "
                  "grid 1080 x 1020 x 540 at 60 voxel/mm (speed and memory)";
  // Magnification 60 px/mm x 7.4 um = 0.444 = f / D: a 100 mm lens at 225.2 mm, so a pixel sees
  // 1/60 mm = one voxel at the origin.
  constexpr double kMagnification = 60.0 * 7.4e-3;
  const double yaws[] = {45.0, 15.0, -15.0, -45.0};  // Table 6.1 order
  for (int i = 0; i < 4; ++i) {
    SimulatedCameraSpec cam;
    cam.id = "cam" + std::to_string(i);
    cam.yaw_deg = yaws[i];
    cam.focal_length_mm = 100.0;
    cam.pixel_pitch_um = 7.4;
    cam.distance_mm = 100.0 / kMagnification;
    cam.width = 1600;
    cam.height = 1200;
    cam.pixel_format = PixelFormat::Mono16;
    c.cameras.push_back(cam);
  }
  // 18 x 17 x 9 mm, seeded throughout.
  c.grid = VoxelGrid::centred(1080, 1020, 540, 1.0 / 60.0);
  c.slab = {{-9.0, -8.5, -4.5}, {9.0, 8.5, 4.5}};
  c.sigma_px = 0.75;  // 4 sigma = 3 px
  // The tpiv-thesis flow scaled to this grid (A = 5 voxel, p = half the x edge), so that the
  // double exposure has a known displacement.
  c.make_flow = [](const CaseDefinition& self) { return std::make_unique<TaylorGreenFlow>(self.grid, 5.0, 540.0); };
  return c;
}

}  // namespace tomorig::sim

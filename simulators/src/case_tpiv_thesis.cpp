// tpiv-thesis: the synthetic tomographic PIV case of thesis Sect. 3.2 (Table 3.1, Eq. 3.13),
// exactly as ../shared/benchmarks/README.md defines it.
#include "tomorig/simulators/cases.h"
#include "tomorig/simulators/taylor_green.h"

namespace tomorig::sim {

CaseDefinition tpiv_thesis_case() {
  CaseDefinition c;
  c.name = "tpiv-thesis";
  c.description = "synthetic TPIV, thesis Sect. 3.2: 4 cameras at yaw -42/-14/14/42 deg, "
                  "10 x 10 x 3 mm slab, Taylor-Green vortices (Eq. 3.13)";
  // 100 mm lens at 263.16 mm: magnification 0.38, so a 7.4 um pixel sees 19.47 um ~ 1 voxel.
  const double yaws[] = {-42.0, -14.0, 14.0, 42.0};
  for (int i = 0; i < 4; ++i) {
    SimulatedCameraSpec cam;
    cam.id = "cam" + std::to_string(i);
    cam.yaw_deg = yaws[i];
    cam.focal_length_mm = 100.0;
    cam.pixel_pitch_um = 7.4;
    cam.distance_mm = 263.16;
    cam.width = cam.height = 512;
    cam.pixel_format = PixelFormat::Mono16;
    c.cameras.push_back(cam);
  }
  c.slab = {{-5.0, -5.0, -1.5}, {5.0, 5.0, 1.5}};
  // Voxel (i, j, k) centred at ((i - 255.5), (j - 255.5), (k - 79.5)) * 0.0195 mm.
  c.grid = VoxelGrid::centred(512, 512, 160, 0.0195);
  c.sigma_px = 0.75;  // 4 sigma = 3 px particle image diameter
  // A = 5 voxel; p = 256 voxel = half the 512-voxel edge.
  c.make_flow = [](const CaseDefinition& self) { return std::make_unique<TaylorGreenFlow>(self.grid, 5.0, 256.0); };
  return c;
}

}  // namespace tomorig::sim

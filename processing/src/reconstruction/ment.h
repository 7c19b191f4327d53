#pragma once
// MENT, the maximum entropy technique (thesis Sect. 3.1.1 after Minerbo and Bilsky et al.):
// the iteration runs on one 2-D pseudo-image h_j per camera, and the volume is recovered only at
// the end, z-slice by z-slice, as the product of the pseudo-images at each voxel's image
// positions (Eq. 3.4). The dense volume is never held: each slice's non-zero voxels are appended
// to the sparse output in slice order.
#include <memory>

#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::recon::detail {

std::unique_ptr<Reconstructor> make_ment(const ReconstructionOptions& options);

}  // namespace tomorig::recon::detail

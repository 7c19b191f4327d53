#pragma once
// The dense reference implementation of MENT (thesis Sect. 3.1.1): the same equations as the
// "ment" reconstructor, but every camera update sweeps the whole grid lattice instead of the
// precomputed sparse sample list. Slow; for tests that check the sparse MENT against it on
// small cases.
#include <memory>

#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::recon {

// Same options as make_reconstructor() with algorithm "ment" (the algorithm field is ignored).
std::unique_ptr<Reconstructor> make_ment_dense_reference(const ReconstructionOptions& options);

}  // namespace tomorig::recon

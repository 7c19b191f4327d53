#pragma once
// The concrete reconstructors, each defined in its own .cpp file; make_reconstructor() picks one.
#include <memory>

#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::recon::detail {

std::unique_ptr<Reconstructor> make_mlos(const ReconstructionOptions& options);
std::unique_ptr<Reconstructor> make_mart(const ReconstructionOptions& options);
std::unique_ptr<Reconstructor> make_smart(const ReconstructionOptions& options);
std::unique_ptr<Reconstructor> make_fmart(const ReconstructionOptions& options);

}  // namespace tomorig::recon::detail

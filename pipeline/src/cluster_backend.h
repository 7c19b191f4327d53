#pragma once
// run_backend as one rank of an MPI job (mpirun -n N tomorig process ...). See cluster_backend.cpp.
#include <filesystem>

#include "tomorig/pipeline/backend.h"

namespace tomorig::pipeline {

BackendReport run_backend_on_mpi(const std::filesystem::path& session, const BackendOptions& options,
                                 const BackendHooks& hooks);

}  // namespace tomorig::pipeline

#pragma once
// What identifies a recording whatever its path, for resuming a results file: when it was
// made, its cameras, its rig config and the pixels of its first frame (two simulations of one
// rig differ only there). FNV-1a hashes: stable across builds and machines, unlike std::hash.
#include <string>

#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

std::string session_identity(const storage::SessionReader& session);

}  // namespace tomorig::pipeline

#pragma once
// The preprocessing stage of `tomorig process`: the chain of a TOML file (the format of
// `tomorig preprocess --chain`, docs/preprocessing.md) run on every frame of a set, one chain
// per camera. Sequence statistics (subtract_minimum, normalize by average_image) are computed
// in streaming passes over the whole session when the preprocessor is made.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/processing/preprocess/image_chain.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

// The average of every present frame of `camera_id` in a session of reference frames (darks or
// bright fields), for chain step `step`. Throws tomorig::Error naming the step when the file
// cannot be read or holds no frame of that camera.
Image reference_image(const std::filesystem::path& file, const std::string& camera_id, std::size_t step);

class SessionPreprocessor {
 public:
  // An empty `chain_file`: no preprocessing. Throws tomorig::Error (bad_input) for a bad chain.
  SessionPreprocessor(const storage::SessionReader& session, const std::filesystem::path& chain_file);
  bool empty() const { return chains_.empty(); }
  std::size_t steps() const;
  // Replaces each present frame of `set` by its preprocessed float image. Not thread-safe.
  void apply(FrameSet& set);

 private:
  std::vector<preprocess::ImageChain> chains_;  // session camera order
};

}  // namespace tomorig::pipeline

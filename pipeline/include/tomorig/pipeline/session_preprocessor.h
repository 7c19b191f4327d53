#pragma once
// The preprocessing stage of `tomorig process`: the chain of a TOML file (the format of
// `tomorig preprocess --chain`, docs/preprocessing.md) run on every frame of a set, one chain
// per camera. Sequence statistics (subtract_minimum, normalize by average_image) are computed
// in streaming passes over the session's sets (or a selection of them) when the preprocessor is
// made. Also the chain of `tomorig preprocess` (preprocessed_session.h).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/core/set_selection.h"
#include "tomorig/processing/preprocess/image_chain.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

// The average of every present frame of `camera_id` in a session of reference frames (darks or
// bright fields), for chain step `step`. Throws tomorig::Error naming the step when the file
// cannot be read or holds no frame of that camera.
Image reference_image(const std::filesystem::path& file, const std::string& camera_id, std::size_t step);

class SessionPreprocessor {
 public:
  // After each set of a sequence pass: pass (0-based) of `passes` (the chain's
  // sequence_passes()), sets done of the selection's.
  using PassProgress = std::function<void(std::size_t pass, std::size_t passes, std::uint64_t done)>;

  // An empty `chain_file`: no preprocessing. The sequence statistics come from the sets of
  // `sets` (a contiguous run; default every set). Throws tomorig::Error (bad_input) for a bad
  // chain, or a camera without frames in those sets where a step needs them.
  SessionPreprocessor(const storage::SessionReader& session, const std::filesystem::path& chain_file,
                      const SetSelection& sets = {}, const PassProgress& progress = {});
  // No step to run (no chain file, or a chain without steps).
  bool empty() const { return steps() == 0; }
  std::size_t steps() const;
  // Streaming passes over the sets that the constructor made (one per sequence statistic).
  std::size_t sequence_passes() const { return sequence_passes_; }
  // Replaces each present frame of `set` by its preprocessed float image. Not thread-safe.
  void apply(FrameSet& set);
  // The same rounded and clipped to [0, 65535] (Mono16 frames of a preprocessed session; with
  // a chain file of no steps, the frames converted). Needs a chain file.
  void apply_as_uint16(FrameSet& set);

 private:
  std::vector<preprocess::ImageChain> chains_;  // session camera order; none without a chain file
  std::size_t sequence_passes_ = 0;
};

}  // namespace tomorig::pipeline

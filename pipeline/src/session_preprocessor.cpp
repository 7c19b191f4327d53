#include "tomorig/pipeline/session_preprocessor.h"

#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/preprocess/chain_spec.h"
#include "tomorig/processing/preprocess/sequence_image.h"

namespace tomorig::pipeline {
namespace fs = std::filesystem;

Image reference_image(const fs::path& file, const std::string& camera_id, std::size_t step) {
  const auto reader = [&] {
    try {
      return std::make_unique<storage::SessionReader>(file);
    } catch (const Error& e) {
      throw Error(e.kind(), fmt::format("preprocess step {}: reference frames: {}", step, e.what()));
    }
  };
  const std::unique_ptr<storage::SessionReader> opened = reader();
  const storage::SessionReader& reference = *opened;
  preprocess::MeanImage mean;
  for (std::uint64_t s = 0; s < reference.set_count(); ++s) {
    const FrameSet set = reference.read_set(s);
    for (const CameraFrames& c : set.cameras) {
      if (c.camera_id != camera_id) continue;
      for (const Frame* f : {&c.a, &c.b})
        if (f->present()) mean.add(f->image);
    }
  }
  if (mean.count() == 0)
    throw bad_input(fmt::format("preprocess step {}: reference session '{}' has no frame of camera '{}'", step,
                                file.string(), camera_id));
  return mean.result();
}

SessionPreprocessor::SessionPreprocessor(const storage::SessionReader& session, const fs::path& chain_file,
                                         const SetSelection& sets, const PassProgress& progress) {
  if (chain_file.empty()) return;
  const preprocess::ChainSpec spec = preprocess::read_chain(chain_file.string());
  for (const storage::SessionCamera& camera : session.info().cameras) {
    chains_.emplace_back(spec);
    for (std::size_t i = 0; i < spec.steps.size(); ++i)
      if (preprocess::needs_reference_image(spec.steps[i])) {
        const fs::path file(spec.steps[i].file);
        chains_.back().set_reference_image(
            i, reference_image(file.is_absolute() ? file : chain_file.parent_path() / file, camera.id, i));
      }
  }
  const auto [first, end] = sets.range(session.set_count());
  sequence_passes_ = static_cast<std::size_t>(std::count_if(
      spec.steps.begin(), spec.steps.end(), [](const preprocess::Step& s) { return preprocess::needs_sequence_image(s); }));
  std::size_t pass = 0;
  // One streaming pass per step that needs a sequence statistic, each over the chain up to
  // that step (so a later statistic sees the earlier steps' output).
  for (std::size_t step = 0; step < spec.steps.size(); ++step) {
    if (!preprocess::needs_sequence_image(spec.steps[step])) continue;
    const bool minimum = spec.steps[step].kind == preprocess::StepKind::subtract_minimum;
    std::vector<std::array<preprocess::MinimumImage, 2>> minima(chains_.size());
    std::vector<std::array<preprocess::MeanImage, 2>> means(chains_.size());
    for (std::uint64_t s = first; s < end; ++s) {
      const FrameSet set = session.read_set(s);
      for (std::size_t c = 0; c < set.cameras.size() && c < chains_.size(); ++c)
        for (const Exposure e : {Exposure::A, Exposure::B}) {
          const Frame& frame = set.cameras[c][e];
          if (!frame.present()) continue;
          const Image& partial = chains_[c].run(frame.image, e, step);
          if (minimum) minima[c][static_cast<int>(e)].add(partial);
          else means[c][static_cast<int>(e)].add(partial);
        }
      if (progress) progress(pass, sequence_passes_, s - first + 1);
    }
    for (std::size_t c = 0; c < chains_.size(); ++c)
      for (const Exposure e : {Exposure::A, Exposure::B}) {
        const int k = static_cast<int>(e);
        if ((minimum ? minima[c][k].count() : means[c][k].count()) == 0)
          throw bad_input(fmt::format("camera '{}' has no frame {} in the {} sets from set {}, so preprocess step {} "
                                      "({}) has no sequence image; select more sets",
                                      session.info().cameras[c].id, k == 0 ? "A" : "B", end - first, first, step,
                                      to_string(spec.steps[step].kind)));
        chains_[c].set_sequence_image(step, e, minimum ? minima[c][k].result() : means[c][k].result());
      }
    ++pass;
  }
}

std::size_t SessionPreprocessor::steps() const { return chains_.empty() ? 0 : chains_.front().spec().steps.size(); }

void SessionPreprocessor::apply(FrameSet& set) {
  if (empty()) return;
  for (std::size_t c = 0; c < set.cameras.size() && c < chains_.size(); ++c)
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      Frame& frame = set.cameras[c][e];
      if (frame.present()) frame.image = chains_[c].run(frame.image, e).clone();  // the chain reuses its buffer
    }
}

void SessionPreprocessor::apply_as_uint16(FrameSet& set) {
  if (chains_.empty()) throw std::logic_error("SessionPreprocessor::apply_as_uint16 needs a chain file");
  for (std::size_t c = 0; c < set.cameras.size() && c < chains_.size(); ++c)
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      Frame& frame = set.cameras[c][e];
      if (!frame.present()) continue;
      Image out;  // a fresh image: the FrameSet keeps it (e.g. until a writer has written it)
      preprocess::to_uint16(chains_[c].run(frame.image, e), out);
      frame.image = out;
    }
}

}  // namespace tomorig::pipeline

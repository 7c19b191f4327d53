// frame-stats: per camera, the mean grey level and the fraction of saturated pixels of the
// newest set, so an operator sees at once a camera that is dark, over-exposed or out of step.
// It may skip sets: its figures are about the present, not a census.
//
//   --stage frame-stats                      every camera, 12-bit full scale
//   --stage frame-stats:full_scale=255       8-bit cameras
#include <algorithm>
#include <cstdint>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/stage.h"

namespace tomorig::pipeline {
namespace {

struct FrameStatsOptions {
  double full_scale = 4095.0;  // grey level of a saturated pixel (12-bit cameras)
  bool skip = true;            // may skip sets to stay current
};

struct CameraFigures {
  std::string id;
  double mean_a = 0, mean_b = 0;
  double saturated_a = 0, saturated_b = 0;  // fraction of pixels at or above full scale
  bool present_a = false, present_b = false;
};

// Mean and saturated fraction of one frame (integer or float samples).
template <typename T>
void measure(const Image& image, double full_scale, double& mean, double& saturated) {
  double sum = 0;
  std::uint64_t at_top = 0;
  for (int y = 0; y < image.height(); ++y) {
    const T* row = image.row<T>(y);
    for (int x = 0; x < image.width(); ++x) {
      sum += row[x];
      at_top += static_cast<double>(row[x]) >= full_scale ? 1 : 0;
    }
  }
  const double n = static_cast<double>(image.width()) * image.height();
  mean = n > 0 ? sum / n : 0;
  saturated = n > 0 ? at_top / n : 0;
}

void measure(const Frame& frame, double full_scale, bool& present, double& mean, double& saturated) {
  present = frame.present();
  if (!present) return;
  switch (frame.image.type()) {
    case SampleType::u8: measure<std::uint8_t>(frame.image, full_scale, mean, saturated); break;
    case SampleType::u16: measure<std::uint16_t>(frame.image, full_scale, mean, saturated); break;
    default: measure<float>(frame.image, full_scale, mean, saturated); break;
  }
}

class FrameStatsStage final : public Stage {
 public:
  void configure(const StageTable& table) override {
    options_.full_scale = table.number("full_scale", options_.full_scale);
    options_.skip = table.flag("skip", options_.skip);
    if (!(options_.full_scale > 0))
      throw bad_input(fmt::format("stage 'frame-stats': full_scale = {:g} must be > 0", options_.full_scale));
  }
  void process(const FrameSet& set) override {
    std::vector<CameraFigures> figures;
    for (const CameraFrames& c : set.cameras) {
      CameraFigures f{.id = c.camera_id};
      measure(c.a, options_.full_scale, f.present_a, f.mean_a, f.saturated_a);
      measure(c.b, options_.full_scale, f.present_b, f.mean_b, f.saturated_b);
      figures.push_back(std::move(f));
    }
    latest_ = std::move(figures);
    latest_index_ = set.trigger_index;
  }
  nlohmann::json status() const override {
    nlohmann::json cameras = nlohmann::json::array();
    for (const CameraFigures& f : latest_)
      cameras.push_back({{"id", f.id},
                         {"mean", {f.present_a ? nlohmann::json(f.mean_a) : nullptr,
                                   f.present_b ? nlohmann::json(f.mean_b) : nullptr}},
                         {"saturated_fraction", {f.saturated_a, f.saturated_b}}});
    return {{"trigger_index", latest_index_}, {"cameras", cameras}};
  }
  bool may_skip() const override { return options_.skip; }

 private:
  FrameStatsOptions options_;
  std::vector<CameraFigures> latest_;
  std::uint64_t latest_index_ = 0;
};

}  // namespace

std::unique_ptr<Stage> make_frame_stats_stage() { return std::make_unique<FrameStatsStage>(); }

}  // namespace tomorig::pipeline

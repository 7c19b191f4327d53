// recorder: rig::Recorder as a stage, for chains fed by a replay or a second rig. It sees
// every set (a recorder never skips) and writes a live session file; the cameras and rig
// config come from the recording it is told about.
//
//   --stage recorder:out=copy.h5,compression=bitshuffle-lz4
#include "tomorig/pipeline/stage.h"
#include "tomorig/rig/recorder.h"

namespace tomorig::rig {
namespace {

class RecorderStage final : public pipeline::Stage {
 public:
  void configure(const pipeline::StageTable& table) override {
    options_.out = table.text("out", options_.out.string());
    compression_ = table.text("compression", compression_);
    options_.compression = parse_compression_option(compression_);
    options_.overwrite = table.flag("overwrite", options_.overwrite);
    options_.disk_reserve_mb = table.number("disk_reserve_mb", options_.disk_reserve_mb);
    prepare_output(options_);  // refuse an existing file now, before the chain starts
  }
  void begin(const pipeline::SessionDescription& recording) override {
    options_.cameras = recording.cameras;
    options_.rig_config_toml = recording.rig_toml;
    options_.truth = recording.truth;
    recorder_ = std::make_unique<Recorder>(options_);
  }
  void process(const FrameSet& set) override { recorder_->add(set); }
  void end() override {
    if (recorder_ && recorder_->started()) recorder_->finish();
  }
  nlohmann::json status() const override {
    if (!recorder_) return nlohmann::json::object();
    const RecorderReport& r = recorder_->report();
    return {{"out", r.out.string()}, {"written", r.written}, {"refused", r.refused}, {"bytes", r.bytes},
            {"disk_full", r.disk_full}, {"finished", r.finished}};
  }

 private:
  RecorderOptions options_;
  std::string compression_ = "none";
  std::unique_ptr<Recorder> recorder_;
};

}  // namespace

std::unique_ptr<pipeline::Stage> make_recorder_stage() { return std::make_unique<RecorderStage>(); }

}  // namespace tomorig::rig

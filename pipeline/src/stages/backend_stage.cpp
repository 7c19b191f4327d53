// backend: the back-end as a stage. Each set it takes is reconstructed (both exposures) and
// correlated into a results file, as `tomorig process` does for a session, but for sets as
// they come: from a live rig (where it would fall behind, so `skip=true` lets it take the
// newest set whenever it is free) or from a replayed session. No preprocessing chain and no
// resume: a new results file per run.
//
//   --stage backend:out=live.h5,grid=96,96,160,0.0195,window=32,32,32,skip=true
#include <cstdint>

#include <fmt/core.h>

#include "../pair_processor.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/stage.h"

namespace tomorig::pipeline {
namespace {

class BackendStage final : public Stage {
 public:
  void configure(const StageTable& table) override {
    BackendOptions& o = options_;
    o.out = table.text("out", o.out.string());
    o.calib = table.text("calib", o.calib);
    o.overwrite = table.flag("overwrite", o.overwrite);
    o.threads = static_cast<int>(table.integer("threads", o.threads));
    o.dt_ns = table.integer("dt_ns", o.dt_ns);
    ReconstructionChoices& r = o.reconstruction;
    r.algorithm = table.text("algorithm", r.algorithm);
    r.iterations = static_cast<int>(table.integer("iterations", r.iterations));
    r.options.relaxation = table.number("relaxation", r.options.relaxation);
    r.options.mlos_threshold = table.number("mlos_threshold", r.options.mlos_threshold);
    r.options.prune_fraction = table.number("prune_fraction", r.options.prune_fraction);
    r.grid = table.text("grid", r.grid);
    r.sigma_px = table.number("sigma_px", r.sigma_px);
    CorrelationArgs& c = o.correlation;
    c.window = table.text("window", c.window);
    c.overlap = table.number("overlap", c.overlap);
    c.deformation_passes = static_cast<int>(table.integer("deformation_passes", c.deformation_passes));
    skip_ = table.flag("skip", skip_);
    if (o.out.empty()) throw bad_input("stage 'backend' needs out=<results file>");
    o.validate();
  }

  void begin(const SessionDescription& recording) override {
    processor_ = std::make_unique<PairProcessor>(recording, options_);
    writer_ = std::make_unique<storage::ResultsWriter>(
        options_.out,
        storage::ResultsInfo{.session_path = recording.name,
                             .session_identity = "stage backend of " + recording.name,
                             .parameters_json = processor_->parameters().dump(),
                             .voxel_size_mm = processor_->input().grid.voxel_size},
        storage::ResultsWriterOptions{.overwrite = options_.overwrite});
    if (writer_->resumed_sets() > 0)
      throw bad_input(fmt::format("stage 'backend': '{}' already holds sets; choose another out or overwrite=true",
                                  options_.out.string()));
    writer_->write();
  }

  void process(const FrameSet& set) override {
    const std::int64_t dt = options_.dt_ns > 0 ? options_.dt_ns : set.dt_ns;
    if (dt <= 0)
      throw bad_input(fmt::format("stage 'backend': set {} has no pulse separation; give dt_ns=<ns>", set.set_index));
    const ReconstructedSet pair = processor_->reconstruct(set, next_index_, dt);
    piv::CorrelationReport report;
    writer_->add(processor_->correlate(pair, report));
    ++next_index_;
    valid_sum_ += report.valid_fraction();
  }

  void end() override {
    if (writer_) writer_->close();
  }

  nlohmann::json status() const override {
    return {{"out", options_.out.string()},
            {"sets_written", next_index_},
            {"mean_valid_fraction", next_index_ > 0 ? valid_sum_ / static_cast<double>(next_index_) : 0.0}};
  }

  bool may_skip() const override { return skip_; }

 private:
  BackendOptions options_;
  bool skip_ = false;
  std::unique_ptr<PairProcessor> processor_;
  std::unique_ptr<storage::ResultsWriter> writer_;
  std::uint64_t next_index_ = 0;  // sets are numbered in the order this stage took them
  double valid_sum_ = 0.0;
};

}  // namespace

std::unique_ptr<Stage> make_backend_stage() { return std::make_unique<BackendStage>(); }

}  // namespace tomorig::pipeline

#include "tomorig/pipeline/stage_registry.h"

#include <stdexcept>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::pipeline {

StageSpec parse_stage_spec(const std::string& text) {
  const std::size_t colon = text.find(':');
  const std::string type = text.substr(0, colon);
  if (type.empty())
    throw bad_input(fmt::format("--stage '{}' names no stage: give TYPE or TYPE:key=value,key=value", text));
  return {type, colon == std::string::npos ? StageTable({}, type) : StageTable::parse(text.substr(colon + 1), type)};
}

void StageRegistry::add(std::string type, std::string summary, StageFactory factory) {
  for (const auto& [known, ignored] : summaries_)
    if (known == type) throw std::logic_error("stage type '" + type + "' registered twice");
  summaries_.emplace_back(std::move(type), std::move(summary));
  factories_.push_back(std::move(factory));
}

std::unique_ptr<Stage> StageRegistry::create(const StageSpec& spec) const {
  for (std::size_t i = 0; i < summaries_.size(); ++i)
    if (summaries_[i].first == spec.type) {
      std::unique_ptr<Stage> stage = factories_[i]();
      stage->configure(spec.table);
      spec.table.check_all_used();
      return stage;
    }
  std::string known;
  for (const auto& [type, summary] : summaries_) known += (known.empty() ? "" : ", ") + type;
  throw bad_input(fmt::format("there is no stage '{}'; the stages are: {}", spec.type, known));
}

StageChain make_chain(const StageRegistry& registry, const std::vector<StageSpec>& specs) {
  StageChain chain;
  for (const StageSpec& spec : specs) chain.add(spec.type, registry.create(spec));
  return chain;
}

}  // namespace tomorig::pipeline

#include "decode.h"

namespace tomorig::config::detail {

void decode_processing(TableReader& root, ProcessingConfig& processing) {
  auto r = root.table("processing");
  if (!r) return;
  r->read("algorithm", processing.algorithm, Need::optional,
          one_of<std::string>({"mlos", "ment", "mart", "smart", "fmart"}));
  r->read("iterations", processing.iterations, Need::optional, at_least(1));
  r->report_unknown_keys();
}

}  // namespace tomorig::config::detail

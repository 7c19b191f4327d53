#include "decode.h"

namespace tomorig::config::detail {

RigConfig decode_rig(const toml::table& root_table, std::vector<ConfigIssue>& issues) {
  RigConfig rig;
  TableReader root(root_table, "", issues);
  root.read("name", rig.name);
  decode_trigger(root, rig.trigger);
  decode_cameras(root, rig.trigger, rig.cameras);
  if (auto calibration = root.table("calibration")) {
    std::string file;
    if (calibration->read("file", file, Need::required, not_empty())) rig.calibration_file = file;
    calibration->report_unknown_keys();
  }
  decode_grid(root, rig.grid);
  decode_processing(root, rig.processing);
  decode_simulation(root, rig.simulation);
  decode_quicklook(root, rig.quicklook);
  decode_dashboard(root, rig.dashboard);
  root.report_unknown_keys();
  return rig;
}

}  // namespace tomorig::config::detail

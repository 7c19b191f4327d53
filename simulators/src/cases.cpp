#include "tomorig/simulators/cases.h"

#include "tomorig/core/error.h"

namespace tomorig::sim {

const std::vector<CaseDefinition>& cases() {
  // Built once, on first use; every case is a plain value after that.
  static const std::vector<CaseDefinition> all{tpiv_thesis_case(), size_thesis_spray_case()};
  return all;
}

std::string case_names() {
  std::string names;
  for (const CaseDefinition& c : cases()) names += (names.empty() ? "" : ", ") + c.name;
  return names;
}

const CaseDefinition& find_case(std::string_view name) {
  for (const CaseDefinition& c : cases())
    if (c.name == name) return c;
  throw bad_input("unknown simulation case '" + std::string(name) + "': available cases are " + case_names());
}

}  // namespace tomorig::sim

#pragma once
// Helpers shared by the config test files: where a fixture line is, and what the parser said.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "tomorig/config/rig_config.h"

namespace tomorig::config::test_support {

// 1-based line of the first line containing `needle`: tests say where a problem is by its
// text, so editing a fixture cannot silently shift what they expect.
inline int line_containing(const std::string& doc, const std::string& needle) {
  std::istringstream in(doc);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (line.find(needle) != std::string::npos) return n;
  ADD_FAILURE() << "fixture has no line containing " << needle;
  return -1;
}

// Every issue, one per line, for failure messages.
inline std::string dump(const std::vector<ConfigIssue>& issues) {
  std::string out;
  for (const auto& i : issues) out += "  " + i.to_string() + "\n";
  return out.empty() ? "  (no issues)\n" : out;
}

}  // namespace tomorig::config::test_support

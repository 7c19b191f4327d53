// The named chains: shadow preprocessing A and B of thesis Sect. 7.4, kept as TOML text so they
// go through the same parser and checks as a chain file, and print as one.
#include <array>
#include <fstream>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/preprocess/chain_spec.h"

namespace tomorig::preprocess {
namespace {

// Preprocessing A: the 3 x 3 median against sensor pixel artefacts, a flat-field by the frame's
// own bright field (the thesis divides by a bright-field recording; a spray session has none, and
// shadows cover a small part of each 64 x 64 tile, so the tile median is the bright field; the
// pulse-to-pulse LED variation goes with it), inversion (bright field 1000 -> 0, a full shadow ->
// 1000), and a constant offset of 2 sigma of the background subtracted, clipping the pixel noise.
// For the spatial distribution of the liquid (Fig. 7.12).
constexpr std::string_view kShadowA = R"(# shadow-a: thesis Sect. 7.4, preprocessing A (tomorig preprocess --chain shadow-a)
[[preprocess.steps]]
kind = "median"
size = 3

[[preprocess.steps]]
kind = "normalize"
by = "local"
size = 64
target = 1000

[[preprocess.steps]]
kind = "invert"
max = 1000

[[preprocess.steps]]
kind = "clip"
sigmas = 2
subtract = true
)";

// Preprocessing B: A, then the local minimum in a 20 x 20 kernel subtracted (the unstructured
// background between droplet shadows) and a constant threshold of 10 counts (1 % of the bright
// field, about one sigma of its noise): sharper droplet borders, a higher correlation peak.
// For droplet velocities (3-D correlation) and droplet detection.
constexpr std::string_view kShadowBTail = R"(
[[preprocess.steps]]
kind = "subtract_local_minimum"
size = 20

[[preprocess.steps]]
kind = "clip"
level = 10
)";

const std::string& shadow_b_text() {
  static const std::string text = [] {
    std::string t(kShadowA);
    t.replace(0, t.find('\n'), "# shadow-b: thesis Sect. 7.4, preprocessing B (tomorig preprocess --chain shadow-b)");
    return t + std::string(kShadowBTail);
  }();
  return text;
}

}  // namespace

std::vector<std::string_view> preset_names() { return {"shadow-a", "shadow-b"}; }

std::string_view preset_chain_toml(std::string_view name) {
  if (name == "shadow-a") return kShadowA;
  if (name == "shadow-b") return shadow_b_text();
  return {};
}

ChainSpec read_chain(const std::string& chain) {
  const std::string_view preset = preset_chain_toml(chain);
  if (!preset.empty()) return parse_chain(preset, "preset " + chain);
  return read_chain_file(chain);
}

std::string chain_text(const std::string& chain) {
  if (chain.empty()) return "";
  const std::string_view preset = preset_chain_toml(chain);
  if (!preset.empty()) return std::string(preset);
  std::ifstream in(chain, std::ios::binary);
  if (!in)
    throw bad_input(fmt::format("cannot read the chain file '{}': check the path, or name a preset ({})", chain,
                                fmt::join(preset_names(), ", ")));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace tomorig::preprocess

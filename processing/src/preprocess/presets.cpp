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

// Preprocessing A: a flat-field by the frame's own bright field (the thesis divides by a
// bright-field recording; a spray session has none, and shadows cover a small part of each
// 64 x 64 tile, so the tile median is the bright field; the pulse-to-pulse LED variation goes
// with it), inversion, and a constant offset of 2 sigma of the background subtracted, clipping
// the pixel noise. The inversion maps the bright field to 100, not 0: invert clips at 0, and a
// background whose lower half is cut away would show the clip a robust sigma of ~0. The thesis's
// 3 x 3 median (sCMOS pixel artefacts) is left out: where a droplet near the visibility limit is
// a shadow of 1-2 px (the reduced case's 29 um object pixel), the median erases it. Add a median
// step in a chain file for a sensor with hot pixels. For the spatial distribution of the liquid
// (Fig. 7.12) and droplet detection.
constexpr std::string_view kShadowA = R"(# shadow-a: thesis Sect. 7.4, preprocessing A (tomorig preprocess --chain shadow-a)
[[preprocess.steps]]
kind = "normalize"
by = "local"
size = 64
target = 1000

[[preprocess.steps]]
kind = "invert"
max = 1100

[[preprocess.steps]]
kind = "clip"
sigmas = 2
subtract = true
)";

// Preprocessing B: A, then the local minimum in a 20 x 20 kernel subtracted (the unstructured
// background between droplet shadows) and a constant threshold of 10 counts (1 % of the bright
// field, about one sigma of its noise): sharper droplet borders, a higher correlation peak, at
// the cost of the faintest droplets. For droplet velocities (3-D correlation).
constexpr std::string_view kShadowBTail = R"(
[[preprocess.steps]]
kind = "subtract_local_minimum"
size = 20

[[preprocess.steps]]
kind = "clip"
level = 10
)";

// Detection: A with the offset at 0 sigma: the background is subtracted and the noise above it
// kept. The set-up's visibility limit is where a droplet's deepest pixel reaches 1 - 2 sigma in
// its worst view, so A's 2 sigma offset takes exactly the droplets at the limit away; the views'
// agreement in the reconstruction, not the clip, then tells droplets from noise (at the price
// of ghost blobs, which the truth comparison counts).
const std::string& shadow_detect_text() {
  static const std::string text = [] {
    std::string t(kShadowA);
    t.replace(0, t.find('\n'), "# shadow-detect: preprocessing A without the 2 sigma offset, for droplet detection");
    t.replace(t.find("sigmas = 2"), 10, "sigmas = 0");
    return t;
  }();
  return text;
}

const std::string& shadow_b_text() {
  static const std::string text = [] {
    std::string t(kShadowA);
    t.replace(0, t.find('\n'), "# shadow-b: thesis Sect. 7.4, preprocessing B (tomorig preprocess --chain shadow-b)");
    return t + std::string(kShadowBTail);
  }();
  return text;
}

}  // namespace

std::vector<std::string_view> preset_names() { return {"shadow-a", "shadow-b", "shadow-detect"}; }

std::string_view preset_chain_toml(std::string_view name) {
  if (name == "shadow-a") return kShadowA;
  if (name == "shadow-b") return shadow_b_text();
  if (name == "shadow-detect") return shadow_detect_text();
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

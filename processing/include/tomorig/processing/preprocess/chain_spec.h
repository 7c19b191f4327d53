#pragma once
// The description of an image preprocessing chain: an ordered list of steps with their
// parameters, read from TOML (docs/preprocessing.md). The spec is plain data; ImageChain
// (image_chain.h) runs it on frames.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tomorig::preprocess {

enum class StepKind {
  subtract_dark,           // I - D (a dark image per camera, or a constant level)
  subtract_minimum,        // I - min over the sequence (per camera and exposure)
  subtract_local_minimum,  // I - min over a sliding size x size window
  median,                  // median over size x size (3 or 5)
  lowpass,                 // Gaussian low-pass, sigma in pixels
  highpass,                // I - Gaussian low-pass, clipped at 0
  normalize,               // I / mean(I) * target, or I / average image * target
  flat_field,              // I / B * mean(B), B a bright-field image per camera
  invert,                  // max - I (shadowgraphs), clipped at 0
  clip,                    // values below a threshold (constant, or median + k robust sigma) set to 0
};

// mean: the frame's mean; average_image: the sequence's average image; local: the frame's own
// bright field, the median of each size x size tile interpolated between the tile centres (a
// flat-field for shadowgraphs without a separate bright-field recording: shadows cover a small
// part of any tile).
enum class NormalizeBy { mean, average_image, local };

// Tile of normalize by = "local" when the chain file names none, pixels.
inline constexpr int kLocalNormalizeTile = 64;

struct Step {
  StepKind kind = StepKind::median;
  int size = 3;               // subtract_local_minimum, median; normalize by local: the tile (default 64)
  double sigma = 1.0;         // lowpass, highpass
  NormalizeBy by = NormalizeBy::mean;
  double target = 1000.0;     // normalize: the mean (or average-image level) maps to this
  std::string file;           // subtract_dark, flat_field: session file of reference frames
  double level = 0.0;         // subtract_dark (constant dark), clip (constant threshold)
  bool use_sigmas = false;    // clip: threshold = background mean + sigmas * background sigma
  double sigmas = 3.0;
  bool subtract = false;      // clip: also subtract the threshold from what is kept
  double max = 65535.0;       // invert
};

struct ChainSpec {
  std::vector<Step> steps;
};

std::string_view to_string(StepKind kind);

// Steps whose parameters come from a first pass over the whole sequence.
bool needs_sequence_image(const Step& step);
// Steps that need a reference image per camera (dark or bright field) from `file`.
bool needs_reference_image(const Step& step);

// Checks one step's parameters; bad_input naming "step <index> (<kind>): <parameter>".
void validate(const Step& step, std::size_t index);

// Parses `[[preprocess.steps]]` tables. Errors are bad_input naming `source`, the key path
// (preprocess.steps[i].key), its line and what is allowed; unknown keys are errors.
ChainSpec parse_chain(std::string_view toml_text, const std::string& source);
ChainSpec read_chain_file(const std::filesystem::path& path);

// Named chains (docs/preprocessing.md, "Presets"): "shadow-a" and "shadow-b", the shadow
// preprocessing A and B of thesis Sect. 7.4, and "shadow-detect" (A without its 2 sigma offset,
// for droplet detection down to the visibility limit). Wherever a chain file is asked for
// (`--chain`), a preset name stands for that chain.
std::vector<std::string_view> preset_names();
// The preset's TOML text, or empty if `name` is not a preset.
std::string_view preset_chain_toml(std::string_view name);
// A preset (by name) or a chain file: read_chain_file unless `chain` names a preset.
ChainSpec read_chain(const std::string& chain);
// The chain's TOML text, for records of what was run: the preset's or the file's.
std::string chain_text(const std::string& chain);

}  // namespace tomorig::preprocess

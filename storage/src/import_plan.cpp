// plan_image_import: files per camera, and which frames form a set, before reading pixels.
#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <optional>
#include <unordered_set>
#include <utility>

#include <fmt/format.h>

#include "image_sequence.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/image_import.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace {

constexpr std::array<std::pair<FramePairing, std::string_view>, 3> kPairingNames{{
    {FramePairing::automatic, "auto"}, {FramePairing::by_name, "name"}, {FramePairing::by_order, "order"}}};

// Exposure named by the last character of the file stem: 'a' or 'b', either case.
std::optional<int> exposure_suffix(const fs::path& file) {
  const std::string stem = file.stem().string();
  if (stem.size() < 2) return std::nullopt;  // "a.tif" alone names no sequence
  const char last = static_cast<char>(std::tolower(static_cast<unsigned char>(stem.back())));
  if (last == 'a') return 0;
  if (last == 'b') return 1;
  return std::nullopt;
}

// The other exposure's file: "im00001a.tif" <-> "im00001b.tif", keeping the letter's case.
fs::path partner_of(const fs::path& file) {
  std::string stem = file.stem().string();
  char& last = stem.back();
  const bool upper = std::isupper(static_cast<unsigned char>(last)) != 0;
  const bool is_a = std::tolower(static_cast<unsigned char>(last)) == 'a';
  last = is_a ? (upper ? 'B' : 'b') : (upper ? 'A' : 'a');
  return file.parent_path() / (stem + file.extension().string());
}

std::vector<ImageSource> pages_of(const fs::path& file) {
  const int pages = image_page_count(file);
  std::vector<ImageSource> out;
  for (int p = 0; p < pages; ++p) out.push_back({file, p, pages});
  return out;
}

void pair_by_name(ImportPlan::Camera& camera) {
  // Keyed by the file name without the a/b letter; the map keeps sets in natural order.
  struct Pair {
    std::optional<fs::path> file[2];
  };
  auto key_less = [](const std::string& x, const std::string& y) { return natural_less(x, y); };
  std::map<std::string, Pair, decltype(key_less)> pairs(key_less);
  for (const fs::path& file : camera.files) {
    const auto e = exposure_suffix(file);
    if (!e)
      throw bad_input(fmt::format("camera {}: cannot pair '{}' by name: its name does not end in 'a' or 'b' before "
                                  "the extension (pair by order instead)",
                                  camera.id, file.string()));
    std::string stem = file.stem().string();
    stem.pop_back();
    Pair& pair = pairs[(file.parent_path() / stem).string() + file.extension().string()];
    if (pair.file[*e])
      throw bad_input(fmt::format("camera {}: '{}' and '{}' are both frame {} of the same set", camera.id,
                                  pair.file[*e]->string(), file.string(), *e == 0 ? 'A' : 'B'));
    pair.file[*e] = file;
  }
  for (const auto& [key, pair] : pairs) {
    for (int e = 0; e < 2; ++e)
      if (!pair.file[e]) {
        const fs::path& present = *pair.file[1 - e];
        throw bad_input(fmt::format("camera {}: '{}' has no partner: expected '{}'", camera.id, present.string(),
                                    partner_of(present).string()));
      }
    const auto a = pages_of(*pair.file[0]);
    const auto b = pages_of(*pair.file[1]);
    if (a.size() != b.size())
      throw bad_input(fmt::format("camera {}: '{}' has {} pages but its partner '{}' has {}", camera.id,
                                  pair.file[0]->string(), a.size(), pair.file[1]->string(), b.size()));
    for (std::size_t p = 0; p < a.size(); ++p) camera.sets.push_back({a[p], b[p]});
  }
}

void pair_by_order(ImportPlan::Camera& camera) {
  std::vector<ImageSource> frames;
  for (const fs::path& file : camera.files) {
    auto pages = pages_of(file);
    frames.insert(frames.end(), pages.begin(), pages.end());
  }
  if (frames.size() % 2 != 0)
    throw bad_input(fmt::format("camera {}: '{}' gives {} frames, an odd number, so they cannot be paired A, B, A, "
                                "B, ...; the last one is {}",
                                camera.id, camera.pattern, frames.size(), frames.back().to_string()));
  for (std::size_t i = 0; i < frames.size(); i += 2) camera.sets.push_back({frames[i], frames[i + 1]});
}

std::string describe_sets(const ImportPlan::Camera& c) {
  if (c.sets.empty()) return "0 sets";
  return fmt::format("{} set{} ({} ... {})", c.sets.size(), c.sets.size() == 1 ? "" : "s",
                     c.sets.front()[0].to_string(), c.sets.back()[1].to_string());
}

}  // namespace

std::string_view to_string(FramePairing pairing) {
  for (const auto& [p, name] : kPairingNames)
    if (p == pairing) return name;
  return "unknown";
}

std::optional<FramePairing> parse_frame_pairing(std::string_view name) {
  for (const auto& [p, n] : kPairingNames)
    if (n == name) return p;
  return std::nullopt;
}

std::string ImageSource::to_string() const {
  return pages > 1 ? fmt::format("{} (page {} of {})", file.string(), page + 1, pages) : file.string();
}

ImportPlan plan_image_import(const ImportOptions& options) {
  if (options.cameras.empty()) throw bad_input("import needs at least one camera and its file pattern");
  ImportPlan plan;
  std::unordered_set<std::string> ids;
  for (const ImportCamera& c : options.cameras) {
    if (c.id.empty()) throw bad_input(fmt::format("camera id is empty for pattern '{}'", c.pattern));
    if (!ids.insert(c.id).second) throw bad_input(fmt::format("camera id '{}' is given twice", c.id));
    plan.cameras.push_back({c.id, c.pattern, find_sequence_files(c.pattern, c.id), {}});
  }

  plan.pairing = options.pairing;
  if (plan.pairing == FramePairing::automatic) {
    const bool all_named = std::all_of(plan.cameras.begin(), plan.cameras.end(), [](const ImportPlan::Camera& c) {
      return std::all_of(c.files.begin(), c.files.end(), [](const fs::path& f) { return exposure_suffix(f).has_value(); });
    });
    plan.pairing = all_named ? FramePairing::by_name : FramePairing::by_order;
  }
  for (ImportPlan::Camera& c : plan.cameras) {
    if (plan.pairing == FramePairing::by_name) pair_by_name(c);
    else pair_by_order(c);
  }

  const ImportPlan::Camera& first = plan.cameras.front();
  for (const ImportPlan::Camera& c : plan.cameras) {
    if (c.sets.size() == first.sets.size()) continue;
    const ImportPlan::Camera& longer = c.sets.size() > first.sets.size() ? c : first;
    const auto& extra = longer.sets[std::min(c.sets.size(), first.sets.size())];
    throw bad_input(fmt::format("camera {} has {} but camera {} has {}: every camera needs the same number of sets; "
                                "the first set without a counterpart is {} + {}",
                                first.id, describe_sets(first), c.id, describe_sets(c), extra[0].to_string(),
                                extra[1].to_string()));
  }
  return plan;
}

}  // namespace tomorig::storage

#include "tomorig/pipeline/quicklook_view.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/display.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kVersion = 1;  // of the messages this view reads

double number(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : std::nan("");
}
const json& at(const json& j, const char* key) {
  static const json null;
  const auto it = j.find(key);
  return it == j.end() ? null : *it;
}
// {"value": x, "flag": f} -> x (NaN for null or missing).
double value(const json& judged) { return judged.is_object() ? number(judged, "value") : std::nan(""); }
std::string flag(const json& j) {
  const json& f = j.is_object() && j.contains("flag") ? j.at("flag") : j;
  return f.is_string() ? f.get<std::string>() : "red";
}

std::string shown(double v, const char* format) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : std::string("-");
}

struct SetView {
  std::uint64_t set = 0, trigger = 0;
  std::int64_t dt_ns = 0;
  std::string flag;
  json cameras, preview, drift, counts;
  std::map<std::string, Image> images;  // by name: "cam0/a", "cam0/histogram"
};

struct PreviewView {
  std::uint64_t set = 0;
  double latency_s = 0;
  json sheet;
  std::map<std::string, Image> images;  // "mip_z", "mip_y", "mip_x"
};

// The images a message carries, by the names its JSON gives them.
std::map<std::string, Image> decode_images(const json& j, const stream::PreviewMessage& m) {
  std::map<std::string, Image> out;
  for (const json& entry : at(j, "images")) {
    const auto part = static_cast<std::size_t>(number(entry, "part"));
    const std::string name = at(entry, "name").is_string() ? entry.at("name").get<std::string>() : "";
    if (part < 1 || part > m.images.size() || name.empty())
      throw bad_input(fmt::format("quick-look message lists image '{}' in part {}, but it has {} image parts", name,
                                  part, m.images.size()));
    out[name] = storage::decode_png(m.images[part - 1], "quick-look image '" + name + "'");
  }
  return out;
}

// ---- text --------------------------------------------------------------------------------

class Painter {
 public:
  explicit Painter(bool colour) : colour_(colour) {}
  std::string flagged(const std::string& text, const std::string& f) const {
    if (!colour_) return text;
    const char* code = f == "green" ? "\x1b[32m" : f == "amber" ? "\x1b[33m" : "\x1b[31m";
    return fmt::format("{}{}\x1b[0m", code, text);
  }
  // A judged figure: its value, coloured by its flag (or with the flag as a word).
  std::string judged(const json& j, const char* format, double scale = 1.0) const {
    const std::string text = shown(value(j) * scale, format);
    if (colour_) return flagged(text, flag(j));
    return flag(j) == "green" ? text : fmt::format("{}({})", text, flag(j));
  }

 private:
  bool colour_;
};

std::string camera_line(const json& cam, const Painter& p) {
  const json& st = at(cam, "statistics");
  const std::string id = at(cam, "id").is_string() ? cam.at("id").get<std::string>() : "?";
  if (st.is_null())
    return fmt::format("{:<8} {}  {}", id, p.flagged("not measured", "red"),
                       at(cam, "missing").is_string() ? cam.at("missing").get<std::string>() : "");
  const json& a = at(st, "a");
  const json& particles = at(a, "particles");
  const json& dt = at(cam, "dt_check");
  return fmt::format("{:<8} ppp {:<7} d_tau {:<6} Ns {:<6} sat {:<8} bg {:>7}/{:<5} B/A {:<6} dt {:<6} px valid {:<5}",
                     id, p.judged(at(particles, "ppp"), "{:.3f}"), p.judged(at(particles, "diameter_px"), "{:.2f}"),
                     p.judged(at(particles, "source_density"), "{:.2f}"),
                     p.judged(at(at(a, "saturation"), "fraction"), "{:.2f}%", 100.0),
                     shown(number(at(a, "background"), "level"), "{:.1f}"),
                     shown(number(at(a, "background"), "noise"), "{:.1f}"), p.judged(at(st, "energy_balance"), "{:.2f}"),
                     p.judged(at(dt, "displacement_px"), "{:.1f}"), p.judged(at(dt, "valid_fraction"), "{:.2f}"));
}

std::string sheet_line(const json& preview, const Painter& p) {
  if (preview.is_null()) return "sheet    no preview volume yet";
  if (!at(preview, "found").is_boolean() || !preview.at("found").get<bool>())
    return fmt::format("sheet    {} (preview of set {})", p.flagged("no sheet found", "red"),
                       number(preview, "set"));
  return fmt::format("sheet    {} at {} mm, {} mm thick; ghost {} in front, {} behind; RSNR {}  (preview of set {}, {} s "
                     "after it)",
                     p.flagged(flag(preview), flag(preview)), shown(number(preview, "position_mm"), "{:+.3f}"),
                     shown(number(preview, "thickness_mm"), "{:.3f}"), shown(number(preview, "ghost_front"), "{:.2f}"),
                     shown(number(preview, "ghost_back"), "{:.2f}"), shown(number(preview, "rsnr"), "{:.1f}"),
                     number(preview, "set"), shown(number(preview, "latency_s"), "{:.2f}"));
}

std::string drift_line(const json& drift, const json& cameras, const Painter& p) {
  if (drift.is_null()) return "drift    not measured yet";
  std::string largest;
  const json& px = at(drift, "largest_px");
  for (std::size_t c = 0; c < px.size(); ++c) {
    const std::string id = c < cameras.size() && at(cameras[c], "id").is_string() ? cameras[c].at("id").get<std::string>()
                                                                                : fmt::format("camera {}", c);
    largest += fmt::format("{}{} {}", largest.empty() ? "" : ", ", id,
                           px[c].is_number() ? fmt::format("{:.2f}", px[c].get<double>()) : std::string("-"));
  }
  std::string line = fmt::format("drift    {} over {} sets: largest px {}", p.flagged(flag(drift), flag(drift)),
                                 number(drift, "sets"), largest);
  for (const json& a : at(drift, "alarms"))
    if (a.is_string()) line += fmt::format("\n         {}", p.flagged(fmt::format("ALARM {}", a.get<std::string>()), "red"));
  return line;
}

std::string counts_line(const json& c) {
  return fmt::format("counts   {} sets analysed, {} skipped to stay current; {} preview volumes, {} sets passed over",
                     number(c, "analysed"), number(c, "skipped"), number(c, "previews"), number(c, "previews_skipped"));
}

std::string screen(const SetView& s, const std::string& source) {
  const Painter p(true);
  std::string out = "\x1b[H\x1b[2J";  // home, clear: the view is redrawn in place
  out += fmt::format("tomorig preview  {}  set {} (trigger {})  dt {:g} us  {}\n\n", source, s.set, s.trigger,
                     static_cast<double>(s.dt_ns) * 1e-3, p.flagged(s.flag, s.flag));
  for (const json& cam : s.cameras) out += camera_line(cam, p) + "\n";
  out += fmt::format("\n{}\n{}\n{}\n", sheet_line(s.preview, p), drift_line(s.drift, s.cameras, p), counts_line(s.counts));
  return out;
}

std::string plain_line(const SetView& s) {
  const Painter p(false);
  std::string line = fmt::format("set {} {}", s.set, s.flag);
  for (const json& cam : s.cameras) {
    const json& st = at(cam, "statistics");
    const std::string id = at(cam, "id").is_string() ? cam.at("id").get<std::string>() : "?";
    if (st.is_null()) {
      line += fmt::format(" | {} not measured", id);
      continue;
    }
    const json& particles = at(at(st, "a"), "particles");
    line += fmt::format(" | {} ppp {} d_tau {} Ns {} sat {} dt {}", id, p.judged(at(particles, "ppp"), "{:.3f}"),
                        p.judged(at(particles, "diameter_px"), "{:.2f}"),
                        p.judged(at(particles, "source_density"), "{:.2f}"),
                        p.judged(at(at(at(st, "a"), "saturation"), "fraction"), "{:.2f}%", 100.0),
                        p.judged(at(at(cam, "dt_check"), "displacement_px"), "{:.1f}"));
  }
  if (!s.preview.is_null())
    line += fmt::format(" | sheet {} mm {} mm RSNR {} (set {})", shown(number(s.preview, "position_mm"), "{:+.3f}"),
                        shown(number(s.preview, "thickness_mm"), "{:.3f}"), shown(number(s.preview, "rsnr"), "{:.1f}"),
                        number(s.preview, "set"));
  if (!s.drift.is_null()) {
    line += fmt::format(" | drift {}", flag(s.drift));
    for (const json& a : at(s.drift, "alarms"))
      if (a.is_string()) line += fmt::format(" ALARM {}", a.get<std::string>());
  }
  line += '\n';
  return line;
}

// ---- snapshots -------------------------------------------------------------------------------

Image stack(const std::vector<Image>& parts, bool across, int gap) {
  int w = 0, h = 0;
  for (const Image& im : parts) {
    if (across) {
      w += im.width() + (w > 0 ? gap : 0);
      h = std::max(h, im.height());
    } else {
      h += im.height() + (h > 0 ? gap : 0);
      w = std::max(w, im.width());
    }
  }
  Image out = Image::allocate(std::max(w, 1), std::max(h, 1), SampleType::u8);
  int at_x = 0, at_y = 0;
  for (const Image& im : parts) {
    for (int y = 0; y < im.height(); ++y)
      std::memcpy(out.row<std::uint8_t>(at_y + y) + at_x, im.row<std::uint8_t>(y), static_cast<std::size_t>(im.width()));
    (across ? at_x : at_y) += (across ? im.width() : im.height()) + gap;
  }
  return out;
}

// The depth profile as a picture: one column per slice (doubled), relative intensity upwards,
// the sheet's edges as dotted columns.
Image profile_picture(const json& sheet) {
  const json& profile = at(sheet, "profile");
  const int n = static_cast<int>(profile.size());
  constexpr int kHeight = 100;
  Image out = Image::allocate(std::max(2 * n, 2), kHeight, SampleType::u8);
  const double z0 = number(sheet, "z0_mm"), dz = number(sheet, "dz_mm");
  for (const char* edge : {"low_edge_mm", "high_edge_mm"}) {
    const double z = number(sheet, edge);
    if (!std::isfinite(z) || !std::isfinite(z0) || !(dz != 0)) continue;
    const int x = static_cast<int>(std::lround((z - z0) / dz * 2));
    if (x >= 0 && x < out.width())
      for (int y = 0; y < kHeight; y += 3) out.at<std::uint8_t>(x, y) = 128;
  }
  for (int k = 0; k < n; ++k) {
    if (!profile[static_cast<std::size_t>(k)].is_number()) continue;
    const double v = std::clamp(profile[static_cast<std::size_t>(k)].get<double>(), 0.0, 1.0);
    const int top = kHeight - 1 - static_cast<int>(std::lround(v * (kHeight - 1)));
    for (int y = top; y < kHeight; ++y) out.at<std::uint8_t>(2 * k, y) = out.at<std::uint8_t>(2 * k + 1, y) = 200;
  }
  return out;
}

Image snapshot(const SetView& s, const PreviewView* preview) {
  const Painter p(false);
  std::vector<Image> cameras;
  for (const json& cam : s.cameras) {
    const std::string id = at(cam, "id").is_string() ? cam.at("id").get<std::string>() : "?";
    std::vector<Image> column;
    if (const auto it = s.images.find(id + "/a"); it != s.images.end()) column.push_back(it->second);
    if (const auto it = s.images.find(id + "/histogram"); it != s.images.end()) column.push_back(it->second);
    const json& st = at(cam, "statistics");
    std::vector<std::string> lines = {fmt::format("{}  {}", id, flag(cam))};
    if (!st.is_null()) {
      const json& particles = at(at(st, "a"), "particles");
      lines.push_back(fmt::format("ppp {}  d_tau {}", p.judged(at(particles, "ppp"), "{:.3f}"),
                                  p.judged(at(particles, "diameter_px"), "{:.2f}")));
      lines.push_back(fmt::format("Ns {}  sat {}", p.judged(at(particles, "source_density"), "{:.2f}"),
                                  p.judged(at(at(at(st, "a"), "saturation"), "fraction"), "{:.2f}%", 100.0)));
      lines.push_back(fmt::format("B/A {}  dt {} px", p.judged(at(st, "energy_balance"), "{:.2f}"),
                                  p.judged(at(at(cam, "dt_check"), "displacement_px"), "{:.1f}")));
    }
    Image picture = column.empty() ? Image::allocate(160, 1, SampleType::u8) : stack(column, false, 2);
    cameras.push_back(quicklook::with_caption(picture, lines));
  }
  std::vector<Image> rows;
  const std::string title = fmt::format("set {} (trigger {})  {}", s.set, s.trigger, s.flag);
  rows.push_back(quicklook::with_caption(Image::allocate(1, 1, SampleType::u8), std::vector<std::string>{title}));
  if (!cameras.empty()) rows.push_back(stack(cameras, true, 8));
  if (preview != nullptr) {
    std::vector<Image> volume;
    for (const char* name : {"mip_z", "mip_y", "mip_x"})
      if (const auto it = preview->images.find(name); it != preview->images.end()) volume.push_back(it->second);
    volume.push_back(profile_picture(preview->sheet));
    const json& sh = preview->sheet;
    std::vector<std::string> lines = {
        fmt::format("preview of set {} ({:.2f} s after it): maximum projections along z, y, x; depth profile",
                    preview->set, preview->latency_s),
        std::isfinite(number(sh, "position_mm"))
            ? fmt::format("sheet at {} mm, {} mm thick, ghost {} front / {} back, RSNR {}  {}",
                          shown(number(sh, "position_mm"), "{:+.3f}"), shown(number(sh, "thickness_mm"), "{:.3f}"),
                          shown(number(sh, "ghost_front"), "{:.2f}"), shown(number(sh, "ghost_back"), "{:.2f}"),
                          shown(number(sh, "rsnr"), "{:.1f}"), flag(sh))
            : std::string("no sheet found")};
    rows.push_back(quicklook::with_caption(stack(volume, true, 8), lines));
  }
  return stack(rows, false, 6);
}

bool holds_snapshots(const fs::path& folder) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("set_") && name.ends_with(".png")) return true;
  }
  return false;
}

}  // namespace

struct QuickLookView::State {
  std::uint64_t sets = 0;
  std::optional<PreviewView> preview;
  std::vector<fs::path> snapshots;
  std::optional<Clock::time_point> last_snapshot;
};

QuickLookView::QuickLookView(QuickLookViewOptions options)
    : options_(std::move(options)), state_(std::make_unique<State>()) {
  if (options_.png_folder.empty()) return;
  std::error_code ec;
  fs::create_directories(options_.png_folder, ec);
  if (ec || !fs::is_directory(options_.png_folder))
    throw bad_input(fmt::format("cannot create the snapshot folder '{}': {}; choose another --png",
                                options_.png_folder.string(), ec ? ec.message() : "it is not a folder"));
  if (!options_.overwrite && holds_snapshots(options_.png_folder))
    throw bad_input(fmt::format("'{}' already holds snapshots (set_*.png); choose another --png or pass --overwrite",
                                options_.png_folder.string()));
}

QuickLookView::~QuickLookView() = default;
QuickLookView::QuickLookView(QuickLookView&&) noexcept = default;
QuickLookView& QuickLookView::operator=(QuickLookView&&) noexcept = default;

std::uint64_t QuickLookView::sets() const { return state_->sets; }
const std::vector<fs::path>& QuickLookView::snapshots() const { return state_->snapshots; }

std::string QuickLookView::take(const stream::PreviewMessage& message) {
  json j = json::parse(message.json, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) throw bad_input("a preview message's JSON is not an object: not a tomorig quick-look message");
  const std::string type = at(j, "type").is_string() ? j.at("type").get<std::string>() : "";
  if (type != "tomorig.quicklook" && type != "tomorig.preview")
    throw bad_input(fmt::format("a preview message of type '{}' is not a tomorig quick-look message", type));
  if (number(j, "version") != kVersion)
    throw bad_input(fmt::format("the quick-look message is version {} but this tomorig reads version {}; run the same "
                                "tomorig release on both ends",
                                at(j, "version").dump(), kVersion));

  if (type == "tomorig.preview") {
    PreviewView p;
    p.set = static_cast<std::uint64_t>(number(j, "set"));
    p.latency_s = number(j, "latency_s");
    p.sheet = at(at(j, "preview"), "sheet");
    p.images = decode_images(j, message);
    state_->preview = std::move(p);
    return {};
  }

  SetView s;
  s.set = static_cast<std::uint64_t>(number(j, "set"));
  s.trigger = static_cast<std::uint64_t>(number(j, "trigger_index"));
  s.dt_ns = static_cast<std::int64_t>(number(j, "dt_ns"));
  s.flag = flag(j);
  s.cameras = at(j, "cameras");
  s.preview = at(j, "preview");
  s.drift = at(j, "drift");
  s.counts = at(j, "counts");
  ++state_->sets;
  if (!options_.png_folder.empty()) {
    const auto now = Clock::now();
    if (!state_->last_snapshot ||
        std::chrono::duration<double>(now - *state_->last_snapshot).count() >= options_.png_interval_s) {
      s.images = decode_images(j, message);
      const fs::path file = options_.png_folder / fmt::format("set_{:06}.png", s.set);
      storage::write_png(file, snapshot(s, state_->preview ? &*state_->preview : nullptr));
      state_->snapshots.push_back(file);
      state_->last_snapshot = now;
    }
  }
  if (options_.json) {
    j.erase("images");  // part numbers mean nothing in a line of text
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";  // ids from the wire
  }
  return options_.tty ? screen(s, options_.source) : plain_line(s);
}

}  // namespace tomorig::pipeline

#include "tomorig/rig/recorder.h"

#include <utility>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/rig/record_layout.h"
#include "tomorig/storage/session_cameras.h"

namespace tomorig::rig {
namespace {

bool sizes_known(const std::vector<storage::SessionCamera>& cameras) {
  if (cameras.empty()) return false;
  for (const auto& cam : cameras)
    if (cam.width <= 0 || cam.height <= 0) return false;
  return true;
}

}  // namespace

void RecorderOptions::validate() const {
  if (out.empty()) throw bad_input("the recorder has no output file: give one with -o/--out");
  if (!(disk_reserve_mb >= 0.0))
    throw bad_input(fmt::format("--disk-reserve-mb {:g} is invalid: it must be >= 0", disk_reserve_mb));
  if (!(max_set_mb > 0.0))
    throw bad_input(fmt::format("--max-set-mb {:g} is invalid: it must be > 0", max_set_mb));
}

std::string why_not_recordable(const std::vector<storage::SessionCamera>& cameras, const RecorderOptions& options) {
  try {
    storage::check_session_cameras(cameras, options.out);
  } catch (const Error& e) {
    return e.what();
  }
  double set_bytes = 0.0;  // the sizes are bounded now, so this cannot overflow
  for (const auto& cam : cameras)
    set_bytes += 2.0 * static_cast<double>(cam.width) * static_cast<double>(cam.height) *
                 static_cast<double>(bytes_per_sample(sample_type_of(cam.pixel_format)));
  if (set_bytes > options.max_set_mb * 1e6)
    return fmt::format("a set of its {} cameras takes {:.1f} MB, more than the recorder takes (--max-set-mb {:g})",
                       cameras.size(), set_bytes / 1e6, options.max_set_mb);
  return {};
}

std::string RecorderReport::brief() const {
  return fmt::format("recorded {} set{} ({:.1f} MB of pixels) to {}", written, written == 1 ? "" : "s",
                     static_cast<double>(bytes) / 1e6, out.string());
}

storage::Compression parse_compression_option(const std::string& text) {
  const auto compression = storage::parse_compression(text);
  if (!compression) throw bad_input(fmt::format("--compression {} is not supported (none, bitshuffle-lz4)", text));
  return *compression;
}

void prepare_output(const RecorderOptions& options) {
  options.validate();
  const std::filesystem::path& out = options.out;
  if (std::filesystem::exists(out) && !options.overwrite)
    throw bad_input(fmt::format("{} exists; choose another -o/--out or pass --overwrite", out.string()));
  if (out.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(out.parent_path(), ec);
    if (ec)
      throw bad_input(fmt::format("cannot create the output folder {}: {}; choose another -o/--out",
                                  out.parent_path().string(), ec.message()));
  }
}

Recorder::Recorder(RecorderOptions options) : options_(std::move(options)) {
  prepare_output(options_);
  report_.out = options_.out;
  info_.cameras = options_.cameras;
  info_.rig_config_toml = options_.rig_config_toml;
  info_.software_version = options_.software_version.empty() ? std::string(software_version()) : options_.software_version;
  info_.created_utc = options_.created_utc;
  if (sizes_known(info_.cameras)) open();  // otherwise the first set tells the image sizes
}

Recorder::~Recorder() = default;

void Recorder::open() {
  storage::SessionWriterOptions writer_options;
  writer_options.live = true;
  writer_options.compression = options_.compression;
  writer_options.overwrite = options_.overwrite;
  writer_options.disk_reserve_bytes = static_cast<std::uint64_t>(options_.disk_reserve_mb * 1e6);
  writer_ = std::make_unique<storage::SessionWriter>(options_.out, info_, writer_options);
  if (options_.truth) writer_->write_truth(*options_.truth);
}

Recorder::Outcome Recorder::add(const FrameSet& set, const storage::TruthSet* truth, std::string* why) {
  std::string reason;
  if (!report_.disk_full.empty()) {
    reason = "the disk is full";
    if (why != nullptr) *why = reason;
    return Outcome::stopped;
  }
  if (!writer_) {
    auto cameras = options_.cameras.empty() ? cameras_from_set(set, reason)
                                            : complete_announced_cameras(options_.cameras, set, reason);
    if (cameras) reason = why_not_recordable(*cameras, options_);
    if (!cameras || !reason.empty()) {
      ++report_.refused;
      if (why != nullptr) *why = "it cannot start the session: " + reason;
      return Outcome::refused;
    }
    info_.cameras = std::move(*cameras);
    open();
  } else if (!set_matches_cameras(set, info_.cameras, reason)) {
    ++report_.refused;
    if (why != nullptr) *why = reason;
    return Outcome::refused;
  }
  try {
    writer_->append(set);
  } catch (const storage::DiskFullError& e) {
    // Nothing of this set was written: the session can still be finished with every set before it.
    report_.disk_full = e.what();
    if (why != nullptr) *why = report_.disk_full;
    return Outcome::stopped;
  } catch (const Error& e) {
    // The live writer keeps "<name>.partial" with every set written so far.
    throw runtime_error(fmt::format("recording stopped after {} sets: {}; the sets written so far are in {}",
                                    report_.written, e.what(), writer_->partial_path().string()));
  }
  if (truth != nullptr) writer_->write_truth_set(report_.written, *truth);
  ++report_.written;
  report_.bytes += pixel_bytes(set);
  return Outcome::written;
}

void Recorder::add_quicklook(const storage::QuickLookRecord& record) {
  const std::lock_guard lock(quicklook_mutex_);
  if (!writer_ || report_.finished) return;
  try {
    writer_->append_quicklook(record);
    ++report_.quicklook_rows;
  } catch (const Error&) {
    ++report_.quicklook_failures;
  }
}

const RecorderReport& Recorder::finish() {
  if (!writer_) throw runtime_error("no set could start the session, so nothing was recorded");
  const std::lock_guard lock(quicklook_mutex_);
  if (!report_.finished) {
    writer_->finish();
    report_.finished = true;
  }
  return report_;
}

}  // namespace tomorig::rig

// import_images: reads the planned frames set by set and appends them to a new session, so
// memory holds one set at a time however long the sequence is.
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/image_import.h"

namespace tomorig::storage {
namespace {

void check_options(const ImportOptions& o) {
  if (!std::isfinite(o.dt_us) || o.dt_us < 0)
    throw bad_input(fmt::format("dt = {} us is invalid: it must be >= 0 (0 = unknown)", o.dt_us));
  if (!std::isfinite(o.rate_hz) || o.rate_hz < 0)
    throw bad_input(fmt::format("rate = {} Hz is invalid: it must be >= 0 (0 = unknown)", o.rate_hz));
  for (const ImportCamera& c : o.cameras)
    if (!std::isfinite(c.pixel_pitch_um) || c.pixel_pitch_um < 0)
      throw bad_input(fmt::format("camera {}: pixel pitch {} um is invalid: it must be >= 0 (0 = unknown)", c.id,
                                  c.pixel_pitch_um));
}

// The first frame read: every other frame must match it.
struct Reference {
  Image image;
  std::string source;
};

std::string describe(const Image& image) {
  return fmt::format("{} x {} {}", image.width(), image.height(), to_string(image.type()));
}

class SetReader {
 public:
  SetReader(const ImportOptions& options, const ImportPlan& plan) : options_(options), plan_(plan) {
    per_camera_.resize(plan.cameras.size());
  }

  FrameSet read(std::uint64_t s) {
    FrameSet set;
    set.set_index = s;
    set.trigger_index = s;
    set.dt_ns = std::llround(options_.dt_us * 1e3);
    set.trigger_timestamp_ns = options_.rate_hz > 0 ? std::llround(static_cast<double>(s) * 1e9 / options_.rate_hz) : 0;
    for (std::size_t c = 0; c < plan_.cameras.size(); ++c) {
      const ImportPlan::Camera& camera = plan_.cameras[c];
      CameraFrames frames;
      frames.camera_id = camera.id;
      for (int e = 0; e < 2; ++e) {
        const ImageSource& source = camera.sets[s][static_cast<std::size_t>(e)];
        Frame& frame = frames[e == 0 ? Exposure::A : Exposure::B];
        frame.image = read_image(source.file, source.page);
        check(c, frame.image, source);
        frame.timestamp_ns = set.trigger_timestamp_ns + (e == 0 ? 0 : set.dt_ns);
      }
      set.cameras.push_back(std::move(frames));
    }
    return set;
  }

 private:
  void check(std::size_t camera, const Image& image, const ImageSource& source) {
    const std::string here = source.to_string();
    if (!global_) global_ = Reference{image, here};
    if (image.width() != global_->image.width() || image.height() != global_->image.height())
      throw bad_input(fmt::format("'{}' is {} x {} but '{}' is {} x {}: every frame of every camera must have the "
                                  "same size",
                                  here, image.width(), image.height(), global_->source, global_->image.width(),
                                  global_->image.height()));
    auto& ref = per_camera_[camera];
    if (!ref) ref = Reference{image, here};
    if (image.type() != ref->image.type())
      throw bad_input(fmt::format("camera {}: '{}' is {} but '{}' is {}: a camera's frames must share one sample type",
                                  plan_.cameras[camera].id, here, describe(image), ref->source,
                                  describe(ref->image)));
  }

  const ImportOptions& options_;
  const ImportPlan& plan_;
  std::optional<Reference> global_;
  std::vector<std::optional<Reference>> per_camera_;
};

PixelFormat choose_format(const ImportCamera& camera, const Image& image, const std::string& source) {
  const PixelFormat natural = image.type() == SampleType::u8 ? PixelFormat::Mono8 : PixelFormat::Mono16;
  if (!camera.pixel_format) return natural;
  if (sample_type_of(*camera.pixel_format) != image.type())
    throw bad_input(fmt::format("camera {}: pixel format {} needs {} samples but '{}' holds {}", camera.id,
                                to_string(*camera.pixel_format), to_string(sample_type_of(*camera.pixel_format)),
                                source, to_string(image.type())));
  return *camera.pixel_format;
}

}  // namespace

ImportResult import_images(const ImportOptions& options, const std::filesystem::path& output) {
  check_options(options);
  ImportResult result;
  result.plan = plan_image_import(options);
  result.output = output;
  const ImportPlan& plan = result.plan;
  const std::uint64_t n = plan.set_count();
  if (n == 0) throw bad_input("no sets to import");

  // The first set fixes the camera sizes and formats the session is created with.
  SetReader reader(options, plan);
  FrameSet first = reader.read(0);
  SessionInfo info;
  info.rig_config_toml = options.rig_config_toml;
  for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
    const Image& image = first.cameras[c].a.image;
    SessionCamera camera;
    camera.id = plan.cameras[c].id;
    camera.width = image.width();
    camera.height = image.height();
    camera.pixel_format = choose_format(options.cameras[c], image, plan.cameras[c].sets[0][0].to_string());
    camera.pixel_pitch_um = options.cameras[c].pixel_pitch_um;
    info.cameras.push_back(camera);
  }

  SessionWriter writer(output, info, options.writer);
  writer.append(first);
  first = {};  // release the first set's pixels before reading on
  for (std::uint64_t s = 1; s < n; ++s) writer.append(reader.read(s));
  writer.finish();

  result.cameras = info.cameras;
  result.sets = writer.sets_written();
  return result;
}

}  // namespace tomorig::storage

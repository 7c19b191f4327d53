#pragma once
// A camera model seen through b x b pixel binning: binned pixel (u', v') covers the full
// pixels b u' ... b u' + b - 1, so its centre is at full pixel b u' + (b - 1) / 2 (pixel
// centres at integer coordinates, camera_model.h). Wraps any model; the reconstruction then
// runs on binned images as it does on full ones.
#include <memory>
#include <string>

#include "tomorig/processing/calibration/camera_model.h"

namespace tomorig::quicklook::detail {

class BinnedCamera final : public calibration::CameraModel {
 public:
  BinnedCamera(std::shared_ptr<const calibration::CameraModel> full, int binning)
      : full_(std::move(full)), b_(binning), offset_((binning - 1) * 0.5) {}

  std::string model_name() const override { return full_->model_name() + "-binned"; }
  Vec2d project(const Vec3d& world) const override {
    const Vec2d p = full_->project(world);
    return {(p.x - offset_) / b_, (p.y - offset_) / b_};
  }
  Vec3d back_project(const Vec2d& pixel, double world_z) const override {
    return full_->back_project(to_full(pixel), world_z);
  }
  Ray line_of_sight(const Vec2d& pixel) const override { return full_->line_of_sight(to_full(pixel)); }
  std::unique_ptr<calibration::CameraModel> clone() const override {
    return std::make_unique<BinnedCamera>(full_, b_);
  }

 private:
  Vec2d to_full(const Vec2d& binned) const { return {binned.x * b_ + offset_, binned.y * b_ + offset_}; }

  std::shared_ptr<const calibration::CameraModel> full_;
  double b_;
  double offset_;
};

}  // namespace tomorig::quicklook::detail

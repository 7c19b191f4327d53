#include "genicam_features.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "glib_handles.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition::detail {
namespace {

ArvGcFeatureNode* find_feature(ArvDevice* device, const std::string& feature) {
  ArvGcNode* node = arv_device_get_feature(device, feature.c_str());
  if (node == nullptr || !ARV_IS_GC_FEATURE_NODE(node)) return nullptr;
  auto* feature_node = ARV_GC_FEATURE_NODE(node);
  GErrorSlot error;
  if (!arv_gc_feature_node_is_implemented(feature_node, error.out()) || error) return nullptr;
  return feature_node;
}

}  // namespace

bool has_feature(ArvDevice* device, const std::string& feature) { return find_feature(device, feature) != nullptr; }

bool feature_available(ArvDevice* device, const std::string& feature) {
  ArvGcFeatureNode* node = find_feature(device, feature);
  if (node == nullptr) return false;
  GErrorSlot error;
  return arv_gc_feature_node_is_available(node, error.out()) && !error;
}

std::vector<std::string> enumeration_entries(ArvDevice* device, const std::string& feature) {
  std::vector<std::string> entries;
  ArvGcFeatureNode* node = find_feature(device, feature);
  if (node == nullptr || !ARV_IS_GC_ENUMERATION(node)) return entries;
  guint count = 0;
  GErrorSlot error;
  const char** values = arv_gc_enumeration_dup_available_string_values(ARV_GC_ENUMERATION(node), &count, error.out());
  if (values != nullptr) {
    for (guint i = 0; i < count; ++i) entries.emplace_back(values[i]);
    g_free(values);
  }
  return entries;
}

void set_feature(ArvDevice* device, const std::string& camera_id, const std::string& feature,
                 const std::string& value) {
  ArvGcFeatureNode* node = find_feature(device, feature);
  if (node == nullptr)
    throw bad_input(fmt::format("camera {}: the camera has no GenICam feature '{}' (remove it from [cameras.features] "
                                "or check its spelling with arv-tool-0.8 features)",
                                camera_id, feature));
  GErrorSlot error;
  if (!arv_gc_feature_node_is_available(node, error.out()))
    throw bad_input(fmt::format("camera {}: GenICam feature '{}' is not available in the camera's current state{}",
                                camera_id, feature, error ? ": " + error.message() : std::string()));

  if (ARV_IS_GC_ENUMERATION(node)) {
    const auto offered = enumeration_entries(device, feature);
    if (std::find(offered.begin(), offered.end(), value) == offered.end())
      throw bad_input(fmt::format("camera {}: GenICam feature {} does not accept '{}'; the camera offers: {}", camera_id,
                                  feature, value, offered.empty() ? std::string("nothing") : fmt::format("{}", fmt::join(offered, ", "))));
  }
  // An integer outside the camera's range is refused here: some cameras (and Aravis's
  // fakes) would store it and deliver a different image size than configured.
  std::int64_t wanted = 0;
  const auto parsed = std::from_chars(value.data(), value.data() + value.size(), wanted);
  const bool integer_value = parsed.ec == std::errc() && parsed.ptr == value.data() + value.size();
  if (ARV_IS_GC_INTEGER(node) && integer_value) {
    GErrorSlot range_error;
    const std::int64_t lo = arv_gc_integer_get_min(ARV_GC_INTEGER(node), range_error.out());
    const std::int64_t hi = range_error ? wanted : arv_gc_integer_get_max(ARV_GC_INTEGER(node), range_error.out());
    if (!range_error && (wanted < lo || wanted > hi))
      throw bad_input(fmt::format("camera {}: GenICam feature {} = {} is out of range: the camera allows {} to {}",
                                  camera_id, feature, wanted, lo, hi));
  }
  // A float outside the camera's range is refused here too, naming the range.
  double wanted_float = 0.0;
  const auto parsed_float = std::from_chars(value.data(), value.data() + value.size(), wanted_float);
  const bool float_value = parsed_float.ec == std::errc() && parsed_float.ptr == value.data() + value.size();
  if (ARV_IS_GC_FLOAT(node) && float_value) {
    GErrorSlot range_error;
    const double lo = arv_gc_float_get_min(ARV_GC_FLOAT(node), range_error.out());
    const double hi = range_error ? wanted_float : arv_gc_float_get_max(ARV_GC_FLOAT(node), range_error.out());
    if (!range_error && (wanted_float < lo || wanted_float > hi))
      throw bad_input(fmt::format("camera {}: GenICam feature {} = {} is out of range: the camera allows {} to {}",
                                  camera_id, feature, value, lo, hi));
  }
  arv_gc_feature_node_set_value_from_string(node, value.c_str(), error.out());
  if (error)
    throw bad_input(fmt::format("camera {}: setting GenICam feature {} = '{}' failed: {}", camera_id, feature, value,
                                error.message()));

  // Read back: an entry or a number the camera silently replaced would leave it running on
  // something other than the plan.
  if (ARV_IS_GC_ENUMERATION(node)) {
    const char* got = arv_gc_enumeration_get_string_value(ARV_GC_ENUMERATION(node), error.out());
    if (!error && (got == nullptr || value != got))
      throw bad_input(fmt::format("camera {}: GenICam feature {} = '{}' was not accepted (the camera reads back '{}')",
                                  camera_id, feature, value, got != nullptr ? got : ""));
  }
  if (ARV_IS_GC_FLOAT(node) && float_value) {
    const double got = arv_gc_float_get_value(ARV_GC_FLOAT(node), error.out());
    // Cameras keep floats in their own units and steps; a thousandth is rounding, more is not.
    if (!error && std::abs(got - wanted_float) > 1e-3 * std::max(1.0, std::abs(wanted_float)))
      throw bad_input(fmt::format("camera {}: GenICam feature {} = {} was not accepted (the camera reads back {})",
                                  camera_id, feature, value, got));
  }
  // An integer the camera silently rounds or clamps (Width = 5000 on a 2048-pixel sensor)
  // would change the image size behind the configuration's back: refuse it.
  if (ARV_IS_GC_INTEGER(node)) {
    if (integer_value) {
      const std::int64_t got = arv_gc_integer_get_value(ARV_GC_INTEGER(node), error.out());
      if (!error && got != wanted) {
        const std::int64_t lo = arv_gc_integer_get_min(ARV_GC_INTEGER(node), nullptr);
        const std::int64_t hi = arv_gc_integer_get_max(ARV_GC_INTEGER(node), nullptr);
        const std::int64_t inc = arv_gc_integer_get_inc(ARV_GC_INTEGER(node), nullptr);
        throw bad_input(fmt::format("camera {}: GenICam feature {} = {} was not accepted (the camera set {}); "
                                    "allowed: {} to {} in steps of {}",
                                    camera_id, feature, wanted, got, lo, hi, inc));
      }
    }
  }
}

}  // namespace tomorig::acquisition::detail

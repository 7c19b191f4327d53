#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/stream/status.h"

namespace tomorig::stream {
namespace {

using nlohmann::json;

constexpr const char* kStatusType = "tomorig.status";

template <typename T>
T field(const json& object, const char* key, const char* where = "status") {
  const auto it = object.find(key);
  if (it == object.end()) throw bad_input(std::string(where) + " message lacks key '" + key + "'");
  try {
    return it->get<T>();
  } catch (const json::exception&) {
    throw bad_input(std::string(where) + " key '" + key + "' has the wrong type: " + it->dump());
  }
}

// Keys added within version 1: a message from an older sender lacks them, and keeps the default.
template <typename T>
void optional_field(const json& object, const char* key, T& out, const char* where = "status") {
  if (object.contains(key)) out = field<T>(object, key, where);
}

}  // namespace

std::string to_json(const Status& s) {
  json cameras = json::array();
  for (const auto& c : s.cameras)
    cameras.push_back({{"id", c.camera_id},
                       {"frames_lost", c.frames_lost},
                       {"incomplete_sets", c.incomplete_sets},
                       {"connected", c.connected},
                       {"problem", c.problem},
                       {"free_running", c.free_running},
                       {"frames", c.frames},
                       {"underruns", c.underruns},
                       {"failed", c.failed},
                       {"missing_packets", c.missing_packets},
                       {"resends", c.resends},
                       {"mismatched", c.mismatched}});
  const json j = {{"type", kStatusType},
                  {"version", kStatusVersion},
                  {"time_ns", s.time_ns},
                  {"state", s.state},
                  {"sets_total", s.sets_total},
                  {"sets_per_second", s.sets_per_second},
                  {"stream_mb_per_second", s.stream_mb_per_second},
                  {"frames_lost", s.frames_lost},
                  {"incomplete_sets", s.incomplete_sets},
                  {"preview_drops", s.preview_drops},
                  {"queue_depth", s.queue_depth},
                  {"disk_mb_per_second", s.disk_mb_per_second},
                  {"dropped_trigger_events", s.dropped_trigger_events},
                  {"trigger_lag_events", s.trigger_lag_events},
                  {"trigger_lag_ms", s.trigger_lag_ms},
                  {"trigger_queue_capacity", s.trigger_queue_capacity},
                  {"disk_free_bytes", s.disk_free_bytes},
                  {"disk_minutes_until_full", s.disk_minutes_until_full},
                  {"warnings", s.warnings},
                  {"cameras", cameras}};
  return j.dump();
}

Status parse_status(std::string_view text) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw bad_input(std::string("status message is not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw bad_input("status message is not a JSON object");
  const auto type = field<std::string>(j, "type");
  if (type != kStatusType) throw bad_input("status message has type '" + type + "', expected '" + kStatusType + "'");
  const auto version = field<int>(j, "version");
  if (version != kStatusVersion)
    throw bad_input("the peer sends status version " + std::to_string(version) + " but this program reads version " +
                    std::to_string(kStatusVersion) + "; run the same tomorig release on both ends");
  Status s;
  s.time_ns = field<std::int64_t>(j, "time_ns");
  s.state = field<std::string>(j, "state");
  s.sets_total = field<std::uint64_t>(j, "sets_total");
  s.sets_per_second = field<double>(j, "sets_per_second");
  s.stream_mb_per_second = field<double>(j, "stream_mb_per_second");
  s.frames_lost = field<std::uint64_t>(j, "frames_lost");
  s.incomplete_sets = field<std::uint64_t>(j, "incomplete_sets");
  s.preview_drops = field<std::uint64_t>(j, "preview_drops");
  s.queue_depth = field<std::uint64_t>(j, "queue_depth");
  s.disk_mb_per_second = field<double>(j, "disk_mb_per_second");
  optional_field(j, "dropped_trigger_events", s.dropped_trigger_events);
  optional_field(j, "trigger_lag_events", s.trigger_lag_events);
  optional_field(j, "trigger_lag_ms", s.trigger_lag_ms);
  optional_field(j, "trigger_queue_capacity", s.trigger_queue_capacity);
  optional_field(j, "disk_free_bytes", s.disk_free_bytes);
  optional_field(j, "disk_minutes_until_full", s.disk_minutes_until_full);
  optional_field(j, "warnings", s.warnings);
  const auto cameras = field<json>(j, "cameras");
  if (!cameras.is_array()) throw bad_input("status key 'cameras' must be an array");
  for (const auto& c : cameras) {
    if (!c.is_object()) throw bad_input("status 'cameras' entries must be objects");
    CameraStatus cam;
    cam.camera_id = field<std::string>(c, "id", "status camera");
    cam.frames_lost = field<std::uint64_t>(c, "frames_lost", "status camera");
    cam.incomplete_sets = field<std::uint64_t>(c, "incomplete_sets", "status camera");
    optional_field(c, "connected", cam.connected, "status camera");
    optional_field(c, "problem", cam.problem, "status camera");
    optional_field(c, "free_running", cam.free_running, "status camera");
    optional_field(c, "frames", cam.frames, "status camera");
    optional_field(c, "underruns", cam.underruns, "status camera");
    optional_field(c, "failed", cam.failed, "status camera");
    optional_field(c, "missing_packets", cam.missing_packets, "status camera");
    optional_field(c, "resends", cam.resends, "status camera");
    optional_field(c, "mismatched", cam.mismatched, "status camera");
    s.cameras.push_back(std::move(cam));
  }
  return s;
}

}  // namespace tomorig::stream

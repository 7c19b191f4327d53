#pragma once
// A GenTL producer (`.cti`) loaded with dlopen: its function table, its opened system
// (TLOpen) and interfaces, and device lookup. One Producer per library file per process,
// shared by every camera it serves (GCInitLib runs once), closed when the last user goes.
//
//   auto producer = Producer::load("/opt/euresys/coaxlink.cti");   // bad_input naming file + symbol
//   auto device = producer->open_device("cam0", "CXP-1234");         // runtime_error listing devices
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "gentl_api.h"

namespace tomorig::acquisition::gentl_detail {

struct Functions {
#define TOMORIG_GENTL_FUNCTION(name, since) gentl::name##_t name = nullptr;
#include "gentl_functions.inc"
#undef TOMORIG_GENTL_FUNCTION
};

class Device;

class Producer : public std::enable_shared_from_this<Producer> {
 public:
  // Loads (or returns the already loaded) producer at `path` and initialises it.
  // Throws bad_input naming the file when it does not exist, is not a shared library, is not
  // a GenTL producer (no GCInitLib) or lacks a mandatory function (naming it); runtime_error
  // when GCInitLib or TLOpen fails.
  static std::shared_ptr<Producer> load(const std::filesystem::path& path);
  // The producers named by GENICAM_GENTL64_PATH (directories of .cti files, or .cti files,
  // separated by ':'). Throws bad_input when the variable is unset or names no producer.
  static std::vector<std::filesystem::path> from_environment();

  ~Producer();
  Producer(const Producer&) = delete;
  Producer& operator=(const Producer&) = delete;

  const Functions& fn() const { return fn_; }
  const std::filesystem::path& path() const { return path_; }
  // "DSQueueBuffer failed: -1011 (timeout): <the producer's GCGetLastError text>".
  std::string describe(const char* function, gentl::Status status) const;

  // Every device of every interface, as "interface/device-id (model, serial)", for messages.
  std::vector<std::string> list_devices();
  // Opens the device whose GenTL id, serial number, user-defined name or display name is
  // `wanted`, with control access. nullptr when no device matches.
  std::unique_ptr<Device> open_device(const std::string& wanted);

 private:
  Producer() = default;
  struct Found {
    gentl::Handle interface = nullptr;
    std::string device_id;
  };
  std::vector<Found> enumerate();
  std::string device_text(gentl::Handle interface, const std::string& device_id, std::int32_t cmd);

  std::filesystem::path path_;
  void* library_ = nullptr;
  Functions fn_;
  bool initialised_ = false;
  gentl::Handle system_ = nullptr;
  std::vector<gentl::Handle> interfaces_;
};

// An opened device: its handle, its remote (camera) port and the producer it came from.
class Device {
 public:
  Device(std::shared_ptr<Producer> producer, gentl::Handle handle, std::string id);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  Producer& producer() const { return *producer_; }
  std::shared_ptr<Producer> producer_ref() const { return producer_; }
  gentl::Handle handle() const { return handle_; }
  gentl::Handle remote_port() const { return port_; }
  const std::string& id() const { return id_; }

 private:
  std::shared_ptr<Producer> producer_;
  gentl::Handle handle_ = nullptr;
  gentl::Handle port_ = nullptr;
  std::string id_;
};

// Reads a string info value through a GenTL "GetInfo"-style call (size query, then value).
template <typename Call>
std::string info_string(Call&& call) {
  gentl::InfoType type = gentl::kTypeUnknown;
  std::size_t size = 0;
  if (call(&type, nullptr, &size) != gentl::kSuccess || size == 0) return {};
  std::string text(size, '\0');
  if (call(&type, text.data(), &size) != gentl::kSuccess) return {};
  text.resize(std::min(size, text.size()));
  while (!text.empty() && text.back() == '\0') text.pop_back();
  return text;
}

}  // namespace tomorig::acquisition::gentl_detail

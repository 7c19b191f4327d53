#include "gentl_producer.h"

#include <dlfcn.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <system_error>

#include "tomorig/core/error.h"

namespace tomorig::acquisition::gentl_detail {
namespace {

using gentl::Status;

// How long an interface or device list update may take (ms); real grabbers answer at once.
constexpr std::uint64_t kUpdateTimeoutMs = 1000;

const char* status_name(Status status) {
  switch (status) {
    case gentl::kErrError: return "error";
    case gentl::kErrNotInitialized: return "not initialised";
    case gentl::kErrNotImplemented: return "not implemented";
    case gentl::kErrResourceInUse: return "resource in use";
    case gentl::kErrAccessDenied: return "access denied";
    case gentl::kErrInvalidHandle: return "invalid handle";
    case gentl::kErrInvalidId: return "invalid id";
    case gentl::kErrNoData: return "no data";
    case gentl::kErrInvalidParameter: return "invalid parameter";
    case gentl::kErrIo: return "I/O error";
    case gentl::kErrTimeout: return "timeout";
    case gentl::kErrAbort: return "aborted";
    case gentl::kErrInvalidBuffer: return "invalid buffer";
    case gentl::kErrNotAvailable: return "not available";
    case gentl::kErrInvalidAddress: return "invalid address";
    case gentl::kErrBufferTooSmall: return "buffer too small";
    case gentl::kErrInvalidIndex: return "invalid index";
    case gentl::kErrInvalidValue: return "invalid value";
    case gentl::kErrResourceExhausted: return "resource exhausted";
    case gentl::kErrOutOfMemory: return "out of memory";
    case gentl::kErrBusy: return "busy";
    default: return "unknown status";
  }
}

// Loaded producers by canonical path: cameras on one grabber share its producer.
std::mutex registry_mutex;
std::map<std::filesystem::path, std::weak_ptr<Producer>>& registry() {
  static std::map<std::filesystem::path, std::weak_ptr<Producer>> loaded;
  return loaded;
}

}  // namespace

std::vector<std::filesystem::path> Producer::from_environment() {
  const char* variable = std::getenv("GENICAM_GENTL64_PATH");
  if (variable == nullptr || *variable == '\0')
    throw bad_input("no GenTL producer: give the camera's producer (the .cti file) with producer = \"...\" in its "
                    "[[cameras]] entry, or set GENICAM_GENTL64_PATH to the folder holding it");
  std::vector<std::filesystem::path> producers;
  const std::string text = variable;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find(':', begin), text.size());
    const std::filesystem::path entry = text.substr(begin, end - begin);
    begin = end + 1;
    std::error_code ec;
    if (entry.empty()) continue;
    if (std::filesystem::is_directory(entry, ec)) {
      std::vector<std::filesystem::path> found;
      for (const auto& file : std::filesystem::directory_iterator(entry, ec))
        if (file.path().extension() == ".cti") found.push_back(file.path());
      std::sort(found.begin(), found.end());  // a stable order, so the same producer wins each run
      producers.insert(producers.end(), found.begin(), found.end());
    } else if (std::filesystem::exists(entry, ec)) {
      producers.push_back(entry);
    }
  }
  if (producers.empty())
    throw bad_input(fmt::format("GENICAM_GENTL64_PATH = \"{}\" names no GenTL producer (.cti file): set it to the "
                                "folder holding the grabber's producer, or give producer = \"...\" in [[cameras]]",
                                text));
  return producers;
}

std::shared_ptr<Producer> Producer::load(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw bad_input(fmt::format("GenTL producer '{}' does not exist: give the path of the grabber's .cti file "
                                "(producer in [[cameras]] or GENICAM_GENTL64_PATH)",
                                path.string()));
  const std::filesystem::path canonical = std::filesystem::canonical(path, ec);
  const std::filesystem::path key = ec ? path : canonical;
  std::lock_guard lock(registry_mutex);
  if (auto existing = registry()[key].lock()) return existing;

  std::shared_ptr<Producer> producer(new Producer());
  producer->path_ = path;
  // RTLD_LOCAL: two producers may export the same names.
  producer->library_ = dlopen(key.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (producer->library_ == nullptr) {
    const char* why = dlerror();
    throw bad_input(fmt::format("GenTL producer '{}' is not a GenTL producer: it cannot be loaded as a shared library "
                                "({}), so it exports no GCInitLib",
                                path.string(), why != nullptr ? why : "dlopen failed"));
  }
  auto& fn = producer->fn_;
  std::vector<std::string> missing;
#define TOMORIG_GENTL_FUNCTION(name, since)                                                    \
  fn.name = reinterpret_cast<gentl::name##_t>(dlsym(producer->library_, #name));               \
  if (fn.name == nullptr && (since) < 13) missing.push_back(#name);
#include "gentl_functions.inc"
#undef TOMORIG_GENTL_FUNCTION
  if (fn.GCInitLib == nullptr)
    throw bad_input(fmt::format("'{}' is not a GenTL producer: it does not export GCInitLib; give the grabber "
                                "vendor's .cti file",
                                path.string()));
  if (!missing.empty())
    throw bad_input(fmt::format("GenTL producer '{}' lacks the mandatory GenTL function{} {} (GenTL 1.0-1.2 functions "
                                "are required): it is incomplete or too old; update the grabber's driver",
                                path.string(), missing.size() > 1 ? "s" : "", fmt::format("{}", fmt::join(missing, ", "))));

  const Status init = fn.GCInitLib();
  if (init != gentl::kSuccess)
    throw runtime_error(fmt::format("GenTL producer '{}': GCInitLib failed ({}); check the grabber's driver and licence",
                                    path.string(), producer->describe("GCInitLib", init)));
  producer->initialised_ = true;
  const Status open = fn.TLOpen(&producer->system_);
  if (open != gentl::kSuccess) {
    producer->system_ = nullptr;
    throw runtime_error(fmt::format("GenTL producer '{}': {}", path.string(), producer->describe("TLOpen", open)));
  }
  registry()[key] = producer;
  return producer;
}

Producer::~Producer() {
  for (auto* interface : interfaces_) fn_.IFClose(interface);
  if (system_ != nullptr) fn_.TLClose(system_);
  if (initialised_) fn_.GCCloseLib();
  // The library stays loaded: a producer may leave threads or atexit handlers behind, and
  // unloading their code under them would crash the process at exit.
}

std::string Producer::describe(const char* function, Status status) const {
  std::string text = fmt::format("{} failed: {} ({})", function, status, status_name(status));
  if (fn_.GCGetLastError != nullptr) {
    Status code = 0;
    char message[512] = {};
    std::size_t size = sizeof message;
    if (fn_.GCGetLastError(&code, message, &size) == gentl::kSuccess && message[0] != '\0')
      text += fmt::format(": {}", std::string(message, strnlen(message, sizeof message)));
  }
  return text;
}

std::vector<Producer::Found> Producer::enumerate() {
  std::vector<Found> found;
  gentl::Bool8 changed = 0;
  fn_.TLUpdateInterfaceList(system_, &changed, kUpdateTimeoutMs);
  std::uint32_t count = 0;
  if (fn_.TLGetNumInterfaces(system_, &count) != gentl::kSuccess) return found;
  for (auto* interface : interfaces_) fn_.IFClose(interface);
  interfaces_.clear();
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::string interface_id = info_string([&](gentl::InfoType*, void* buffer, std::size_t* size) {
      return fn_.TLGetInterfaceID(system_, i, static_cast<char*>(buffer), size);
    });
    gentl::Handle interface = nullptr;
    if (interface_id.empty() || fn_.TLOpenInterface(system_, interface_id.c_str(), &interface) != gentl::kSuccess)
      continue;
    interfaces_.push_back(interface);
    fn_.IFUpdateDeviceList(interface, &changed, kUpdateTimeoutMs);
    std::uint32_t devices = 0;
    if (fn_.IFGetNumDevices(interface, &devices) != gentl::kSuccess) continue;
    for (std::uint32_t d = 0; d < devices; ++d) {
      std::string device_id = info_string([&](gentl::InfoType*, void* buffer, std::size_t* size) {
        return fn_.IFGetDeviceID(interface, d, static_cast<char*>(buffer), size);
      });
      if (!device_id.empty()) found.push_back({interface, std::move(device_id)});
    }
  }
  return found;
}

std::string Producer::device_text(gentl::Handle interface, const std::string& device_id, std::int32_t cmd) {
  return info_string([&](gentl::InfoType* type, void* buffer, std::size_t* size) {
    return fn_.IFGetDeviceInfo(interface, device_id.c_str(), cmd, type, buffer, size);
  });
}

std::vector<std::string> Producer::list_devices() {
  std::vector<std::string> listed;
  for (const auto& f : enumerate())
    listed.push_back(fmt::format("{} (model {}, serial {})", f.device_id, device_text(f.interface, f.device_id, gentl::kDevInfoModel),
                                 device_text(f.interface, f.device_id, gentl::kDevInfoSerialNumber)));
  return listed;
}

std::unique_ptr<Device> Producer::open_device(const std::string& wanted) {
  for (const auto& f : enumerate()) {
    const bool match = f.device_id == wanted ||
                       device_text(f.interface, f.device_id, gentl::kDevInfoSerialNumber) == wanted ||
                       device_text(f.interface, f.device_id, gentl::kDevInfoUserDefinedName) == wanted ||
                       device_text(f.interface, f.device_id, gentl::kDevInfoDisplayName) == wanted;
    if (!match) continue;
    gentl::Handle handle = nullptr;
    const Status status = fn_.IFOpenDevice(f.interface, f.device_id.c_str(), gentl::kAccessControl, &handle);
    if (status != gentl::kSuccess)
      throw runtime_error(fmt::format("GenTL device '{}' of producer '{}': {} (is another program using it?)",
                                      f.device_id, path_.string(), describe("IFOpenDevice", status)));
    return std::make_unique<Device>(shared_from_this(), handle, f.device_id);
  }
  return nullptr;
}

Device::Device(std::shared_ptr<Producer> producer, gentl::Handle handle, std::string id)
    : producer_(std::move(producer)), handle_(handle), id_(std::move(id)) {
  const Status status = producer_->fn().DevGetPort(handle_, &port_);
  if (status != gentl::kSuccess) {
    producer_->fn().DevClose(handle_);
    throw runtime_error(fmt::format("GenTL device '{}': {}", id_, producer_->describe("DevGetPort", status)));
  }
}

Device::~Device() {
  if (handle_ != nullptr) producer_->fn().DevClose(handle_);
}

}  // namespace tomorig::acquisition::gentl_detail

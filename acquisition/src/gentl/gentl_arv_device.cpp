#include "gentl_arv_device.h"

#include <fmt/format.h>

#include <cstring>

#include "tomorig/core/error.h"
#include "gentl_xml.h"

namespace {

using tomorig::acquisition::gentl_detail::Device;

struct TomorigGentlDevice {
  ArvDevice parent_instance;
  std::shared_ptr<Device>* device;  // heap-held: GObject instances are C structs
  ArvGc* genicam;
  char* xml;
  std::size_t xml_size;
};
struct TomorigGentlDeviceClass {
  ArvDeviceClass parent_class;
};

G_DEFINE_TYPE(TomorigGentlDevice, tomorig_gentl_device, ARV_TYPE_DEVICE)

TomorigGentlDevice* self_of(ArvDevice* device) { return reinterpret_cast<TomorigGentlDevice*>(device); }

void set_port_error(GError** error, const Device& device, const char* function, std::int32_t status,
                    std::uint64_t address) {
  const gint code = status == tomorig::gentl::kErrTimeout ? ARV_DEVICE_ERROR_TIMEOUT
                    : status == tomorig::gentl::kErrInvalidAddress ? ARV_DEVICE_ERROR_PROTOCOL_ERROR_INVALID_ADDRESS
                    : status == tomorig::gentl::kErrAccessDenied ? ARV_DEVICE_ERROR_PROTOCOL_ERROR_ACCESS_DENIED
                                                                 : ARV_DEVICE_ERROR_TRANSFER_ERROR;
  const std::string text = fmt::format("GenTL device {} at 0x{:x}: {}", device.id(), address,
                                       device.producer().describe(function, status));
  g_set_error_literal(error, ARV_DEVICE_ERROR, code, text.c_str());
}

gboolean read_memory(ArvDevice* device, guint64 address, guint32 size, void* buffer, GError** error) {
  const Device& d = **self_of(device)->device;
  std::size_t done = size;
  const std::int32_t status = d.producer().fn().GCReadPort(d.remote_port(), address, buffer, &done);
  if (status != tomorig::gentl::kSuccess || done != size) {
    set_port_error(error, d, "GCReadPort", status == tomorig::gentl::kSuccess ? tomorig::gentl::kErrIo : status, address);
    return FALSE;
  }
  return TRUE;
}

gboolean write_memory(ArvDevice* device, guint64 address, guint32 size, void* buffer, GError** error) {
  const Device& d = **self_of(device)->device;
  std::size_t done = size;
  const std::int32_t status = d.producer().fn().GCWritePort(d.remote_port(), address, buffer, &done);
  if (status != tomorig::gentl::kSuccess || done != size) {
    set_port_error(error, d, "GCWritePort", status == tomorig::gentl::kSuccess ? tomorig::gentl::kErrIo : status, address);
    return FALSE;
  }
  return TRUE;
}

// Bare 32-bit registers in the host's byte order; GenApi nodes go through read/write_memory
// with the endianness their description states.
gboolean read_register(ArvDevice* device, guint64 address, guint32* value, GError** error) {
  return read_memory(device, address, sizeof *value, value, error);
}

gboolean write_register(ArvDevice* device, guint64 address, guint32 value, GError** error) {
  return write_memory(device, address, sizeof value, &value, error);
}

ArvGc* get_genicam(ArvDevice* device) { return self_of(device)->genicam; }

const char* get_genicam_xml(ArvDevice* device, size_t* size) {
  *size = self_of(device)->xml_size;
  return self_of(device)->xml;
}

ArvStream* create_stream(ArvDevice*, ArvStreamCallback, void*, GDestroyNotify, GError** error) {
  g_set_error_literal(error, ARV_DEVICE_ERROR, ARV_DEVICE_ERROR_NO_STREAM_CHANNEL,
                      "a GenTL device streams through its GenTL data stream, not an Aravis stream");
  return nullptr;
}

void finalize(GObject* object) {
  auto* self = reinterpret_cast<TomorigGentlDevice*>(object);
  g_clear_object(&self->genicam);
  g_free(self->xml);
  self->xml = nullptr;
  delete self->device;
  self->device = nullptr;
  G_OBJECT_CLASS(tomorig_gentl_device_parent_class)->finalize(object);
}

void tomorig_gentl_device_init(TomorigGentlDevice* self) {
  self->device = nullptr;
  self->genicam = nullptr;
  self->xml = nullptr;
  self->xml_size = 0;
}

void tomorig_gentl_device_class_init(TomorigGentlDeviceClass* klass) {
  G_OBJECT_CLASS(klass)->finalize = finalize;
  auto* device_class = ARV_DEVICE_CLASS(klass);
  device_class->create_stream = create_stream;
  device_class->get_genicam_xml = get_genicam_xml;
  device_class->get_genicam = get_genicam;
  device_class->read_memory = read_memory;
  device_class->write_memory = write_memory;
  device_class->read_register = read_register;
  device_class->write_register = write_register;
}

}  // namespace

namespace tomorig::acquisition::gentl_detail {

ArvDevice* new_arv_device(std::shared_ptr<Device> device, const std::string& what) {
  const std::string xml = fetch_port_xml(device->producer(), device->remote_port(), what);
  auto* self = static_cast<TomorigGentlDevice*>(g_object_new(tomorig_gentl_device_get_type(), nullptr));
  self->device = new std::shared_ptr<Device>(std::move(device));
  self->xml = static_cast<char*>(g_malloc(xml.size() + 1));
  std::memcpy(self->xml, xml.data(), xml.size());
  self->xml[xml.size()] = '\0';
  self->xml_size = xml.size();
  self->genicam = arv_gc_new(ARV_DEVICE(self), self->xml, self->xml_size);
  if (self->genicam == nullptr || arv_gc_get_node(self->genicam, "Root") == nullptr) {
    g_object_unref(self);
    throw runtime_error(fmt::format("{}: the GenICam description of the GenTL device cannot be parsed (no Root node)",
                                    what));
  }
  return ARV_DEVICE(self);
}

}  // namespace tomorig::acquisition::gentl_detail

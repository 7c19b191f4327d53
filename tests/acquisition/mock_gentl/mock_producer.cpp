// A mock GenTL producer (.cti) for tomorig's tests: one interface with MOCK_GENTL_DEVICES
// cameras (default 4, ids "mockcam0"...), each with a small GenICam description and register
// map, software and hardware-style ("Line1", fired by MockGenTLFireLine) triggers, a
// one-trigger-two-frames burst (TriggerSelector = FrameBurstStart, AcquisitionBurstFrameCount
// = 2) and synthetic particle images that carry a tag: which camera, which trigger (counted
// since AcquisitionStart) and which frame of the burst, so a test can check from the recorded
// session that frames A and B of a set answer the same trigger.
//
// Faults, by GenICam feature (rig file [cameras.features]), counted per camera:
//   MockIncompleteEvery = N  every Nth frame is delivered flagged incomplete, half filled,
//                            its tag marked corrupt
//   MockDropEvery = N        every Nth frame never comes (its frame id is skipped)
//   MockUnderrunEvery = N    every Nth frame finds no buffer (an underrun)
//   MockStallAfter = N       the camera stops answering triggers after N (a camera that died)
// and by environment, read at GCInitLib:
//   MOCK_GENTL_FAIL_INIT=1      GCInitLib fails
//   MOCK_GENTL_XML=zip|file     the description is served zipped, or as a file: URL
//   MOCK_GENTL_NO_PAYLOADSIZE=1 the description has no PayloadSize (the stream gives it)
// Build variants: MOCK_GENTL_NO_OPTIONAL is an older producer: no GenTL 1.3+ functions,
// timestamps in microsecond ticks (TIMESTAMP and the device's TIMESTAMP_FREQUENCY, no
// TIMESTAMP_NS), and buffers that must be 4096-byte aligned (BUF_ALIGNMENT);
// MOCK_GENTL_OMIT_QUEUE leaves out the mandatory DSQueueBuffer.
//
// Written for tests only: one process, a handful of cameras, no real hardware.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include "../../../acquisition/src/gentl/gentl_api.h"

using namespace tomorig::gentl;

#define MOCK_EXPORT extern "C" __attribute__((visibility("default")))

namespace {

constexpr std::uint32_t kMagicSystem = 0x5359534d, kMagicInterface = 0x4946434d, kMagicDevice = 0x4445564d,
                        kMagicPort = 0x504f524d, kMagicStream = 0x5354524d, kMagicBuffer = 0x4255464d,
                        kMagicEvent = 0x45564e4d;

constexpr std::uint64_t kXmlAddress = 0x100000;
constexpr std::uint32_t kMono8 = 0x01080001, kMono16 = 0x01100007;

// Register addresses (little-endian).
enum : std::uint64_t {
  kVendor = 0x0000,
  kModel = 0x0020,
  kSerial = 0x0040,
  kWidth = 0x0100,
  kHeight = 0x0104,
  kPixelFormat = 0x0108,
  kPayloadSize = 0x010C,
  kAcquisitionMode = 0x0110,
  kAcquisitionStart = 0x0114,
  kAcquisitionStop = 0x0118,
  kTriggerSelector = 0x011C,
  kTriggerMode = 0x0120,        // + 4 * selector
  kTriggerSource = 0x0128,      // + 4 * selector (0 Line1, 1 Software)
  kTriggerActivation = 0x0130,  // + 4 * selector
  kTriggerSoftware = 0x0138,
  kBurstCount = 0x0140,
  kExposure = 0x0148,  // float64, microseconds
  kIncompleteEvery = 0x0150,
  kDropEvery = 0x0154,
  kStallAfter = 0x0158,
  kUnderrunEvery = 0x015C,
  kTriggersReceived = 0x0164,
  kRegisterBytes = 0x0200,
};

thread_local std::string last_error;

Status fail(Status status, std::string text) {
  last_error = std::move(text);
  return status;
}

template <typename T>
Status put(InfoType* type, void* buffer, std::size_t* size, T value, InfoType kind) {
  if (type != nullptr) *type = kind;
  if (size == nullptr) return fail(kErrInvalidParameter, "size is null");
  if (buffer == nullptr) {
    *size = sizeof value;
    return kSuccess;
  }
  if (*size < sizeof value) return fail(kErrBufferTooSmall, "buffer too small");
  std::memcpy(buffer, &value, sizeof value);
  *size = sizeof value;
  return kSuccess;
}

Status put_string(InfoType* type, void* buffer, std::size_t* size, const std::string& text) {
  if (type != nullptr) *type = kTypeString;
  if (size == nullptr) return fail(kErrInvalidParameter, "size is null");
  if (buffer == nullptr) {
    *size = text.size() + 1;
    return kSuccess;
  }
  if (*size < text.size() + 1) return fail(kErrBufferTooSmall, "buffer too small");
  std::memcpy(buffer, text.c_str(), text.size() + 1);
  *size = text.size() + 1;
  return kSuccess;
}

struct Options {
  bool fail_init = false;
  std::string xml_mode = "local";
  bool payload_size_feature = true;
  int devices = 4;
};
Options options;
std::atomic<bool> initialised{false};

std::string genicam_xml() {
  std::string xml = R"(<?xml version="1.0" encoding="utf-8"?>
<RegisterDescription ModelName="MockGenTL" VendorName="tomorig" StandardNameSpace="None"
  SchemaMajorVersion="1" SchemaMinorVersion="1" SchemaSubMinorVersion="0" MajorVersion="1" MinorVersion="0"
  SubMinorVersion="0" ToolTip="tomorig mock GenTL camera" ProductGuid="0" VersionGuid="0"
  xmlns="http://www.genicam.org/GenApi/Version_1_1">
  <Category Name="Root" NameSpace="Standard">
    <pFeature>DeviceVendorName</pFeature><pFeature>DeviceModelName</pFeature><pFeature>Width</pFeature>
    <pFeature>Height</pFeature><pFeature>PixelFormat</pFeature>@PAYLOAD_FEATURE@<pFeature>AcquisitionMode</pFeature>
    <pFeature>AcquisitionStart</pFeature><pFeature>AcquisitionStop</pFeature><pFeature>TriggerSelector</pFeature>
    <pFeature>TriggerMode</pFeature><pFeature>TriggerSource</pFeature><pFeature>TriggerActivation</pFeature>
    <pFeature>TriggerSoftware</pFeature><pFeature>AcquisitionBurstFrameCount</pFeature><pFeature>ExposureTime</pFeature>
    <pFeature>MockIncompleteEvery</pFeature><pFeature>MockDropEvery</pFeature><pFeature>MockStallAfter</pFeature>
    <pFeature>MockUnderrunEvery</pFeature><pFeature>MockTriggersReceived</pFeature>
  </Category>
  <StringReg Name="DeviceVendorName" NameSpace="Standard"><Address>0x0</Address><Length>32</Length><AccessMode>RO</AccessMode><pPort>Device</pPort></StringReg>
  <StringReg Name="DeviceModelName" NameSpace="Standard"><Address>0x20</Address><Length>32</Length><AccessMode>RO</AccessMode><pPort>Device</pPort></StringReg>
  <Integer Name="Width" NameSpace="Standard"><pValue>WidthReg</pValue><Min>16</Min><Max>2048</Max><Inc>1</Inc></Integer>
  <IntReg Name="WidthReg"><Address>0x100</Address><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Integer Name="Height" NameSpace="Standard"><pValue>HeightReg</pValue><Min>4</Min><Max>2048</Max><Inc>1</Inc></Integer>
  <IntReg Name="HeightReg"><Address>0x104</Address><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Enumeration Name="PixelFormat" NameSpace="Standard">
    <EnumEntry Name="Mono8" NameSpace="Standard"><Value>0x01080001</Value></EnumEntry>
    <EnumEntry Name="Mono16" NameSpace="Standard"><Value>0x01100007</Value></EnumEntry>
    <pValue>PixelFormatReg</pValue>
  </Enumeration>
  <IntReg Name="PixelFormatReg"><Address>0x108</Address><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  @PAYLOAD_NODE@
  <Enumeration Name="AcquisitionMode" NameSpace="Standard">
    <EnumEntry Name="Continuous" NameSpace="Standard"><Value>0</Value></EnumEntry>
    <pValue>AcquisitionModeReg</pValue>
  </Enumeration>
  <IntReg Name="AcquisitionModeReg"><Address>0x110</Address><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Command Name="AcquisitionStart" NameSpace="Standard"><pValue>AcquisitionStartReg</pValue><CommandValue>1</CommandValue></Command>
  <IntReg Name="AcquisitionStartReg"><Address>0x114</Address><Length>4</Length><AccessMode>WO</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Command Name="AcquisitionStop" NameSpace="Standard"><pValue>AcquisitionStopReg</pValue><CommandValue>1</CommandValue></Command>
  <IntReg Name="AcquisitionStopReg"><Address>0x118</Address><Length>4</Length><AccessMode>WO</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Enumeration Name="TriggerSelector" NameSpace="Standard">
    <EnumEntry Name="FrameStart" NameSpace="Standard"><Value>0</Value></EnumEntry>
    <EnumEntry Name="FrameBurstStart" NameSpace="Standard"><Value>1</Value></EnumEntry>
    <pValue>TriggerSelectorReg</pValue>
  </Enumeration>
  <IntReg Name="TriggerSelectorReg"><Address>0x11C</Address><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Enumeration Name="TriggerMode" NameSpace="Standard">
    <EnumEntry Name="Off" NameSpace="Standard"><Value>0</Value></EnumEntry>
    <EnumEntry Name="On" NameSpace="Standard"><Value>1</Value></EnumEntry>
    <pValue>TriggerModeReg</pValue>
  </Enumeration>
  <IntReg Name="TriggerModeReg"><Address>0x120</Address><pIndex Offset="4">TriggerSelectorReg</pIndex><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Enumeration Name="TriggerSource" NameSpace="Standard">
    <EnumEntry Name="Line1" NameSpace="Standard"><Value>0</Value></EnumEntry>
    <EnumEntry Name="Software" NameSpace="Standard"><Value>1</Value></EnumEntry>
    <pValue>TriggerSourceReg</pValue>
  </Enumeration>
  <IntReg Name="TriggerSourceReg"><Address>0x128</Address><pIndex Offset="4">TriggerSelectorReg</pIndex><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Enumeration Name="TriggerActivation" NameSpace="Standard">
    <EnumEntry Name="RisingEdge" NameSpace="Standard"><Value>0</Value></EnumEntry>
    <EnumEntry Name="FallingEdge" NameSpace="Standard"><Value>1</Value></EnumEntry>
    <pValue>TriggerActivationReg</pValue>
  </Enumeration>
  <IntReg Name="TriggerActivationReg"><Address>0x130</Address><pIndex Offset="4">TriggerSelectorReg</pIndex><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Command Name="TriggerSoftware" NameSpace="Standard"><pValue>TriggerSoftwareReg</pValue><CommandValue>1</CommandValue></Command>
  <IntReg Name="TriggerSoftwareReg"><Address>0x138</Address><Length>4</Length><AccessMode>WO</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Integer Name="AcquisitionBurstFrameCount" NameSpace="Standard"><pValue>BurstReg</pValue><Min>1</Min><Max>2</Max><Inc>1</Inc></Integer>
  <IntReg Name="BurstReg"><Address>0x140</Address><Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Float Name="ExposureTime" NameSpace="Standard"><pValue>ExposureReg</pValue><Min>1</Min><Max>1000000</Max><Unit>us</Unit></Float>
  <FloatReg Name="ExposureReg"><Address>0x148</Address><Length>8</Length><AccessMode>RW</AccessMode><pPort>Device</pPort><Endianess>LittleEndian</Endianess></FloatReg>
  @MOCK_FAULTS@
  <Integer Name="MockTriggersReceived"><pValue>TriggersReceivedReg</pValue></Integer>
  <IntReg Name="TriggersReceivedReg"><Address>0x164</Address><Length>4</Length><AccessMode>RO</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>
  <Port Name="Device" NameSpace="Standard"/>
</RegisterDescription>
)";
  auto replace = [&](const std::string& key, const std::string& value) { xml.replace(xml.find(key), key.size(), value); };
  std::string faults;
  const std::pair<const char*, std::uint64_t> fault_registers[] = {{"MockIncompleteEvery", kIncompleteEvery},
                                                                   {"MockDropEvery", kDropEvery},
                                                                   {"MockStallAfter", kStallAfter},
                                                                   {"MockUnderrunEvery", kUnderrunEvery}};
  for (const auto& [name, address] : fault_registers) {
    char node[640];
    std::snprintf(node, sizeof node,
                  "<Integer Name=\"%s\"><pValue>%sReg</pValue><Min>0</Min><Max>1000000</Max><Inc>1</Inc></Integer>\n"
                  "  <IntReg Name=\"%sReg\"><Address>0x%llx</Address><Length>4</Length><AccessMode>RW</AccessMode>"
                  "<pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess></IntReg>\n  ",
                  name, name, name, static_cast<unsigned long long>(address));
    faults += node;
  }
  replace("@MOCK_FAULTS@", faults);
  replace("@PAYLOAD_FEATURE@", options.payload_size_feature ? "<pFeature>PayloadSize</pFeature>" : "");
  replace("@PAYLOAD_NODE@",
          options.payload_size_feature
              ? "<IntReg Name=\"PayloadSize\" NameSpace=\"Standard\"><Address>0x10C</Address><Length>4</Length>"
                "<AccessMode>RO</AccessMode><pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>LittleEndian</Endianess>"
                "</IntReg>"
              : "");
  return xml;
}

// A zip archive holding `name` stored (method 0): readers must handle stored entries as well
// as deflated ones, and this needs no compressor.
std::string stored_zip(const std::string& name, const std::string& data) {
  std::uint32_t table[256];
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  std::uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char byte : data) crc = table[(crc ^ byte) & 0xFF] ^ (crc >> 8);
  crc ^= 0xFFFFFFFFu;
  std::string out;
  auto u16 = [&](std::uint32_t v) { out.push_back(char(v & 0xFF)), out.push_back(char((v >> 8) & 0xFF)); };
  auto u32 = [&](std::uint32_t v) { u16(v & 0xFFFF), u16(v >> 16); };
  const auto size = static_cast<std::uint32_t>(data.size());
  const auto name_size = static_cast<std::uint32_t>(name.size());
  u32(0x04034b50), u16(20), u16(0), u16(0), u16(0), u16(0), u32(crc), u32(size), u32(size), u16(name_size), u16(0);
  out += name;
  out += data;
  const auto central = static_cast<std::uint32_t>(out.size());
  u32(0x02014b50), u16(20), u16(20), u16(0), u16(0), u16(0), u16(0), u32(crc), u32(size), u32(size), u16(name_size);
  u16(0), u16(0), u16(0), u16(0), u32(0), u32(0);
  out += name;
  const auto central_size = static_cast<std::uint32_t>(out.size()) - central;
  u32(0x06054b50), u16(0), u16(0), u16(1), u16(1), u32(central_size), u32(central), u16(0);
  return out;
}

struct Stream;

struct Buffer {
  std::uint32_t magic = kMagicBuffer;
  std::byte* base = nullptr;
  std::size_t size = 0;
  void* user = nullptr;
  bool queued = false;
  std::uint64_t frame_id = 0;
  std::uint64_t timestamp_ns = 0;
  bool incomplete = false;
  std::size_t filled = 0;
  std::uint32_t width = 0, height = 0, pixel_format = 0;
};

struct Event {
  std::uint32_t magic = kMagicEvent;
  Stream* stream = nullptr;
};

struct Device;

struct Stream {
  std::uint32_t magic = kMagicStream;
  Device* device = nullptr;
  std::mutex mutex;
  std::condition_variable filled;
  std::vector<std::unique_ptr<Buffer>> buffers;
  std::deque<Buffer*> input, output;
  std::unique_ptr<Event> event;
  bool killed = false;
  bool acquiring = false;
  std::uint64_t delivered = 0, underruns = 0;
};

struct Port {
  std::uint32_t magic = kMagicPort;
  Device* device = nullptr;
};

struct Trigger {
  std::uint64_t host_ns;
};

struct Device {
  std::uint32_t magic = kMagicDevice;
  int index = 0;
  std::string id;
  Port port;
  std::mutex mutex;  // registers, triggers, stream state
  std::condition_variable wake;
  std::vector<std::byte> registers = std::vector<std::byte>(kRegisterBytes);
  std::string xml_blob;  // what the local: URL points at (plain or zipped, NUL padded)
  std::string url;
  std::string xml_file;  // MOCK_GENTL_XML=file: the description on disk, removed at GCCloseLib
  bool open = false;
  bool acquiring = false;  // AcquisitionStart executed
  std::deque<Trigger> triggers;
  std::unique_ptr<Stream> stream;
  std::thread worker;
  bool stop_worker = false;
  std::uint64_t next_frame_id = 0;

  template <typename T>
  T reg(std::uint64_t address) const {
    T value;
    std::memcpy(&value, registers.data() + address, sizeof value);
    return value;
  }
  template <typename T>
  void set_reg(std::uint64_t address, T value) {
    std::memcpy(registers.data() + address, &value, sizeof value);
  }
  std::uint32_t bytes_per_pixel() const { return reg<std::uint32_t>(kPixelFormat) == kMono16 ? 2 : 1; }
  std::size_t payload() const {
    return std::size_t{reg<std::uint32_t>(kWidth)} * reg<std::uint32_t>(kHeight) * bytes_per_pixel();
  }
  // The trigger in use: FrameBurstStart if its mode is On, else FrameStart if On; -1: none.
  int active_selector() const {
    if (reg<std::uint32_t>(kTriggerMode + 4) == 1) return 1;
    if (reg<std::uint32_t>(kTriggerMode) == 1) return 0;
    return -1;
  }
};

struct Interface {
  std::uint32_t magic = kMagicInterface;
  std::vector<std::unique_ptr<Device>> devices;
  bool open = false;
};

struct System {
  std::uint32_t magic = kMagicSystem;
  Interface interface;
  bool open = false;
};

System* the_system = nullptr;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

template <typename T>
T* as(void* handle, std::uint32_t magic) {
  auto* typed = static_cast<T*>(handle);
  return typed != nullptr && typed->magic == magic ? typed : nullptr;
}

void make_devices() {
  the_system = new System();
  for (int i = 0; i < options.devices; ++i) {
    auto device = std::make_unique<Device>();
    device->index = i;
    device->id = "mockcam" + std::to_string(i);
    device->port.device = device.get();
    std::snprintf(reinterpret_cast<char*>(device->registers.data() + kVendor), 32, "tomorig");
    std::snprintf(reinterpret_cast<char*>(device->registers.data() + kModel), 32, "MockGenTL");
    std::snprintf(reinterpret_cast<char*>(device->registers.data() + kSerial), 32, "MOCK%04d", i);
    device->set_reg<std::uint32_t>(kWidth, 64);
    device->set_reg<std::uint32_t>(kHeight, 48);
    device->set_reg<std::uint32_t>(kPixelFormat, kMono8);
    device->set_reg<std::uint32_t>(kBurstCount, 1);
    device->set_reg<std::uint32_t>(kTriggerSource, 1);
    device->set_reg<std::uint32_t>(kTriggerSource + 4, 1);
    device->set_reg<double>(kExposure, 100.0);
    const std::string xml = genicam_xml();
    if (options.xml_mode == "file") {
      const std::string path = "/tmp/tomorig-mock-gentl-" + std::to_string(getpid()) + "-" + device->id + ".xml";
      std::ofstream(path, std::ios::binary) << xml;
      device->url = "file://" + path + "?SchemaVersion=1.1.0";
      device->xml_file = path;
    } else {
      const bool zip = options.xml_mode == "zip";
      device->xml_blob = zip ? stored_zip("mock_camera.xml", xml) : xml;
      // Padded with NULs to a whole block, as description registers are; readers strip them.
      device->xml_blob.resize((device->xml_blob.size() / 256 + 1) * 256, '\0');
      char url[160];
      std::snprintf(url, sizeof url, "local:///%s;%llx;%zx?SchemaVersion=1.1.0", zip ? "mock_camera.zip" : "mock_camera.xml",
                    static_cast<unsigned long long>(kXmlAddress), device->xml_blob.size());
      device->url = url;
    }
    the_system->interface.devices.push_back(std::move(device));
  }
}

// Simulated particle images: dots at positions drawn from the trigger number, displaced by
// 2 px in frame B; the first 16 bytes carry the tag.
void render(Device& d, Buffer& b, std::uint32_t trigger, int frame_in_burst, bool corrupt) {
  const std::uint32_t w = d.reg<std::uint32_t>(kWidth), h = d.reg<std::uint32_t>(kHeight);
  const std::uint32_t bpp = d.bytes_per_pixel();
  const std::size_t bytes = std::size_t{w} * h * bpp;
  b.width = w, b.height = h, b.pixel_format = d.reg<std::uint32_t>(kPixelFormat);
  b.filled = corrupt ? bytes / 2 : bytes;
  std::memset(b.base, 0, b.filled);
  std::uint64_t state = 0x9E3779B97F4A7C15ull * (trigger + 1);
  for (int p = 0; p < 12; ++p) {
    state ^= state >> 33, state *= 0xff51afd7ed558ccdull, state ^= state >> 29;
    const std::uint32_t x = 2 + static_cast<std::uint32_t>(state % (w - 6)) + (frame_in_burst == 1 ? 2 : 0);
    const std::uint32_t y = 2 + static_cast<std::uint32_t>((state >> 20) % (h - 4));
    for (std::uint32_t dy = 0; dy < 2; ++dy)
      for (std::uint32_t dx = 0; dx < 2 && x + dx < w; ++dx) {
        const std::size_t at = (std::size_t{y + dy} * w + x + dx) * bpp;
        if (at + bpp > b.filled) continue;
        if (bpp == 2) {
          const std::uint16_t value = 2000;
          std::memcpy(b.base + at, &value, 2);
        } else {
          b.base[at] = std::byte{200};
        }
      }
  }
  unsigned char tag[16] = {'T', 'M', 'G', '1'};
  const std::uint32_t camera = static_cast<std::uint32_t>(d.index);
  std::memcpy(tag + 4, &camera, 4);
  std::memcpy(tag + 8, &trigger, 4);
  tag[12] = corrupt ? 0xEE : static_cast<unsigned char>(frame_in_burst);
  unsigned sum = 0;
  for (int i = 0; i < 13; ++i) sum += tag[i];
  tag[13] = static_cast<unsigned char>(sum & 0xFF), tag[14] = static_cast<unsigned char>(sum >> 8), tag[15] = 0x5A;
  std::memcpy(b.base, tag, std::min<std::size_t>(16, b.filled));
}

// One trigger: one frame (FrameStart) or a burst (FrameBurstStart), with the faults applied.
void answer(Device& d, const Trigger& trigger) {
  std::unique_lock lock(d.mutex);
  const std::uint32_t received = d.reg<std::uint32_t>(kTriggersReceived) + 1;
  d.set_reg<std::uint32_t>(kTriggersReceived, received);
  const std::uint32_t stall_after = d.reg<std::uint32_t>(kStallAfter);
  if (stall_after > 0 && received > stall_after) return;  // the camera no longer answers
  const int frames = d.active_selector() == 1 ? static_cast<int>(d.reg<std::uint32_t>(kBurstCount)) : 1;
  const double exposure_us = d.reg<double>(kExposure);
  if (!d.stream) return;
  Stream& s = *d.stream;
  for (int k = 0; k < frames; ++k) {
    const std::uint64_t frame_id = d.next_frame_id++;
    const std::uint64_t nth = frame_id + 1;
    auto every = [&](std::uint64_t address) {
      const std::uint32_t n = d.reg<std::uint32_t>(address);
      return n > 0 && nth % n == 0;
    };
    if (every(kDropEvery)) continue;
    std::lock_guard stream_lock(s.mutex);
    if (!s.acquiring) continue;  // the stream is stopped: the frame goes nowhere
    if (every(kUnderrunEvery) || s.input.empty()) {
      ++s.underruns;
      continue;
    }
    Buffer* b = s.input.front();
    if (b->size < d.payload()) {  // a buffer too small for the image: not filled
      ++s.underruns;
      continue;
    }
    s.input.pop_front();
    const bool corrupt = every(kIncompleteEvery);
    render(d, *b, received - 1, k, corrupt);
    b->incomplete = corrupt;
    b->frame_id = frame_id;
    b->timestamp_ns = static_cast<std::uint64_t>(trigger.host_ns) +
                      static_cast<std::uint64_t>(k * exposure_us * 1000.0);
    b->queued = false;
    s.output.push_back(b);
    ++s.delivered;
    s.filled.notify_all();
  }
}

void worker_loop(Device* d) {
  for (;;) {
    Trigger trigger{};
    {
      std::unique_lock lock(d->mutex);
      d->wake.wait(lock, [&] { return d->stop_worker || !d->triggers.empty(); });
      if (d->stop_worker) return;
      trigger = d->triggers.front();
      d->triggers.pop_front();
    }
    answer(*d, trigger);
  }
}

// Called with d.mutex held.
void fire(Device& d, std::uint32_t source) {
  const int selector = d.active_selector();
  if (!d.acquiring || selector < 0) return;
  if (d.reg<std::uint32_t>(kTriggerSource + 4 * static_cast<std::uint64_t>(selector)) != source) return;
  d.triggers.push_back({static_cast<std::uint64_t>(now_ns())});
  d.wake.notify_all();
}

Status read_remote(Device& d, std::uint64_t address, void* buffer, std::size_t* size) {
  std::lock_guard lock(d.mutex);
  if (address >= kXmlAddress) {
    const std::uint64_t offset = address - kXmlAddress;
    if (offset + *size > d.xml_blob.size()) return fail(kErrInvalidAddress, "read past the description");
    std::memcpy(buffer, d.xml_blob.data() + offset, *size);
    return kSuccess;
  }
  if (address + *size > kRegisterBytes) return fail(kErrInvalidAddress, "no register there");
  d.set_reg<std::uint32_t>(kPayloadSize, static_cast<std::uint32_t>(d.payload()));
  std::memcpy(buffer, d.registers.data() + address, *size);
  return kSuccess;
}

Status write_remote(Device& d, std::uint64_t address, const void* buffer, std::size_t* size) {
  std::lock_guard lock(d.mutex);
  if (address + *size > kRegisterBytes) return fail(kErrInvalidAddress, "no register there");
  if (address == kPayloadSize || address == kTriggersReceived) return fail(kErrAccessDenied, "read-only register");
  std::memcpy(d.registers.data() + address, buffer, *size);
  if (address == kAcquisitionStart) {
    d.acquiring = true;
    d.set_reg<std::uint32_t>(kTriggersReceived, 0);
  } else if (address == kAcquisitionStop) {
    d.acquiring = false;
  } else if (address == kTriggerSoftware) {
    fire(d, 1);
  }
  return kSuccess;
}

}  // namespace

// ---- GenTL system functions --------------------------------------------------------------

MOCK_EXPORT Status GCInitLib() {
  if (initialised) return fail(kErrResourceInUse, "already initialised");
  const char* fail_init = std::getenv("MOCK_GENTL_FAIL_INIT");
  if (fail_init != nullptr && std::string(fail_init) == "1")
    return fail(kErrError, "mock producer: GCInitLib fails as asked (MOCK_GENTL_FAIL_INIT=1)");
  options = Options{};
  if (const char* xml = std::getenv("MOCK_GENTL_XML")) options.xml_mode = xml;
  if (const char* no_payload = std::getenv("MOCK_GENTL_NO_PAYLOADSIZE")) options.payload_size_feature = std::string(no_payload) != "1";
  if (const char* devices = std::getenv("MOCK_GENTL_DEVICES")) options.devices = std::max(1, std::atoi(devices));
  make_devices();
  initialised = true;
  return kSuccess;
}

MOCK_EXPORT Status GCCloseLib() {
  if (!initialised) return fail(kErrNotInitialized, "not initialised");
  for (auto& device : the_system->interface.devices) {
    {
      std::lock_guard lock(device->mutex);
      device->stop_worker = true;
    }
    device->wake.notify_all();
    if (device->worker.joinable()) device->worker.join();
    if (!device->xml_file.empty()) std::remove(device->xml_file.c_str());
  }
  delete the_system;
  the_system = nullptr;
  initialised = false;
  return kSuccess;
}

MOCK_EXPORT Status GCGetInfo(std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size) {
  if (cmd == kTlInfoVendor) return put_string(type, buffer, size, "tomorig");
  if (cmd == kTlInfoModel) return put_string(type, buffer, size, "mock GenTL producer");
  return fail(kErrNotImplemented, "info not available");
}

MOCK_EXPORT Status GCGetLastError(Status* code, char* text, std::size_t* size) {
  if (code != nullptr) *code = kErrError;
  return put_string(nullptr, text, size, last_error);
}

MOCK_EXPORT Status GCReadPort(Handle port, std::uint64_t address, void* buffer, std::size_t* size) {
  if (!initialised) return fail(kErrNotInitialized, "not initialised");
  auto* p = as<Port>(port, kMagicPort);
  if (p == nullptr || buffer == nullptr || size == nullptr) return fail(kErrInvalidHandle, "not a remote port");
  return read_remote(*p->device, address, buffer, size);
}

MOCK_EXPORT Status GCWritePort(Handle port, std::uint64_t address, const void* buffer, std::size_t* size) {
  if (!initialised) return fail(kErrNotInitialized, "not initialised");
  auto* p = as<Port>(port, kMagicPort);
  if (p == nullptr || buffer == nullptr || size == nullptr) return fail(kErrInvalidHandle, "not a remote port");
  return write_remote(*p->device, address, buffer, size);
}

MOCK_EXPORT Status GCGetPortURL(Handle port, char* url, std::size_t* size) {
  auto* p = as<Port>(port, kMagicPort);
  if (p == nullptr) return fail(kErrInvalidHandle, "not a remote port");
  return put_string(nullptr, url, size, p->device->url);
}

MOCK_EXPORT Status GCGetPortInfo(Handle, std::int32_t, InfoType*, void*, std::size_t*) {
  return fail(kErrNotImplemented, "no port info");
}

MOCK_EXPORT Status GCGetNumPortURLs(Handle port, std::uint32_t* count) {
  if (as<Port>(port, kMagicPort) == nullptr) return fail(kErrInvalidHandle, "not a remote port");
  *count = 1;
  return kSuccess;
}

MOCK_EXPORT Status GCGetPortURLInfo(Handle port, std::uint32_t index, std::int32_t cmd, InfoType* type, void* buffer,
                                    std::size_t* size) {
  auto* p = as<Port>(port, kMagicPort);
  if (p == nullptr) return fail(kErrInvalidHandle, "not a remote port");
  if (index != 0) return fail(kErrInvalidIndex, "one URL only");
  if (cmd != kUrlInfoUrl) return fail(kErrNotImplemented, "URL info not available");
  return put_string(type, buffer, size, p->device->url);
}

MOCK_EXPORT Status GCReadPortStacked(Handle, void*, std::size_t*) { return fail(kErrNotImplemented, "no stacked reads"); }
MOCK_EXPORT Status GCWritePortStacked(Handle, void*, std::size_t*) { return fail(kErrNotImplemented, "no stacked writes"); }

MOCK_EXPORT Status GCRegisterEvent(Handle source, std::int32_t event_type, Handle* event) {
  auto* s = as<Stream>(source, kMagicStream);
  if (s == nullptr || event_type != kEventNewBuffer) return fail(kErrNotImplemented, "only NEW_BUFFER on streams");
  std::lock_guard lock(s->mutex);
  if (s->event) return fail(kErrResourceInUse, "already registered");
  s->event = std::make_unique<Event>();
  s->event->stream = s;
  s->killed = false;
  *event = s->event.get();
  return kSuccess;
}

MOCK_EXPORT Status GCUnregisterEvent(Handle source, std::int32_t event_type) {
  auto* s = as<Stream>(source, kMagicStream);
  if (s == nullptr || event_type != kEventNewBuffer) return fail(kErrInvalidHandle, "not registered");
  std::lock_guard lock(s->mutex);
  s->event.reset();
  return kSuccess;
}

MOCK_EXPORT Status EventGetData(Handle event, void* buffer, std::size_t* size, std::uint64_t timeout_ms) {
  auto* e = as<Event>(event, kMagicEvent);
  if (e == nullptr) return fail(kErrInvalidHandle, "not an event");
  if (size == nullptr || *size < sizeof(NewBufferEventData)) return fail(kErrBufferTooSmall, "buffer too small");
  Stream& s = *e->stream;
  std::unique_lock lock(s.mutex);
  const auto ready = [&] { return s.killed || !s.output.empty(); };
  if (timeout_ms == kInfinite)
    s.filled.wait(lock, ready);
  else if (!s.filled.wait_for(lock, std::chrono::milliseconds(timeout_ms), ready))
    return fail(kErrTimeout, "no buffer filled in time");
  if (s.killed) {
    s.killed = false;
    return fail(kErrAbort, "EventKill");
  }
  Buffer* b = s.output.front();
  s.output.pop_front();
  NewBufferEventData data{b, b->user};
  std::memcpy(buffer, &data, sizeof data);
  *size = sizeof data;
  return kSuccess;
}

MOCK_EXPORT Status EventGetDataInfo(Handle, const void*, std::size_t, std::int32_t, InfoType*, void*, std::size_t*) {
  return fail(kErrNotImplemented, "no event data info");
}
MOCK_EXPORT Status EventGetInfo(Handle, std::int32_t, InfoType*, void*, std::size_t*) {
  return fail(kErrNotImplemented, "no event info");
}
MOCK_EXPORT Status EventFlush(Handle event) {
  auto* e = as<Event>(event, kMagicEvent);
  if (e == nullptr) return fail(kErrInvalidHandle, "not an event");
  std::lock_guard lock(e->stream->mutex);
  e->stream->output.clear();
  return kSuccess;
}
MOCK_EXPORT Status EventKill(Handle event) {
  auto* e = as<Event>(event, kMagicEvent);
  if (e == nullptr) return fail(kErrInvalidHandle, "not an event");
  std::lock_guard lock(e->stream->mutex);
  e->stream->killed = true;
  e->stream->filled.notify_all();
  return kSuccess;
}

// ---- System (TL) and interface -----------------------------------------------------------

MOCK_EXPORT Status TLOpen(Handle* system) {
  if (!initialised) return fail(kErrNotInitialized, "GCInitLib first");
  if (the_system->open) return fail(kErrResourceInUse, "already open");
  the_system->open = true;
  *system = the_system;
  return kSuccess;
}
MOCK_EXPORT Status TLClose(Handle system) {
  auto* s = as<System>(system, kMagicSystem);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a system");
  s->open = false;
  return kSuccess;
}
MOCK_EXPORT Status TLGetInfo(Handle system, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size) {
  if (as<System>(system, kMagicSystem) == nullptr) return fail(kErrInvalidHandle, "not a system");
  return GCGetInfo(cmd, type, buffer, size);
}
MOCK_EXPORT Status TLGetNumInterfaces(Handle system, std::uint32_t* count) {
  if (as<System>(system, kMagicSystem) == nullptr) return fail(kErrInvalidHandle, "not a system");
  *count = 1;
  return kSuccess;
}
MOCK_EXPORT Status TLGetInterfaceID(Handle system, std::uint32_t index, char* id, std::size_t* size) {
  if (as<System>(system, kMagicSystem) == nullptr) return fail(kErrInvalidHandle, "not a system");
  if (index != 0) return fail(kErrInvalidIndex, "one interface");
  return put_string(nullptr, id, size, "mock_if0");
}
MOCK_EXPORT Status TLGetInterfaceInfo(Handle, const char*, std::int32_t, InfoType*, void*, std::size_t*) {
  return fail(kErrNotImplemented, "no interface info");
}
MOCK_EXPORT Status TLOpenInterface(Handle system, const char* interface_id, Handle* interface) {
  auto* s = as<System>(system, kMagicSystem);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a system");
  if (interface_id == nullptr || std::string(interface_id) != "mock_if0") return fail(kErrInvalidId, "no such interface");
  s->interface.open = true;
  *interface = &s->interface;
  return kSuccess;
}
MOCK_EXPORT Status TLUpdateInterfaceList(Handle system, Bool8* changed, std::uint64_t) {
  if (as<System>(system, kMagicSystem) == nullptr) return fail(kErrInvalidHandle, "not a system");
  if (changed != nullptr) *changed = 0;
  return kSuccess;
}
MOCK_EXPORT Status IFClose(Handle interface) {
  auto* i = as<Interface>(interface, kMagicInterface);
  if (i == nullptr) return fail(kErrInvalidHandle, "not an interface");
  i->open = false;
  return kSuccess;
}
MOCK_EXPORT Status IFGetInfo(Handle, std::int32_t, InfoType*, void*, std::size_t*) {
  return fail(kErrNotImplemented, "no interface info");
}
MOCK_EXPORT Status IFGetNumDevices(Handle interface, std::uint32_t* count) {
  auto* i = as<Interface>(interface, kMagicInterface);
  if (i == nullptr) return fail(kErrInvalidHandle, "not an interface");
  *count = static_cast<std::uint32_t>(i->devices.size());
  return kSuccess;
}
MOCK_EXPORT Status IFGetDeviceID(Handle interface, std::uint32_t index, char* id, std::size_t* size) {
  auto* i = as<Interface>(interface, kMagicInterface);
  if (i == nullptr) return fail(kErrInvalidHandle, "not an interface");
  if (index >= i->devices.size()) return fail(kErrInvalidIndex, "no such device");
  return put_string(nullptr, id, size, i->devices[index]->id);
}
MOCK_EXPORT Status IFUpdateDeviceList(Handle interface, Bool8* changed, std::uint64_t) {
  if (as<Interface>(interface, kMagicInterface) == nullptr) return fail(kErrInvalidHandle, "not an interface");
  if (changed != nullptr) *changed = 0;
  return kSuccess;
}
namespace {
Device* find_device(Handle interface, const char* device_id) {
  auto* i = as<Interface>(interface, kMagicInterface);
  if (i == nullptr || device_id == nullptr) return nullptr;
  for (auto& d : i->devices)
    if (d->id == device_id) return d.get();
  return nullptr;
}
Status device_info(Device& d, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size) {
  switch (cmd) {
    case kDevInfoId: return put_string(type, buffer, size, d.id);
    case kDevInfoVendor: return put_string(type, buffer, size, "tomorig");
    case kDevInfoModel: return put_string(type, buffer, size, "MockGenTL");
    case kDevInfoDisplayName: return put_string(type, buffer, size, "tomorig MockGenTL " + d.id);
    case kDevInfoSerialNumber: return put_string(type, buffer, size, "MOCK000" + std::to_string(d.index));
    case kDevInfoUserDefinedName: return put_string(type, buffer, size, "");
#ifdef MOCK_GENTL_NO_OPTIONAL
    case kDevInfoTimestampFrequency: return put<std::uint64_t>(type, buffer, size, 1'000'000, kTypeUInt64);
#endif
    default: return fail(kErrNotImplemented, "device info not available");
  }
}
}  // namespace
MOCK_EXPORT Status IFGetDeviceInfo(Handle interface, const char* device_id, std::int32_t cmd, InfoType* type,
                                   void* buffer, std::size_t* size) {
  Device* d = find_device(interface, device_id);
  if (d == nullptr) return fail(kErrInvalidId, "no such device");
  return device_info(*d, cmd, type, buffer, size);
}
MOCK_EXPORT Status IFOpenDevice(Handle interface, const char* device_id, std::int32_t, Handle* device) {
  Device* d = find_device(interface, device_id);
  if (d == nullptr) return fail(kErrInvalidId, "no such device");
  std::lock_guard lock(d->mutex);
  if (d->open) return fail(kErrResourceInUse, "device already open");
  d->open = true;
  *device = d;
  return kSuccess;
}

// ---- Device --------------------------------------------------------------------------------

MOCK_EXPORT Status DevGetPort(Handle device, Handle* port) {
  auto* d = as<Device>(device, kMagicDevice);
  if (d == nullptr) return fail(kErrInvalidHandle, "not a device");
  *port = &d->port;
  return kSuccess;
}
MOCK_EXPORT Status DevGetNumDataStreams(Handle device, std::uint32_t* count) {
  if (as<Device>(device, kMagicDevice) == nullptr) return fail(kErrInvalidHandle, "not a device");
  *count = 1;
  return kSuccess;
}
MOCK_EXPORT Status DevGetDataStreamID(Handle device, std::uint32_t index, char* id, std::size_t* size) {
  if (as<Device>(device, kMagicDevice) == nullptr) return fail(kErrInvalidHandle, "not a device");
  if (index != 0) return fail(kErrInvalidIndex, "one stream");
  return put_string(nullptr, id, size, "stream0");
}
MOCK_EXPORT Status DevOpenDataStream(Handle device, const char* stream_id, Handle* stream) {
  auto* d = as<Device>(device, kMagicDevice);
  if (d == nullptr) return fail(kErrInvalidHandle, "not a device");
  if (stream_id == nullptr || std::string(stream_id) != "stream0") return fail(kErrInvalidId, "no such stream");
  std::lock_guard lock(d->mutex);
  if (d->stream) return fail(kErrResourceInUse, "stream already open");
  d->stream = std::make_unique<Stream>();
  d->stream->device = d;
  d->stop_worker = false;
  d->worker = std::thread(worker_loop, d);
  *stream = d->stream.get();
  return kSuccess;
}
MOCK_EXPORT Status DevGetInfo(Handle device, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size) {
  auto* d = as<Device>(device, kMagicDevice);
  if (d == nullptr) return fail(kErrInvalidHandle, "not a device");
  return device_info(*d, cmd, type, buffer, size);
}
MOCK_EXPORT Status DevClose(Handle device) {
  auto* d = as<Device>(device, kMagicDevice);
  if (d == nullptr) return fail(kErrInvalidHandle, "not a device");
  std::lock_guard lock(d->mutex);
  d->open = false;
  d->acquiring = false;
  return kSuccess;
}

// ---- Data stream ---------------------------------------------------------------------------

MOCK_EXPORT Status DSAnnounceBuffer(Handle stream, void* memory, std::size_t size, void* user, Handle* buffer) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  if (memory == nullptr || size == 0) return fail(kErrInvalidParameter, "no memory");
#ifdef MOCK_GENTL_NO_OPTIONAL
  if (reinterpret_cast<std::uintptr_t>(memory) % 4096 != 0) return fail(kErrInvalidParameter, "buffer not 4096-byte aligned");
#endif
  std::lock_guard lock(s->mutex);
  auto b = std::make_unique<Buffer>();
  b->base = static_cast<std::byte*>(memory);
  b->size = size;
  b->user = user;
  *buffer = b.get();
  s->buffers.push_back(std::move(b));
  return kSuccess;
}
MOCK_EXPORT Status DSAllocAndAnnounceBuffer(Handle, std::size_t, void*, Handle*) {
  return fail(kErrNotImplemented, "announce your own memory");
}
MOCK_EXPORT Status DSFlushQueue(Handle stream, std::int32_t operation) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  std::lock_guard lock(s->mutex);
  if (operation == kQueueAllDiscard) {
    for (auto* b : s->input) b->queued = false;
    s->input.clear();
    s->output.clear();
  } else if (operation == kQueueOutputDiscard) {
    s->output.clear();
  } else if (operation == kQueueAllToInput) {
    for (auto& b : s->buffers) b->queued = true;
    s->output.clear();
    s->input.clear();
    for (auto& b : s->buffers) s->input.push_back(b.get());
  } else if (operation == kQueueInputToOutput) {
    while (!s->input.empty()) s->output.push_back(s->input.front()), s->input.pop_front();
  }
  return kSuccess;
}
MOCK_EXPORT Status DSStartAcquisition(Handle stream, std::int32_t, std::uint64_t) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  std::lock_guard lock(s->mutex);
  s->acquiring = true;
  return kSuccess;
}
MOCK_EXPORT Status DSStopAcquisition(Handle stream, std::int32_t) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  std::lock_guard lock(s->mutex);
  s->acquiring = false;
  return kSuccess;
}
MOCK_EXPORT Status DSGetInfo(Handle stream, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  std::size_t payload = 0;
  {
    std::lock_guard device_lock(s->device->mutex);
    payload = s->device->payload();
  }
  std::lock_guard lock(s->mutex);
  switch (cmd) {
    case kStreamInfoNumDelivered: return put<std::uint64_t>(type, buffer, size, s->delivered, kTypeUInt64);
    case kStreamInfoNumUnderrun: return put<std::uint64_t>(type, buffer, size, s->underruns, kTypeUInt64);
    case kStreamInfoNumAnnounced: return put<std::size_t>(type, buffer, size, s->buffers.size(), kTypeSizeT);
    case kStreamInfoPayloadSize: return put<std::size_t>(type, buffer, size, payload, kTypeSizeT);
    case kStreamInfoDefinesPayloadSize: return put<Bool8>(type, buffer, size, 0, kTypeBool8);
    case kStreamInfoBufAnnounceMin: return put<std::size_t>(type, buffer, size, 2, kTypeSizeT);
#ifdef MOCK_GENTL_NO_OPTIONAL
    case kStreamInfoBufAlignment: return put<std::size_t>(type, buffer, size, 4096, kTypeSizeT);
#endif
    default: return fail(kErrNotImplemented, "stream info not available");
  }
}
MOCK_EXPORT Status DSGetBufferID(Handle stream, std::uint32_t index, Handle* buffer) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  std::lock_guard lock(s->mutex);
  if (index >= s->buffers.size()) return fail(kErrInvalidIndex, "no such buffer");
  *buffer = s->buffers[index].get();
  return kSuccess;
}
MOCK_EXPORT Status DSClose(Handle stream) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  Device* d = s->device;
  {
    std::lock_guard lock(d->mutex);
    d->stop_worker = true;
  }
  d->wake.notify_all();
  if (d->worker.joinable()) d->worker.join();
  std::lock_guard lock(d->mutex);
  d->triggers.clear();
  d->stream.reset();
  return kSuccess;
}
MOCK_EXPORT Status DSRevokeBuffer(Handle stream, Handle buffer, void** memory, void** user) {
  auto* s = as<Stream>(stream, kMagicStream);
  auto* b = as<Buffer>(buffer, kMagicBuffer);
  if (s == nullptr || b == nullptr) return fail(kErrInvalidHandle, "not a stream or buffer");
  std::lock_guard lock(s->mutex);
  if (b->queued) return fail(kErrBusy, "buffer still queued");
  if (memory != nullptr) *memory = b->base;
  if (user != nullptr) *user = b->user;
  std::erase_if(s->output, [&](Buffer* o) { return o == b; });
  b->magic = 0;
  std::erase_if(s->buffers, [&](const std::unique_ptr<Buffer>& o) { return o.get() == b; });
  return kSuccess;
}
#ifndef MOCK_GENTL_OMIT_QUEUE
MOCK_EXPORT Status DSQueueBuffer(Handle stream, Handle buffer) {
  auto* s = as<Stream>(stream, kMagicStream);
  auto* b = as<Buffer>(buffer, kMagicBuffer);
  if (s == nullptr || b == nullptr) return fail(kErrInvalidHandle, "not a stream or buffer");
  std::lock_guard lock(s->mutex);
  if (b->queued) return fail(kErrResourceInUse, "already queued");
  b->queued = true;
  s->input.push_back(b);
  return kSuccess;
}
#endif
MOCK_EXPORT Status DSGetBufferInfo(Handle stream, Handle buffer, std::int32_t cmd, InfoType* type, void* out,
                                   std::size_t* size) {
  auto* s = as<Stream>(stream, kMagicStream);
  auto* b = as<Buffer>(buffer, kMagicBuffer);
  if (s == nullptr || b == nullptr) return fail(kErrInvalidHandle, "not a stream or buffer");
  std::lock_guard lock(s->mutex);
  switch (cmd) {
    case kBufInfoBase: return put<void*>(type, out, size, b->base, kTypePtr);
    case kBufInfoSize: return put<std::size_t>(type, out, size, b->size, kTypeSizeT);
#ifdef MOCK_GENTL_NO_OPTIONAL
    case kBufInfoTimestamp: return put<std::uint64_t>(type, out, size, b->timestamp_ns / 1000, kTypeUInt64);
#else
    case kBufInfoTimestamp: return put<std::uint64_t>(type, out, size, b->timestamp_ns, kTypeUInt64);
    case kBufInfoTimestampNs: return put<std::uint64_t>(type, out, size, b->timestamp_ns, kTypeUInt64);
#endif
    case kBufInfoIsIncomplete: return put<Bool8>(type, out, size, b->incomplete ? 1 : 0, kTypeBool8);
    case kBufInfoSizeFilled: return put<std::size_t>(type, out, size, b->filled, kTypeSizeT);
    case kBufInfoWidth: return put<std::size_t>(type, out, size, b->width, kTypeSizeT);
    case kBufInfoHeight: return put<std::size_t>(type, out, size, b->height, kTypeSizeT);
    case kBufInfoFrameId: return put<std::uint64_t>(type, out, size, b->frame_id, kTypeUInt64);
    case kBufInfoImagePresent: return put<Bool8>(type, out, size, 1, kTypeBool8);
    case kBufInfoImageOffset: return put<std::size_t>(type, out, size, 0, kTypeSizeT);
    case kBufInfoPixelFormat: return put<std::uint64_t>(type, out, size, b->pixel_format, kTypeUInt64);
    case kBufInfoPixelFormatNamespace: return put<std::uint64_t>(type, out, size, kPixelNamespacePfnc32, kTypeUInt64);
    default: return fail(kErrNotImplemented, "buffer info not available");
  }
}

// ---- GenTL 1.3+ (optional) -----------------------------------------------------------------
#ifndef MOCK_GENTL_NO_OPTIONAL
MOCK_EXPORT Status DSGetBufferChunkData(Handle, Handle, void*, std::size_t* count) {
  if (count != nullptr) *count = 0;
  return kSuccess;
}
MOCK_EXPORT Status IFGetParentTL(Handle, Handle* system) {
  *system = the_system;
  return kSuccess;
}
MOCK_EXPORT Status DevGetParentIF(Handle, Handle* interface) {
  *interface = &the_system->interface;
  return kSuccess;
}
MOCK_EXPORT Status DSGetParentDev(Handle stream, Handle* device) {
  auto* s = as<Stream>(stream, kMagicStream);
  if (s == nullptr) return fail(kErrInvalidHandle, "not a stream");
  *device = s->device;
  return kSuccess;
}
#endif

// ---- Test hook -----------------------------------------------------------------------------

// A hardware trigger line pulse on `device_id`'s Line1 (frame grabbers route camera triggers
// from their I/O lines); taken only by a trigger whose TriggerSource is Line1. Returns 0 when
// the device exists.
MOCK_EXPORT int MockGenTLFireLine(const char* device_id) {
  if (!initialised || device_id == nullptr) return -1;
  for (auto& d : the_system->interface.devices) {
    if (d->id != device_id) continue;
    std::lock_guard lock(d->mutex);
    fire(*d, 0);
    return 0;
  }
  return -1;
}

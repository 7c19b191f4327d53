#pragma once
// Names and types of the session file layout, in one place for the writer and the reader.
// docs/file-formats.md documents the same layout for h5py and MATLAB users; change both
// together, and bump kFormatVersion when an old reader could misread a new file.
#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "tomorig/core/pixel_format.h"

namespace tomorig::storage::layout {

inline constexpr std::string_view kFormatName = "tomorig-session";
// Version 2 stores every string (attributes and /config) as a fixed-length string; version 1
// used variable-length strings, which libhdf5 1.10 reads from a global heap without bounds
// checks (a damaged file crashed it). Both are read; only version 2 is written.
inline constexpr int kFormatVersion = 2;
inline constexpr int kOldestFormatVersion = 1;

// Limits a session file must keep, checked by the writer and by the reader before it
// allocates anything a file declares:
//  - cameras per session: a rig has a handful (the wire format could carry 32767), and the
//    /cameras 'order' attribute of 256 ids of kMaxCameraIdBytes stays within the 64 KiB an
//    HDF5 attribute may take in a file of the oldest format;
inline constexpr std::size_t kMaxCameras = 256;
//  - image sides, as the wire format allows (stream/wire_format.h);
inline constexpr std::int64_t kMaxImageSide = std::int64_t{1} << 16;
//  - bytes per frame: a frame is one HDF5 chunk, and HDF5 chunks are smaller than 4 GiB;
inline constexpr std::uint64_t kMaxFrameBytes = (std::uint64_t{1} << 32) - 1;
//  - memory the per-set records held by a reader may take, as a multiple of the file's size
//    (tomorig stores them uncompressed, so a real file holds at least that many bytes; 16x
//    leaves room for files compressed by other tools), with a floor for tiny files.
inline constexpr std::uint64_t kRecordBytesPerFileByte = 16;
inline constexpr std::uint64_t kRecordBytesFloor = std::uint64_t{64} << 20;

// Root attributes.
inline constexpr const char* kAttrFormat = "format";
inline constexpr const char* kAttrFormatVersion = "format_version";
inline constexpr const char* kAttrSoftwareVersion = "software_version";
inline constexpr const char* kAttrCreatedUtc = "created_utc";
inline constexpr const char* kAttrCompression = "compression";
// int32 1 once a live recording finished; 0 while it is written (or if it was interrupted).
// Absent in files written in one go, which are complete by construction.
inline constexpr const char* kAttrRecordingComplete = "recording_complete";

inline constexpr const char* kConfig = "config";  // scalar string dataset: rig TOML

inline constexpr const char* kCameras = "cameras";
inline constexpr const char* kAttrOrder = "order";  // on /cameras and /truth/cameras
inline constexpr const char* kFrames = "frames";
inline constexpr const char* kAttrWidth = "width";
inline constexpr const char* kAttrHeight = "height";
inline constexpr const char* kAttrPixelFormat = "pixel_format";
inline constexpr const char* kAttrPixelPitch = "pixel_pitch_um";
inline constexpr const char* kAttrIndex = "index";

inline constexpr const char* kSets = "sets";
inline constexpr const char* kTriggerIndex = "trigger_index";
inline constexpr const char* kTriggerTimestamp = "trigger_timestamp_ns";
inline constexpr const char* kDt = "dt_ns";
inline constexpr const char* kFrameTimestamp = "frame_timestamp_ns";
inline constexpr const char* kFramePresent = "frame_present";

inline constexpr const char* kTruth = "truth";
inline constexpr const char* kAttrCase = "case";
inline constexpr const char* kAttrFlow = "flow";
inline constexpr const char* kAttrFlowParameters = "flow_parameters";
inline constexpr const char* kAttrSeed = "seed";
inline constexpr const char* kAttrPpp = "ppp";
inline constexpr const char* kAttrModel = "model";
inline constexpr const char* kAttrK = "K";
inline constexpr const char* kAttrR = "R";
inline constexpr const char* kAttrT = "t";
inline constexpr const char* kParticlesA = "particles_a";
inline constexpr const char* kParticlesB = "particles_b";

// Quick-look numbers (quicklook_record.h): float tables with their column names in an
// attribute, and the set each row is of. Live recordings create them empty with the layout
// (SWMR cannot create objects later); other writers on first use.
inline constexpr const char* kQuickLook = "quicklook";
inline constexpr const char* kQuickLookSetIndex = "set_index";
inline constexpr const char* kQuickLookSets = "sets";
inline constexpr const char* kQuickLookCameras = "cameras";
inline constexpr const char* kAttrColumns = "columns";
inline std::string quicklook_path(std::string_view name) { return "/quicklook/" + std::string(name); }

// Sets per chunk of the /sets datasets: small chunks would make the chunk index large for
// long runs, and a few KiB per chunk costs nothing for short ones.
inline constexpr hsize_t kSetsPerChunk = 512;

inline std::string camera_path(std::string_view id) { return "/cameras/" + std::string(id); }
inline std::string frames_path(std::string_view id) { return camera_path(id) + "/frames"; }
inline std::string sets_path(std::string_view name) { return "/sets/" + std::string(name); }
inline std::string truth_set_name(std::uint64_t set_index) { return std::to_string(set_index); }
inline std::string truth_set_path(std::uint64_t set_index) { return "/truth/sets/" + truth_set_name(set_index); }

// Frames are stored little-endian unsigned: 8 bits for Mono8, 16 bits for Mono12 and Mono16.
inline hid_t file_sample_type(PixelFormat format) {
  return format == PixelFormat::Mono8 ? H5T_STD_U8LE : H5T_STD_U16LE;
}
inline hid_t memory_sample_type(SampleType type) {
  return type == SampleType::u8 ? H5T_NATIVE_UINT8 : H5T_NATIVE_UINT16;
}

}  // namespace tomorig::storage::layout

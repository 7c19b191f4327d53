#pragma once
// Cameras behind a frame grabber (CoaXPress, Camera Link), reached through the grabber
// vendor's GenTL producer (a `.cti` shared library): rig-file backend "gentl".
//
//   [[cameras]]
//   id = "cam0"
//   backend = "gentl"
//   device_id = "CXP-0001"                 # GenTL device id, serial or user-defined name
//   producer = "/opt/vendor/grabber.cti"   # else the .cti files GENICAM_GENTL64_PATH names
//
// The producer is loaded with dlopen and shared by every camera it serves; the camera's
// GenICam features go through Aravis's GenApi engine over the producer's register port
// (GCReadPort / GCWritePort), so features, frame modes and the timing plan's settings work as
// for Aravis cameras; frames come from the GenTL data stream (DSAnnounceBuffer, DSQueueBuffer,
// NEW_BUFFER events). See docs/acquisition.md, "Frame grabbers through GenTL".
#include <memory>
#include <string>

#include "tomorig/acquisition/aravis_camera.h"

namespace tomorig::acquisition {

// A camera for a backend = "gentl" configuration; configure() loads the producer and opens
// the device. The options are those of an Aravis camera (GenTL frame ids are 64-bit and may
// be 0, which this sets). Errors: bad_input naming the file (and the function) for a producer
// path that does not exist, a library that is not a GenTL producer or lacks a mandatory
// function; runtime_error for GCInitLib failing or the device not found (listing the devices).
std::unique_ptr<AravisCamera> make_gentl_camera(std::string id, AravisCameraOptions options);

}  // namespace tomorig::acquisition

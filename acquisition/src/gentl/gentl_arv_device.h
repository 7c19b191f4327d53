#pragma once
// An ArvDevice whose registers are a GenTL device's remote port: Aravis's GenApi engine
// (ArvGc, built from the port's GenICam description) then reads and writes every feature
// through GCReadPort / GCWritePort, so an ArvCamera over it takes the rig file's features and
// the timing plan's settings exactly like a GigE Vision or USB3 Vision camera. Streaming does
// not go through Aravis (GenTLFrameStream does it).
#include <arv.h>

#include <memory>
#include <string>

#include "gentl_producer.h"

namespace tomorig::acquisition::gentl_detail {

// A new ArvDevice (caller owns the reference) over `device`'s remote port. Throws
// runtime_error naming `what` when the GenICam description cannot be read or parsed.
ArvDevice* new_arv_device(std::shared_ptr<Device> device, const std::string& what);

}  // namespace tomorig::acquisition::gentl_detail

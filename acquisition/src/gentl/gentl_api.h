#pragma once
// The GenICam GenTL C interface as tomorig uses it, written from the GenTL standard's text
// (EMVA GenTL 1.5/1.6, chapters "Software interface" and "C interface"); the EMVA header is
// not used. Only what a consumer needs is declared: the producer's functions are looked up by
// name with dlsym and called through these pointer types. Values of the enumerations are the
// standard's; names are tomorig's.
//
// A producer is a shared library (`.cti`) exporting C functions with the platform's default
// calling convention (on Linux x86-64 the standard's GC_CALLTYPE is empty). Every function
// returns a status (0: success, negative: an error code listed below).
#include <cstddef>
#include <cstdint>

namespace tomorig::gentl {

using Status = std::int32_t;  // GC_ERROR
using Bool8 = std::uint8_t;   // bool8_t: 0 false, anything else true
using Handle = void*;         // every module handle (TL, IF, DEV, DS, BUFFER, EVENT, PORT)

// Status codes.
enum : Status {
  kSuccess = 0,
  kErrError = -1001,
  kErrNotInitialized = -1002,
  kErrNotImplemented = -1003,
  kErrResourceInUse = -1004,
  kErrAccessDenied = -1005,
  kErrInvalidHandle = -1006,
  kErrInvalidId = -1007,
  kErrNoData = -1008,
  kErrInvalidParameter = -1009,
  kErrIo = -1010,
  kErrTimeout = -1011,
  kErrAbort = -1012,
  kErrInvalidBuffer = -1013,
  kErrNotAvailable = -1014,
  kErrInvalidAddress = -1015,
  kErrBufferTooSmall = -1016,
  kErrInvalidIndex = -1017,
  kErrParsingChunkData = -1018,
  kErrInvalidValue = -1019,
  kErrResourceExhausted = -1020,
  kErrOutOfMemory = -1021,
  kErrBusy = -1022,
};

// INFO_DATATYPE: how an info query's answer is laid out.
enum InfoType : std::int32_t {
  kTypeUnknown = 0,
  kTypeString = 1,
  kTypeStringList = 2,
  kTypeInt16 = 3,
  kTypeUInt16 = 4,
  kTypeInt32 = 5,
  kTypeUInt32 = 6,
  kTypeInt64 = 7,
  kTypeUInt64 = 8,
  kTypeFloat64 = 9,
  kTypePtr = 10,
  kTypeBool8 = 11,
  kTypeSizeT = 12,
  kTypeBuffer = 13,
};

// TL_INFO_CMD (system module), the subset tomorig asks for.
enum : std::int32_t { kTlInfoId = 0, kTlInfoVendor = 1, kTlInfoModel = 2, kTlInfoVersion = 3 };
// DEVICE_INFO_CMD.
enum : std::int32_t {
  kDevInfoId = 0,
  kDevInfoVendor = 1,
  kDevInfoModel = 2,
  kDevInfoDisplayName = 4,
  kDevInfoUserDefinedName = 6,
  kDevInfoSerialNumber = 7,
  kDevInfoTimestampFrequency = 9,
};
// STREAM_INFO_CMD.
enum : std::int32_t {
  kStreamInfoNumDelivered = 1,
  kStreamInfoNumUnderrun = 2,
  kStreamInfoNumAnnounced = 3,
  kStreamInfoPayloadSize = 7,
  kStreamInfoDefinesPayloadSize = 9,
  kStreamInfoBufAnnounceMin = 12,
  kStreamInfoBufAlignment = 13,
};
// BUFFER_INFO_CMD.
enum : std::int32_t {
  kBufInfoBase = 0,
  kBufInfoSize = 1,
  kBufInfoTimestamp = 3,
  kBufInfoNewData = 4,
  kBufInfoIsIncomplete = 7,
  kBufInfoSizeFilled = 9,
  kBufInfoWidth = 10,
  kBufInfoHeight = 11,
  kBufInfoFrameId = 16,
  kBufInfoImagePresent = 17,
  kBufInfoImageOffset = 18,
  kBufInfoPixelFormat = 20,
  kBufInfoPixelFormatNamespace = 21,
  kBufInfoTimestampNs = 28,
};
// PIXELFORMAT_NAMESPACE: PFNC 32-bit codes are the GenICam pixel format values.
enum : std::int32_t { kPixelNamespacePfnc32 = 4 };
// URL_INFO_CMD (GenTL 1.1).
enum : std::int32_t { kUrlInfoUrl = 0 };
// EVENT_TYPE.
enum : std::int32_t { kEventError = 0, kEventNewBuffer = 1 };
// EVENT_INFO_CMD.
enum : std::int32_t { kEventInfoNumInQueue = 2, kEventInfoNumFired = 3 };
// DEVICE_ACCESS_FLAGS.
enum : std::int32_t { kAccessReadOnly = 2, kAccessControl = 3, kAccessExclusive = 4 };
// ACQ_START_FLAGS, ACQ_STOP_FLAGS, ACQ_QUEUE_TYPE.
enum : std::int32_t { kStartDefault = 0 };
enum : std::int32_t { kStopDefault = 0, kStopKill = 1 };
enum : std::int32_t { kQueueInputToOutput = 0, kQueueOutputDiscard = 1, kQueueAllToInput = 2, kQueueAllDiscard = 4 };

// "Acquire until stopped" for DSStartAcquisition, "wait forever" for EventGetData.
constexpr std::uint64_t kInfinite = ~std::uint64_t{0};

// What EventGetData fills for a NEW_BUFFER event.
struct NewBufferEventData {
  Handle buffer;
  void* user_pointer;  // the private pointer given when the buffer was announced
};

// Function pointer types, by the standard's function names.
using GCInitLib_t = Status (*)();
using GCCloseLib_t = Status (*)();
using GCGetInfo_t = Status (*)(std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using GCGetLastError_t = Status (*)(Status* code, char* text, std::size_t* size);
using GCReadPort_t = Status (*)(Handle port, std::uint64_t address, void* buffer, std::size_t* size);
using GCWritePort_t = Status (*)(Handle port, std::uint64_t address, const void* buffer, std::size_t* size);
using GCGetPortURL_t = Status (*)(Handle port, char* url, std::size_t* size);
using GCGetPortInfo_t = Status (*)(Handle port, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using GCRegisterEvent_t = Status (*)(Handle source, std::int32_t event_type, Handle* event);
using GCUnregisterEvent_t = Status (*)(Handle source, std::int32_t event_type);
using GCGetNumPortURLs_t = Status (*)(Handle port, std::uint32_t* count);
using GCGetPortURLInfo_t = Status (*)(Handle port, std::uint32_t index, std::int32_t cmd, InfoType* type, void* buffer,
                                      std::size_t* size);
using GCReadPortStacked_t = Status (*)(Handle port, void* entries, std::size_t* count);
using GCWritePortStacked_t = Status (*)(Handle port, void* entries, std::size_t* count);

using EventGetData_t = Status (*)(Handle event, void* buffer, std::size_t* size, std::uint64_t timeout_ms);
using EventGetDataInfo_t = Status (*)(Handle event, const void* in, std::size_t in_size, std::int32_t cmd,
                                      InfoType* type, void* out, std::size_t* out_size);
using EventGetInfo_t = Status (*)(Handle event, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using EventFlush_t = Status (*)(Handle event);
using EventKill_t = Status (*)(Handle event);

using TLOpen_t = Status (*)(Handle* system);
using TLClose_t = Status (*)(Handle system);
using TLGetInfo_t = Status (*)(Handle system, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using TLGetNumInterfaces_t = Status (*)(Handle system, std::uint32_t* count);
using TLGetInterfaceID_t = Status (*)(Handle system, std::uint32_t index, char* id, std::size_t* size);
using TLGetInterfaceInfo_t = Status (*)(Handle system, const char* interface_id, std::int32_t cmd, InfoType* type,
                                        void* buffer, std::size_t* size);
using TLOpenInterface_t = Status (*)(Handle system, const char* interface_id, Handle* interface);
using TLUpdateInterfaceList_t = Status (*)(Handle system, Bool8* changed, std::uint64_t timeout_ms);

using IFClose_t = Status (*)(Handle interface);
using IFGetInfo_t = Status (*)(Handle interface, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using IFGetNumDevices_t = Status (*)(Handle interface, std::uint32_t* count);
using IFGetDeviceID_t = Status (*)(Handle interface, std::uint32_t index, char* id, std::size_t* size);
using IFUpdateDeviceList_t = Status (*)(Handle interface, Bool8* changed, std::uint64_t timeout_ms);
using IFGetDeviceInfo_t = Status (*)(Handle interface, const char* device_id, std::int32_t cmd, InfoType* type,
                                     void* buffer, std::size_t* size);
using IFOpenDevice_t = Status (*)(Handle interface, const char* device_id, std::int32_t access, Handle* device);

using DevGetPort_t = Status (*)(Handle device, Handle* remote_port);
using DevGetNumDataStreams_t = Status (*)(Handle device, std::uint32_t* count);
using DevGetDataStreamID_t = Status (*)(Handle device, std::uint32_t index, char* id, std::size_t* size);
using DevOpenDataStream_t = Status (*)(Handle device, const char* stream_id, Handle* stream);
using DevGetInfo_t = Status (*)(Handle device, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using DevClose_t = Status (*)(Handle device);

using DSAnnounceBuffer_t = Status (*)(Handle stream, void* memory, std::size_t size, void* user_pointer,
                                      Handle* buffer);
using DSAllocAndAnnounceBuffer_t = Status (*)(Handle stream, std::size_t size, void* user_pointer, Handle* buffer);
using DSFlushQueue_t = Status (*)(Handle stream, std::int32_t operation);
using DSStartAcquisition_t = Status (*)(Handle stream, std::int32_t flags, std::uint64_t frames);
using DSStopAcquisition_t = Status (*)(Handle stream, std::int32_t flags);
using DSGetInfo_t = Status (*)(Handle stream, std::int32_t cmd, InfoType* type, void* buffer, std::size_t* size);
using DSGetBufferID_t = Status (*)(Handle stream, std::uint32_t index, Handle* buffer);
using DSClose_t = Status (*)(Handle stream);
using DSRevokeBuffer_t = Status (*)(Handle stream, Handle buffer, void** memory, void** user_pointer);
using DSQueueBuffer_t = Status (*)(Handle stream, Handle buffer);
using DSGetBufferInfo_t = Status (*)(Handle stream, Handle buffer, std::int32_t cmd, InfoType* type, void* out,
                                     std::size_t* size);

// GenTL 1.3 onward (optional for tomorig: looked up, used when present).
using DSGetBufferChunkData_t = Status (*)(Handle stream, Handle buffer, void* chunks, std::size_t* count);
using IFGetParentTL_t = Status (*)(Handle interface, Handle* system);
using DevGetParentIF_t = Status (*)(Handle device, Handle* interface);
using DSGetParentDev_t = Status (*)(Handle stream, Handle* device);
using DSGetNumBufferParts_t = Status (*)(Handle stream, Handle buffer, std::uint32_t* count);
using DSGetBufferPartInfo_t = Status (*)(Handle stream, Handle buffer, std::uint32_t part, std::int32_t cmd,
                                         InfoType* type, void* out, std::size_t* size);

}  // namespace tomorig::gentl

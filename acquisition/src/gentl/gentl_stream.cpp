#include "gentl_stream.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <new>
#include <thread>

#include "tomorig/core/error.h"

namespace tomorig::acquisition::gentl_detail {
namespace {

// PFNC codes of the monochrome formats tomorig stores.
std::optional<SampleType> sample_type_of_pfnc(std::uint64_t format) {
  switch (format) {
    case 0x01080001: return SampleType::u8;   // Mono8
    case 0x01100003:                          // Mono10
    case 0x01100005:                          // Mono12
    case 0x01100025:                          // Mono14
    case 0x01100007: return SampleType::u16;  // Mono16
    default: return std::nullopt;
  }
}

template <typename T>
bool stream_info(const DataStream& stream, std::int32_t cmd, T& out) {
  gentl::InfoType type = gentl::kTypeUnknown;
  std::size_t size = sizeof out;
  return stream.fn().DSGetInfo(stream.handle(), cmd, &type, &out, &size) == gentl::kSuccess && size == sizeof out;
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

DataStream::DataStream(std::shared_ptr<Device> device, const std::string& what) : device_(std::move(device)) {
  const auto& f = fn();
  std::uint32_t count = 0;
  gentl::Status status = f.DevGetNumDataStreams(device_->handle(), &count);
  if (status != gentl::kSuccess || count == 0)
    throw runtime_error(fmt::format("{}: GenTL device '{}' has no data stream{}", what, device_->id(),
                                    status != gentl::kSuccess ? ": " + device_->producer().describe("DevGetNumDataStreams", status)
                                                              : std::string()));
  const std::string stream_id = info_string([&](gentl::InfoType*, void* buffer, std::size_t* size) {
    return f.DevGetDataStreamID(device_->handle(), 0, static_cast<char*>(buffer), size);
  });
  status = f.DevOpenDataStream(device_->handle(), stream_id.c_str(), &handle_);
  if (status != gentl::kSuccess)
    throw runtime_error(fmt::format("{}: GenTL device '{}': {}", what, device_->id(),
                                    device_->producer().describe("DevOpenDataStream", status)));
}

DataStream::~DataStream() {
  if (handle_ != nullptr) fn().DSClose(handle_);
}

std::size_t DataStream::payload() const {
  std::size_t bytes = 0;
  return stream_info(*this, gentl::kStreamInfoPayloadSize, bytes) ? bytes : 0;
}

bool DataStream::defines_payload() const {
  gentl::Bool8 defines = 0;
  return stream_info(*this, gentl::kStreamInfoDefinesPayloadSize, defines) && defines != 0;
}

std::uint64_t DataStream::underruns() const {
  std::uint64_t count = 0;
  return stream_info(*this, gentl::kStreamInfoNumUnderrun, count) ? count : 0;
}

std::shared_ptr<GenTLFrameStream> GenTLFrameStream::create(std::shared_ptr<DataStream> stream, std::size_t payload,
                                                           int count, const std::string& what) {
  std::shared_ptr<GenTLFrameStream> self(new GenTLFrameStream());
  self->stream_ = std::move(stream);
  self->what_ = what;
  const auto& f = self->stream_->fn();
  const gentl::Handle ds = self->stream_->handle();
  auto fail = [&](const char* function, gentl::Status status) {
    throw runtime_error(fmt::format("{}: GenTL stream: {}", what, self->stream_->device().producer().describe(function, status)));
  };
  // The producer may need more buffers than asked to stream at all.
  std::size_t minimum = 0;
  if (stream_info(*self->stream_, gentl::kStreamInfoBufAnnounceMin, minimum)) count = std::max<int>(count, static_cast<int>(minimum));
  // Grabbers that DMA into the buffers may need them aligned (a page, often).
  std::size_t alignment = alignof(std::max_align_t);
  if (std::size_t wanted = 0; stream_info(*self->stream_, gentl::kStreamInfoBufAlignment, wanted) && wanted > alignment &&
                              (wanted & (wanted - 1)) == 0)
    alignment = wanted;
  // Timestamps in ticks (producers before GenTL 1.5) are converted with the device's frequency.
  {
    gentl::InfoType type = gentl::kTypeUnknown;
    std::size_t size = sizeof self->tick_hz_;
    if (f.DevGetInfo(self->stream_->device().handle(), gentl::kDevInfoTimestampFrequency, &type, &self->tick_hz_,
                     &size) != gentl::kSuccess ||
        size != sizeof self->tick_hz_)
      self->tick_hz_ = 0;
  }
  for (int i = 0; i < count; ++i) {
    // Uninitialised: the producer overwrites the image before a buffer is delivered complete,
    // and incomplete buffers are never delivered.
    self->memory_.emplace_back(static_cast<std::byte*>(::operator new[](payload, std::align_val_t(alignment))),
                               AlignedDelete{alignment});
    gentl::Handle buffer = nullptr;
    const gentl::Status status = f.DSAnnounceBuffer(ds, self->memory_.back().get(), payload,
                                                    reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)), &buffer);
    if (status != gentl::kSuccess) fail("DSAnnounceBuffer", status);
    self->buffers_.push_back(buffer);
  }
  for (auto* buffer : self->buffers_)
    if (const gentl::Status status = f.DSQueueBuffer(ds, buffer); status != gentl::kSuccess) fail("DSQueueBuffer", status);
  if (const gentl::Status status = f.GCRegisterEvent(ds, gentl::kEventNewBuffer, &self->event_); status != gentl::kSuccess) {
    self->event_ = nullptr;
    fail("GCRegisterEvent(NEW_BUFFER)", status);
  }
  if (const gentl::Status status = f.DSStartAcquisition(ds, gentl::kStartDefault, gentl::kInfinite); status != gentl::kSuccess)
    fail("DSStartAcquisition", status);
  self->started_ = true;
  return self;
}

GenTLFrameStream::~GenTLFrameStream() {
  stop();
  // Images of this stream may have outlived it by a restart: its buffers only are revoked.
  for (auto* buffer : buffers_) stream_->fn().DSRevokeBuffer(stream_->handle(), buffer, nullptr, nullptr);
  // memory_ goes after the producer forgot every buffer.
}

// Everything that ties the data stream to this object ends here, not in the destructor: a
// restarted camera opens a new GenTLFrameStream on the same data stream while images of this
// one may still be alive.
void GenTLFrameStream::stop() {
  if (!started_.exchange(false)) return;
  const auto& f = stream_->fn();
  const gentl::Handle ds = stream_->handle();
  f.DSStopAcquisition(ds, gentl::kStopDefault);
  if (event_ != nullptr) f.GCUnregisterEvent(ds, gentl::kEventNewBuffer);
  event_ = nullptr;
  f.DSFlushQueue(ds, gentl::kQueueAllDiscard);
}

template <typename T>
bool GenTLFrameStream::buffer_info(gentl::Handle buffer, std::int32_t cmd, T& out) const {
  gentl::InfoType type = gentl::kTypeUnknown;
  std::size_t size = sizeof out;
  return stream_->fn().DSGetBufferInfo(stream_->handle(), buffer, cmd, &type, &out, &size) == gentl::kSuccess &&
         size == sizeof out;
}

std::optional<detail::StreamBuffer> GenTLFrameStream::pop(std::chrono::microseconds timeout) {
  if (!started_) return std::nullopt;  // stopped: the event is gone (the delivery thread has ended)
  gentl::NewBufferEventData data{};
  std::size_t size = sizeof data;
  const auto timeout_ms = static_cast<std::uint64_t>(std::max<std::int64_t>(1, timeout.count() / 1000));
  const gentl::Status status = stream_->fn().EventGetData(event_, &data, &size, timeout_ms);
  if (status == gentl::kErrTimeout) return std::nullopt;
  if (status != gentl::kSuccess || data.buffer == nullptr) {
    // A producer that fails at once must not make the delivery thread spin.
    ++event_errors_;
    std::this_thread::sleep_for(timeout);
    return std::nullopt;
  }
  detail::StreamBuffer out;
  out.token = data.buffer;
  const gentl::Handle buffer = data.buffer;
  gentl::Bool8 incomplete = 1;
  if (!buffer_info(buffer, gentl::kBufInfoIsIncomplete, incomplete)) incomplete = 1;  // unknown: not trusted
  std::uint64_t frame_id = 0;
  buffer_info(buffer, gentl::kBufInfoFrameId, frame_id);
  out.frame_id = frame_id;
  gentl::Bool8 image_present = 1;
  buffer_info(buffer, gentl::kBufInfoImagePresent, image_present);
  out.complete = incomplete == 0 && image_present != 0;
  if (!out.complete) {
    ++failures_;
    return out;
  }
  ++completed_;
  void* base = nullptr;
  std::size_t filled = 0, offset = 0, width = 0, height = 0;
  std::uint64_t format = 0;
  buffer_info(buffer, gentl::kBufInfoBase, base);
  if (!buffer_info(buffer, gentl::kBufInfoSizeFilled, filled)) buffer_info(buffer, gentl::kBufInfoSize, filled);
  buffer_info(buffer, gentl::kBufInfoImageOffset, offset);
  buffer_info(buffer, gentl::kBufInfoWidth, width);
  buffer_info(buffer, gentl::kBufInfoHeight, height);
  buffer_info(buffer, gentl::kBufInfoPixelFormat, format);
  out.type = sample_type_of_pfnc(format);
  out.width = static_cast<int>(width);
  out.height = static_cast<int>(height);
  if (base != nullptr && filled > offset) {
    out.data = static_cast<const std::byte*>(base) + offset;
    out.size = filled - offset;
  }
  // Nanoseconds (GenTL 1.5); else the producer's ticks at the device's timestamp frequency
  // (taken for nanoseconds when it does not say); else when the event arrived.
  std::uint64_t stamp = 0;
  if (buffer_info(buffer, gentl::kBufInfoTimestampNs, stamp))
    out.timestamp_ns = static_cast<std::int64_t>(stamp);
  else if (buffer_info(buffer, gentl::kBufInfoTimestamp, stamp))
    out.timestamp_ns = tick_hz_ > 0 && tick_hz_ != 1'000'000'000
                           ? static_cast<std::int64_t>(static_cast<long double>(stamp) * 1e9L / tick_hz_)
                           : static_cast<std::int64_t>(stamp);
  else
    out.timestamp_ns = steady_ns();
  return out;
}

void GenTLFrameStream::give_back(void* buffer) {
  // Queued only while the stream runs; after stop the buffer waits for revocation.
  if (started_) stream_->fn().DSQueueBuffer(stream_->handle(), buffer);
}

std::shared_ptr<void> GenTLFrameStream::lease(void* buffer) {
  return std::shared_ptr<void>(buffer, [self = shared_from_this()](void* b) { self->give_back(b); });
}

detail::StreamCounters GenTLFrameStream::counters() const {
  detail::StreamCounters c;
  c.completed = completed_;
  c.failures = failures_;
  c.underruns = stream_->underruns();
  return c;
}

}  // namespace tomorig::acquisition::gentl_detail

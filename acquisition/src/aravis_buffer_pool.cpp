#include "aravis_buffer_pool.h"

namespace tomorig::acquisition::detail {
namespace {

// Sample type of the pixel formats tomorig stores; nullopt for packed or colour formats.
std::optional<SampleType> sample_type_of_arv(ArvPixelFormat format) {
  switch (format) {
    case ARV_PIXEL_FORMAT_MONO_8: return SampleType::u8;
    case ARV_PIXEL_FORMAT_MONO_10:
    case ARV_PIXEL_FORMAT_MONO_12:
    case ARV_PIXEL_FORMAT_MONO_14:
    case ARV_PIXEL_FORMAT_MONO_16: return SampleType::u16;
    default: return std::nullopt;
  }
}

}  // namespace

std::shared_ptr<AravisBufferPool> AravisBufferPool::create(ArvStream* stream, std::size_t payload_bytes, int count) {
  std::shared_ptr<AravisBufferPool> pool(new AravisBufferPool());
  pool->stream_ = ARV_STREAM(g_object_ref(stream));
  pool->memory_.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    // Default-initialised: the camera overwrites every byte before a frame is delivered.
    pool->memory_.push_back(std::make_unique_for_overwrite<std::byte[]>(payload_bytes));
    ArvBuffer* buffer = arv_buffer_new_full(payload_bytes, pool->memory_.back().get(), nullptr, nullptr);
    arv_stream_push_buffer(stream, buffer);  // the stream owns the buffer object from here
  }
  return pool;
}

AravisBufferPool::~AravisBufferPool() {
  // Destroying the stream stops its thread and frees the ArvBuffer objects it holds (every
  // buffer is back in it: leases keep the pool alive). Only then may the memory go.
  if (stream_ != nullptr) g_object_unref(stream_);
  memory_.clear();
}

std::optional<StreamBuffer> AravisBufferPool::pop(std::chrono::microseconds timeout) {
  ArvBuffer* buffer = arv_stream_timeout_pop_buffer(stream_, static_cast<guint64>(timeout.count()));
  if (buffer == nullptr) return std::nullopt;
  StreamBuffer out;
  out.token = buffer;
  out.frame_id = arv_buffer_get_frame_id(buffer);
  out.complete = arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS;
  if (!out.complete) return out;
  out.type = sample_type_of_arv(arv_buffer_get_image_pixel_format(buffer));
  out.width = arv_buffer_get_image_width(buffer);
  out.height = arv_buffer_get_image_height(buffer);
  out.data = arv_buffer_get_image_data(buffer, &out.size);
  out.timestamp_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
  return out;
}

void AravisBufferPool::give_back(void* buffer) { arv_stream_push_buffer(stream_, static_cast<ArvBuffer*>(buffer)); }

std::shared_ptr<void> AravisBufferPool::lease(void* buffer) {
  return std::shared_ptr<void>(buffer, [pool = shared_from_this()](void* b) { pool->give_back(b); });
}

StreamCounters AravisBufferPool::counters() const {
  StreamCounters c;
  guint64 completed = 0, failures = 0, underruns = 0;
  arv_stream_get_statistics(stream_, &completed, &failures, &underruns);
  c.completed = completed;
  c.failures = failures;
  c.underruns = underruns;
  if (ARV_IS_GV_STREAM(stream_)) {
    guint64 resent = 0, missing = 0;
    arv_gv_stream_get_statistics(ARV_GV_STREAM(stream_), &resent, &missing);
    c.resends = resent;
    c.missing_packets = missing;
  }
  return c;
}

}  // namespace tomorig::acquisition::detail

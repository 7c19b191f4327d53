#include "aravis_buffer_pool.h"

namespace tomorig::acquisition::detail {

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

void AravisBufferPool::give_back(ArvBuffer* buffer) { arv_stream_push_buffer(stream_, buffer); }

std::shared_ptr<void> AravisBufferPool::lease(ArvBuffer* buffer) {
  return std::shared_ptr<void>(buffer, [pool = shared_from_this()](void* b) {
    pool->give_back(static_cast<ArvBuffer*>(b));
  });
}

}  // namespace tomorig::acquisition::detail

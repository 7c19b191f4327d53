#pragma once
// The frame buffers of one Aravis stream, over memory this pool owns (arv_buffer_new_full
// with preallocated data: Aravis writes the packets straight into it, nothing is copied).
// A delivered frame leases its ArvBuffer: the lease's deleter pushes the buffer back to the
// stream. Leases share ownership of the pool, so the stream and the memory outlive every
// Image still looking at them, even after the camera stopped.
#include <arv.h>

#include <cstddef>
#include <memory>
#include <vector>

#include "frame_stream.h"

namespace tomorig::acquisition::detail {

class AravisBufferPool final : public FrameStream, public std::enable_shared_from_this<AravisBufferPool> {
 public:
  // Takes a reference on `stream`; allocates `count` buffers of `payload_bytes` and queues
  // them on the stream.
  static std::shared_ptr<AravisBufferPool> create(ArvStream* stream, std::size_t payload_bytes, int count);
  ~AravisBufferPool() override;
  AravisBufferPool(const AravisBufferPool&) = delete;
  AravisBufferPool& operator=(const AravisBufferPool&) = delete;

  ArvStream* stream() const { return stream_; }
  std::optional<StreamBuffer> pop(std::chrono::microseconds timeout) override;
  // Gives `buffer` (an ArvBuffer*) back to the stream.
  void give_back(void* buffer) override;
  // A lease that gives `buffer` back when its last copy dies.
  std::shared_ptr<void> lease(void* buffer) override;
  StreamCounters counters() const override;

 private:
  AravisBufferPool() = default;

  ArvStream* stream_ = nullptr;
  std::vector<std::unique_ptr<std::byte[]>> memory_;
};

}  // namespace tomorig::acquisition::detail

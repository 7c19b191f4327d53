#pragma once
// Where a GenICam camera's frames come from: an Aravis stream (GigE Vision, USB3 Vision) or a
// GenTL data stream (frame grabbers). The camera logic (frame ids, A/B roles, trigger
// matching, the connection watch) is the same for both and lives in AravisCamera; a stream
// only hands over filled buffers and takes them back. A lease keeps the stream (and the
// memory) alive until the last Image looking at the buffer dies.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>

#include "tomorig/core/image.h"

namespace tomorig::acquisition::detail {

struct StreamCounters {
  std::uint64_t completed = 0;  // buffers the stream filled completely
  std::uint64_t failures = 0;   // buffers it gave up on (incomplete, timed out)
  std::uint64_t underruns = 0;  // frames lost because no buffer was free
  std::uint64_t missing_packets = 0;
  std::uint64_t resends = 0;
};

// One buffer handed over by the stream; `token` gives it back.
struct StreamBuffer {
  void* token = nullptr;
  bool complete = false;           // filled entirely; anything else is never delivered
  std::uint64_t frame_id = 0;      // the transport's counter, not yet unwrapped
  std::optional<SampleType> type;  // nullopt: a pixel format tomorig does not store
  int width = 0;
  int height = 0;
  const void* data = nullptr;
  std::size_t size = 0;  // bytes of image data at `data`
  std::int64_t timestamp_ns = 0;
};

class FrameStream {
 public:
  virtual ~FrameStream() = default;
  // The next filled buffer, or nullopt after `timeout`.
  virtual std::optional<StreamBuffer> pop(std::chrono::microseconds timeout) = 0;
  virtual void give_back(void* token) = 0;
  // A lease that gives the buffer back when its last copy dies.
  virtual std::shared_ptr<void> lease(void* token) = 0;
  virtual StreamCounters counters() const = 0;
  // After AcquisitionStop: the stream stops filling buffers (statistics stay readable).
  virtual void stop() {}
};

}  // namespace tomorig::acquisition::detail

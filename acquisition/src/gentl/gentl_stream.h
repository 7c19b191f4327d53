#pragma once
// A GenTL data stream as a FrameStream: buffers tomorig allocates are announced
// (DSAnnounceBuffer) and queued (DSQueueBuffer); filled ones arrive as NEW_BUFFER events
// (EventGetData). A buffer the producer flags incomplete, or whose filled size is short of
// the image, is handed over as not complete, so it is counted and never delivered.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "../frame_stream.h"
#include "gentl_producer.h"

namespace tomorig::acquisition::gentl_detail {

// An opened data stream (DSClose on destruction); keeps its device open.
class DataStream {
 public:
  // Opens the device's first data stream. Throws runtime_error naming `what`.
  DataStream(std::shared_ptr<Device> device, const std::string& what);
  ~DataStream();
  DataStream(const DataStream&) = delete;
  DataStream& operator=(const DataStream&) = delete;

  gentl::Handle handle() const { return handle_; }
  Device& device() const { return *device_; }
  const Functions& fn() const { return device_->producer().fn(); }
  // Payload bytes of one buffer as the stream states it; 0 if it does not say.
  std::size_t payload() const;
  bool defines_payload() const;
  std::uint64_t underruns() const;

 private:
  std::shared_ptr<Device> device_;
  gentl::Handle handle_ = nullptr;
};

class GenTLFrameStream final : public detail::FrameStream, public std::enable_shared_from_this<GenTLFrameStream> {
 public:
  // Announces and queues `count` buffers of `payload` bytes, registers for NEW_BUFFER and
  // starts the stream (DSStartAcquisition). Throws runtime_error naming `what`.
  static std::shared_ptr<GenTLFrameStream> create(std::shared_ptr<DataStream> stream, std::size_t payload, int count,
                                                  const std::string& what);
  ~GenTLFrameStream() override;

  std::optional<detail::StreamBuffer> pop(std::chrono::microseconds timeout) override;
  void give_back(void* buffer) override;
  std::shared_ptr<void> lease(void* buffer) override;
  detail::StreamCounters counters() const override;
  void stop() override;

 private:
  GenTLFrameStream() = default;
  template <typename T>
  bool buffer_info(gentl::Handle buffer, std::int32_t cmd, T& out) const;

  std::shared_ptr<DataStream> stream_;
  std::string what_;
  struct AlignedDelete {
    std::size_t alignment;
    void operator()(std::byte* memory) const { ::operator delete[](memory, std::align_val_t(alignment)); }
  };
  std::vector<std::unique_ptr<std::byte[], AlignedDelete>> memory_;
  std::uint64_t tick_hz_ = 0;  // the device's timestamp frequency; 0: unknown
  std::vector<gentl::Handle> buffers_;
  gentl::Handle event_ = nullptr;  // NEW_BUFFER, registered from create() to stop()
  std::atomic<bool> started_{false};
  std::atomic<std::uint64_t> completed_{0};
  std::atomic<std::uint64_t> failures_{0};
  std::atomic<std::uint64_t> event_errors_{0};
};

}  // namespace tomorig::acquisition::gentl_detail

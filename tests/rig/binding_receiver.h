#pragma once
// A stream receiver that binds, for the rig suite's senders (SessionReplay, StreamAcquisition):
// it takes every message until the session end (or a 10 s silence) on its own thread, so the
// test checks what actually went over the wire.
#include <chrono>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include <zmq.hpp>

#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::testing {

struct Received {
  std::vector<stream::StreamMessage> messages;
  std::string error;
};

// Takes messages until the session end (or a 10 s silence) on a receiver that binds.
class BindingReceiver {
 public:
  BindingReceiver() : context_(1) {
    stream::SocketOptions socket;
    socket.endpoint = {"tcp://127.0.0.1:*", true, false};
    socket.timeout = std::chrono::milliseconds(10000);
    receiver_ = std::make_unique<stream::FrameReceiver>(context_, socket);
    thread_ = std::thread([this] {
      try {
        while (auto message = receiver_->receive_message()) {
          received_.messages.push_back(std::move(*message));
          if (std::holds_alternative<stream::SessionEnd>(received_.messages.back())) break;
        }
      } catch (const std::exception& e) {
        received_.error = e.what();
      }
    });
  }
  ~BindingReceiver() {
    if (thread_.joinable()) thread_.join();
  }
  std::string endpoint() const { return receiver_->endpoint(); }
  const Received& wait() {
    thread_.join();
    return received_;
  }

 private:
  zmq::context_t context_;
  std::unique_ptr<stream::FrameReceiver> receiver_;
  std::thread thread_;
  Received received_;
};

template <typename T>
std::vector<const T*> all_of(const std::vector<stream::StreamMessage>& messages) {
  std::vector<const T*> out;
  for (const auto& m : messages)
    if (const T* t = std::get_if<T>(&m)) out.push_back(t);
  return out;
}

}  // namespace tomorig::testing

#pragma once
// Sending one message on the lossless stream while the receiver is absent, starting or slow:
// `tomorig acquire` and `tomorig replay` both push to a `tomorig record` that may come later
// or fall behind, and both must stop cleanly on Ctrl-C.
#include "tomorig/core/frame_set.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::rig {

class StopSignalGuard;

enum class SendOutcome { sent, stopped };

// Retries the send until it succeeds or `limit_s` seconds have passed (then throws
// runtime_error naming the message, the endpoint and what to check). A signal interrupts
// ZeroMQ's wait (EINTR); then `stop`, when given, decides: a requested stop returns `stopped`
// with the message not sent.
SendOutcome send_with_retry(stream::FrameSender& sender, const FrameSet& set, double limit_s,
                            const StopSignalGuard* stop);
SendOutcome send_with_retry(stream::FrameSender& sender, const stream::SessionStart& start, double limit_s,
                            const StopSignalGuard* stop);
SendOutcome send_with_retry(stream::FrameSender& sender, const stream::SetTruth& truth, double limit_s,
                            const StopSignalGuard* stop);
SendOutcome send_with_retry(stream::FrameSender& sender, const stream::SessionEnd& end, double limit_s,
                            const StopSignalGuard* stop);

}  // namespace tomorig::rig

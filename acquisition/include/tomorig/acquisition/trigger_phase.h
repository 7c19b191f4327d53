#pragma once
// Where a two-trigger camera's software triggers should go relative to its readout grid (see
// AravisCameraOptions::readout_ns). A camera that takes a trigger only at the end of its
// readout answers each trigger at the next grid line, so its answer latency is the time from
// the trigger to that line. A trigger that lands just before a line is answered at once; with
// the smallest extra host delay it is answered a whole readout later, and its pair is lost.
//
// The judgement goes by the smallest latency seen, not the median: frames A and B of an event
// can sit on opposite sides of a line (A just before it, answered at once; B a few tenths of a
// millisecond after its line, answered a readout later, B - A a readout too long in every set).
// Then half the latencies are near zero and half near a whole readout, and the median says all
// is well. The smallest latency is the trigger nearest before a line: delaying every trigger by
// it plus an eighth of the readout puts that one, and the ones just after their line, an eighth
// of a readout past the line, with most of a readout to spare for host delays.
#include <cstdint>
#include <deque>

namespace tomorig::acquisition {

// The delay to add to every later trigger of the camera, from its recent answer latencies
// (trigger sent -> frame arrived, ns) and its readout time: 0 when even the quickest answer
// took half a readout or more (every trigger is already well past a line), or when there is
// no readout or no latency to judge by.
std::int64_t trigger_phase_delay_ns(const std::deque<std::int64_t>& answer_latencies_ns, std::int64_t readout_ns);

}  // namespace tomorig::acquisition

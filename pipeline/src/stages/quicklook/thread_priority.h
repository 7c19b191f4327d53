#pragma once
// The quick-look's threads yield the CPU to the recorder: on a 2-core machine the statistics of
// 4 x 2048^2 double frames at 10 Hz and a preview volume running flat out would otherwise take
// the cores the recorder needs to write 640 MiB/s, and the recorder would fall behind the
// cameras. Linux gives each thread its own nice value; raising it needs no privilege.
#include <string>

namespace tomorig::pipeline::quicklook_stage {

// Sets the calling thread's nice value to `nice` (0 to 19; higher yields more) if it is lower.
// Returns an empty string on success, else what failed (the thread then runs on unchanged).
std::string lower_this_thread_priority(int nice);

}  // namespace tomorig::pipeline::quicklook_stage

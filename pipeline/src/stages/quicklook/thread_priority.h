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

// Puts the calling thread (and the threads it starts later, e.g. its OpenMP team) into Linux's
// SCHED_IDLE class: it runs only on a core nothing else wants. For the preview volume: measured
// at 4 x 2048^2 and 10 Hz on 2 cores, nice 10 still let it take most of a core from the
// statistics (nice 5), which then skipped 3-6 sets of 50; the statistics of every set come first.
// Returns an empty string on success, else what failed (the thread then runs on unchanged).
std::string run_this_thread_only_when_idle();

}  // namespace tomorig::pipeline::quicklook_stage

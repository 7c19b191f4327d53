#pragma once
// Receive buffers that are reused instead of faulted in afresh for every frame.
//
// ZeroMQ allocates every received part with malloc; the part is freed when the last Image
// viewing it goes. With glibc's defaults a camera-sized part (8 MiB for 2048 x 2048 Mono16)
// lands in fresh memory most of the time (its own mmap, or a per-thread arena that hands
// memory back), so while copying the socket data into it the kernel first faults in and zeroes
// the pages, and unmaps them again on free. That was the lossless TCP path's largest avoidable
// cost: `tomorig bench stream` on the (loaded) build machine took 0.93-1.2 CPU-seconds per GB
// and ~50 000 page faults per GB without this, 0.38-0.39 CPU-seconds and < 10 faults with it.
//
// keep_receive_buffers() makes glibc serve such parts from one heap and keep freed memory for
// the next message (no mmap per part, no trimming), so after the first few sets the parts
// reuse pages already mapped. The setting is process-wide: call it once, before the process
// starts any thread (glibc fixes its arena limit when a second thread first allocates), in a
// program whose main job is receiving frames (`tomorig record`, `tomorig bench stream`). The memory kept is what was in flight at the peak (a few sets).
// Parts over 32 MiB (glibc's largest heap-served size) are still mapped per part.
namespace tomorig::stream {

// True if the C library took the settings (always, with glibc); false elsewhere (no effect).
bool keep_receive_buffers();

}  // namespace tomorig::stream

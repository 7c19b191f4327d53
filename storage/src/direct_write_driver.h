#pragma once
// An HDF5 file driver that writes large, page-aligned blocks (whole frame chunks) with O_DIRECT
// and everything else like HDF5's default "sec2" driver.
//
// Why: through the page cache the kernel copies every frame once more and allocates a page for
// each 4 KiB of it. At 4 x 2048^2 Mono16 double frames and 10 Hz (671 MB/s) that costs most of
// one of the two cores of the machines tomorig records on, and the quick-look running beside
// the recorder then slows the recorder below the trigger rate. Written with O_DIRECT, the
// device reads the frame from the camera buffer itself: the same set costs a few ms of CPU.
//
// The file is an ordinary HDF5 file (nothing driver-specific is stored in it); any reader opens
// it with the default driver, during the recording (SWMR) and after. Debian's HDF5 1.10 is built
// without its own direct driver, hence this one.
//
// What goes direct: a write of at least kDirectThreshold bytes at an address that is a multiple
// of kDirectAlignment; its whole pages go through the O_DIRECT descriptor (split in pieces
// written in parallel: the virtual disk reaches its bandwidth only with several requests in
// flight), the part of a last page through the ordinary one. File space for objects that large
// is aligned to pages by set_direct_write_driver(). Linux keeps the two descriptors coherent
// (a direct write first writes back and drops cached pages of its range). When the file system
// refuses O_DIRECT (tmpfs, some network file systems), every write goes the ordinary way.
#include <hdf5.h>

#include <cstddef>

namespace tomorig::storage {

inline constexpr std::size_t kDirectAlignment = 4096;
inline constexpr std::size_t kDirectThreshold = 256 * 1024;

// Makes `fapl` use the direct-write driver and aligns file space for objects of at least
// kDirectThreshold bytes to kDirectAlignment. Throws h5::Failure if HDF5 refuses.
void set_direct_write_driver(hid_t fapl);

// Bytes written through the O_DIRECT descriptor by this process so far (for tests and the
// benchmark's report).
std::size_t direct_bytes_written();

}  // namespace tomorig::storage

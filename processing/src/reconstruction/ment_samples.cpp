#include "ment_samples.h"

#include <atomic>
#include <cmath>
#include <string>

#include <fmt/core.h>

#include "support_scan.h"
#include "tomorig/core/error.h"

namespace tomorig::recon::detail {

CellCode::CellCode(std::size_t largest_plane) {
  int offset_bits = 1;
  while ((std::size_t{1} << offset_bits) < largest_plane) ++offset_bits;
  bits_ = std::min(8, (32 - offset_bits) / 2);
  if (bits_ < 4)
    throw bad_input(fmt::format("reconstruction: MENT packs image positions in 32 bits and supports cameras of up to "
                                "16 Mpixel; this one has {} pixels (with border)",
                                largest_plane));
  mask_ = (1u << bits_) - 1u;
  steps_ = static_cast<float>(1u << bits_);
  step_ = 1.0f / steps_;
  half_step_ = 0.5f * step_;
}

double ment_bytes_per_sample(std::size_t cameras) { return 4.0 * static_cast<double>(cameras); }

MentSamples build_ment_samples(const PreparedInput& in, const GridProjector& projector,
                               const std::vector<MentPlane>& measured, const CellCode& codec, double threshold,
                               double budget_bytes) {
  const VoxelGrid& g = in.grid;
  const std::size_t cams = in.camera_count();
  const std::size_t nx = static_cast<std::size_t>(g.nx);
  const double per_sample = ment_bytes_per_sample(cams);
  // The MLOS support test (support_scan.h); its thresholded images hold the same pixels as
  // `measured`.
  const SupportScanner scanner(in, projector, threshold);
  MentSamples out;
  // One slab per block of kSlabSlices z-slices, samples in (j, k, i) order: a camera update then
  // reads and splats the same few image rows for a while instead of sweeping the whole images
  // once per slice (support_scan.h).
  const int blocks = (g.nz + kSlabSlices - 1) / kSlabSlices;
  out.slabs.resize(static_cast<std::size_t>(blocks));
  std::atomic<double> bytes{0.0};
  std::atomic<bool> over_budget{false};

#pragma omp parallel num_threads(in.threads)
  {
    // The survivors of a row and the slab's samples as they are found. Reused from slab to
    // slab: nothing is allocated per row.
    SupportScanner::Row row = scanner.make_row();
    std::vector<std::uint32_t> codes_found, voxels, codes(cams);
#pragma omp for schedule(dynamic, 1)
    for (int b = 0; b < blocks; ++b) {
      if (over_budget.load(std::memory_order_relaxed)) continue;
      codes_found.clear();
      voxels.clear();
      const int k0 = b * kSlabSlices, k1 = std::min(g.nz, k0 + kSlabSlices);
      for (int j = 0; j < g.ny; ++j)
        for (int k = k0; k < k1; ++k) {
          const int count = scanner.scan(j, k, row);
          const std::uint32_t base = static_cast<std::uint32_t>(g.linear(0, j, k));
          // The survivors: their packed positions, and the exact test on the quantised position
          // (a read at the centre of the quantisation step can differ from the exact one).
          for (int n = 0; n < count; ++n) {
            const std::size_t i = static_cast<std::size_t>(row.alive[static_cast<std::size_t>(n)]);
            bool active = true;
            for (std::size_t c = 0; c < cams && active; ++c)
              active = codec.encode(measured[c], row.u[c * nx + i], row.v[c * nx + i], codes[c]) &&
                       codec.read(measured[c], codes[c]) > 0.0f;
            if (!active) continue;
            codes_found.insert(codes_found.end(), codes.begin(), codes.end());
            voxels.push_back(base + static_cast<std::uint32_t>(i));
          }
        }
      // Exact-size copies: the slab keeps no spare capacity.
      MentSlab& slab = out.slabs[static_cast<std::size_t>(b)];
      slab.centres = static_cast<std::uint32_t>(voxels.size());
      slab.voxel.assign(voxels.begin(), voxels.end());
      slab.code.assign(codes_found.begin(), codes_found.end());
      const double added = (per_sample + kMentBytesPerCentre) * static_cast<double>(voxels.size());
      if (bytes.fetch_add(added) + added > budget_bytes) over_budget.store(true);
    }
  }
  if (over_budget.load())
    throw bad_input(fmt::format("reconstruction: MENT's sample list of the support outgrew the memory available "
                                "({:.0f} MB allowed for it, more than {:.0f} MB needed): raise mlos_threshold, use a "
                                "smaller grid or raise memory_limit_mb",
                                budget_bytes / (1024.0 * 1024.0), bytes.load() / (1024.0 * 1024.0)));
  for (const MentSlab& slab : out.slabs) {
    out.samples += slab.code.size() / cams;
    out.centres += slab.centres;
  }
  return out;
}

}  // namespace tomorig::recon::detail

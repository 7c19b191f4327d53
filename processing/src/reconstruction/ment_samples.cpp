#include "ment_samples.h"

#include <atomic>
#include <cmath>
#include <string>

#include <fmt/core.h>

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

namespace {

// Per camera, one byte per 2 x 2 cell of the padded plane: 1 if any of its four pixels is
// non-empty, i.e. if a bilinear read there can be > 0. A cheap first test, one load per sample.
std::vector<std::uint8_t> lit_cells(const MentPlane& plane) {
  std::vector<std::uint8_t> lit(plane.data.size(), 0);
  const std::size_t stride = static_cast<std::size_t>(plane.stride);
  for (std::size_t n = 0; n + stride + 1 < plane.data.size(); ++n) {
    const float* p = plane.data.data() + n;
    lit[n] = p[0] > 0.0f || p[1] > 0.0f || p[stride] > 0.0f || p[stride + 1] > 0.0f;
  }
  return lit;
}

// The cell of (u, v) in the padded plane, or -1 outside the image span.
inline std::ptrdiff_t cell_of(const MentPlane& plane, float u, float v) {
  if (!(u >= -0.5f && u <= plane.width - 0.5f && v >= -0.5f && v <= plane.height - 0.5f)) return -1;
  return static_cast<std::ptrdiff_t>(static_cast<int>(v + 1.0f)) * plane.stride + static_cast<int>(u + 1.0f);
}

}  // namespace

MentSamples build_ment_samples(const PreparedInput& in, const GridProjector& projector,
                               const std::vector<MentPlane>& measured, const std::vector<std::size_t>& order,
                               const CellCode& codec, int substeps, double budget_bytes) {
  const VoxelGrid& g = in.grid;
  const std::size_t cams = in.camera_count();
  const std::size_t nx = static_cast<std::size_t>(g.nx);
  const double per_sample = ment_bytes_per_sample(cams);
  std::vector<std::vector<std::uint8_t>> lit;
  for (const MentPlane& plane : measured) lit.push_back(lit_cells(plane));
  MentSamples out;
  out.substeps = substeps;
  out.slabs.resize(static_cast<std::size_t>(g.nz));
  std::atomic<double> bytes{0.0};
  std::atomic<bool> over_budget{false};

#pragma omp parallel num_threads(in.threads)
  {
    // Row positions of every camera at depth k and k + 1, and at the depth of the current
    // sample; the surviving voxels of a row; the slice's samples as they are found. Reused from
    // slice to slice: nothing is allocated per row.
    std::vector<float> u0(cams * nx), v0(cams * nx), u1(cams * nx), v1(cams * nx), us(cams * nx), vs(cams * nx);
    std::vector<std::uint32_t> alive(nx);
    std::vector<std::uint32_t> centre_codes, between_codes, voxels, codes(cams);
#pragma omp for schedule(dynamic, 1)
    for (int k = 0; k < g.nz; ++k) {
      if (over_budget.load(std::memory_order_relaxed)) continue;
      const bool next = k + 1 < g.nz;
      const int steps = next ? substeps : 1;
      centre_codes.clear();
      between_codes.clear();
      voxels.clear();
      for (int j = 0; j < g.ny; ++j) {
        auto load = [&](std::size_t c) {
          projector.row(c, j, k, u0.data() + c * nx, v0.data() + c * nx);
          if (next) projector.row(c, j, k + 1, u1.data() + c * nx, v1.data() + c * nx);
        };
        // The depth k + t row of camera c, in us/vs (t = 0: the voxel centres themselves).
        auto at_depth = [&](std::size_t c, float t) {
          const std::size_t b = c * nx;
          for (std::size_t i = 0; i < nx; ++i) {
            us[b + i] = u0[b + i] + t * (u1[b + i] - u0[b + i]);
            vs[b + i] = v0[b + i] + t * (v1[b + i] - v0[b + i]);
          }
        };
        // The most selective camera's rows first; the others only once a sample survives it.
        load(order[0]);
        bool others_loaded = false;
        for (int s = 0; s < steps; ++s) {
          const float t = static_cast<float>(s) / static_cast<float>(substeps);
          const bool centre = s == 0;
          auto row_u = [&](std::size_t c) { return (centre ? u0.data() : us.data()) + c * nx; };
          auto row_v = [&](std::size_t c) { return (centre ? v0.data() : vs.data()) + c * nx; };
          // Camera by camera, keep the voxels whose cell can read > 0.
          std::size_t count = 0;
          {
            const std::size_t c = order[0];
            if (!centre) at_depth(c, t);
            const float* u = row_u(c);
            const float* v = row_v(c);
            const std::uint8_t* mask = lit[c].data();
            for (std::size_t i = 0; i < nx; ++i) {
              const std::ptrdiff_t cell = cell_of(measured[c], u[i], v[i]);
              alive[count] = static_cast<std::uint32_t>(i);
              count += cell >= 0 && mask[cell];
            }
          }
          if (count == 0) continue;
          if (!others_loaded) {
            for (std::size_t r = 1; r < cams; ++r) load(order[r]);
            others_loaded = true;
          }
          for (std::size_t o = 1; o < cams && count > 0; ++o) {
            const std::size_t c = order[o];
            if (!centre) at_depth(c, t);
            const float* u = row_u(c);
            const float* v = row_v(c);
            const std::uint8_t* mask = lit[c].data();
            std::size_t kept = 0;
            for (std::size_t n = 0; n < count; ++n) {
              const std::uint32_t i = alive[n];
              const std::ptrdiff_t cell = cell_of(measured[c], u[i], v[i]);
              alive[kept] = i;
              kept += cell >= 0 && mask[cell];
            }
            count = kept;
          }
          // The survivors: their packed positions, and the exact test (a lit cell can still
          // read 0 where the only lit pixel has weight 0).
          for (std::size_t n = 0; n < count; ++n) {
            const std::uint32_t i = alive[n];
            bool active = true;
            for (std::size_t c = 0; c < cams && active; ++c)
              active = codec.encode(measured[c], row_u(c)[i], row_v(c)[i], codes[c]) &&
                       codec.read(measured[c], codes[c]) > 0.0f;
            if (!active) continue;
            if (centre) {
              centre_codes.insert(centre_codes.end(), codes.begin(), codes.end());
              voxels.push_back(static_cast<std::uint32_t>(g.linear(static_cast<int>(i), j, k)));
            } else {
              between_codes.insert(between_codes.end(), codes.begin(), codes.end());
            }
          }
        }
      }
      // Exact-size copies: the slab keeps no spare capacity.
      MentSlab& slab = out.slabs[static_cast<std::size_t>(k)];
      slab.centres = static_cast<std::uint32_t>(voxels.size());
      slab.voxel.assign(voxels.begin(), voxels.end());
      slab.code.reserve(centre_codes.size() + between_codes.size());
      slab.code.assign(centre_codes.begin(), centre_codes.end());
      slab.code.insert(slab.code.end(), between_codes.begin(), between_codes.end());
      const double added = per_sample * static_cast<double>(slab.code.size() / cams) +
                           kMentBytesPerCentre * static_cast<double>(voxels.size());
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

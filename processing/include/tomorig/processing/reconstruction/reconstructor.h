#pragma once
// Tomographic reconstruction: N camera images + their camera models + a voxel grid -> a sparse
// volume of voxel intensities (thesis Ch. 3). One interface, several algorithms:
//   "mlos"  multiplicative line of sight, a single pass: preview and initialiser (Sect. 3.1.3)
//   "mart"  classical MART, ray by ray, camera by camera (Eq. 3.6): the slow reference
//   "smart" simultaneous MART with MLOS initialisation and relaxation mu (Eq. 3.5)
//   "fmart" fast MART: sparse MLOS support, precomputed image positions, LUT weights,
//           per-camera projection then multiplicative update (Eq. 3.9)
//   "ment"  maximum entropy technique: pseudo-images, volume as their product, streamed by z-slice (Sect. 3.1.1)
//
//   recon::ReconstructionOptions opt;  opt.algorithm = "fmart";
//   auto r = recon::make_reconstructor(opt);   // throws bad_input for a bad option
//   recon::ReconstructionReport report;
//   SparseVolume v = r->reconstruct(input, report);   // v.to_dense() for a dense export
#include <cstddef>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/core/volume.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/reconstruction/psf_model.h"

namespace tomorig::recon {

// A sensor size in pixels, as the calibration knows it.
struct SensorSize {
  int width = 0, height = 0;
};

// What to reconstruct. The cameras are borrowed and must outlive the call.
struct ReconstructionInput {
  std::vector<Image> images;  // one per camera: u8, u16 or f32, background already removed
  std::vector<const calibration::CameraModel*> cameras;  // same order as images
  VoxelGrid grid;
  // One PSF per camera: the Gaussian weighting function w_ij (Eq. 3.8), or empty: then every
  // camera uses PsfModel::constant(0.5). A voxel blob of width sigma_b imaged through weights of
  // sigma_w gives particle images of sqrt(sigma_w^2 + sigma_b^2), so weights as wide as the
  // particle images (0.75 px in tpiv-thesis) make blobs too sharp; sigma_w = 0.5 reproduces
  // them from blobs of ~0.6 voxel and gives the best unsmoothed volumes. Volumes that will be
  // smoothed (the thesis's FMART evaluation) do better with sigma_w = 0.6: fewer ghosts, and
  // the smoothing restores the blob width (docs/reconstruction.md has the measurements).
  std::vector<PsfModel> psf;
  // The sensor sizes the calibration was made for, one per camera, or empty: not checked.
  // (CameraModel does not carry a size; the calibration file does.)
  std::vector<SensorSize> sensor_sizes;
};

struct ReconstructionOptions {
  // "mlos", "ment", "mart", "smart" or "fmart".
  std::string algorithm = "fmart";
  // Iterations of MART/SMART/FMART (MLOS ignores it). FMART needs 4-8 (thesis Fig. 3.5).
  int max_iterations = 8;
  // mu of Eq. 3.5/3.6/3.9, in (0, 2]. SMART converges faster at 1.5-2 (Atkinson and Soria).
  double relaxation = 1.0;
  // Stop when the mean |1 - P_j| over active voxels and cameras (Eq. 3.9) falls below this;
  // 0 runs max_iterations. The thesis stops at 5-10 %.
  double stop_mean_update = 0.0;
  // A pixel below this fraction of its image's maximum counts as empty for MLOS; a voxel is
  // active only if it is non-empty in every camera. Raise it to drop faint ghosts early.
  double mlos_threshold = 0.05;
  // SMART/FMART start from the MLOS intensities (Atkinson and Soria); false starts every active
  // voxel at 1, as the thesis's FMART did.
  bool mlos_initial_intensity = true;
  // Sub-pixel steps of the weight lookup table per pixel (>= 50; the thesis used 100).
  int lut_steps = 64;
  // Edge of the square pixel patch each voxel spreads over; 0: ceil(4 sigma_max) (Sect. 3.1.3),
  // rounded up to an odd number >= 3 so that the patch is centred on the voxel's image.
  int patch_size = 0;
  // SMART/FMART: after each iteration, voxels whose intensity fell below this fraction of the
  // largest intensity are set to 0 and dropped from the voxel list, so later iterations only
  // visit the live ones (ghosts decay by orders of magnitude within 1-2 iterations). 0 keeps
  // every MLOS voxel to the end.
  double prune_fraction = 1e-3;
  // OpenMP threads; 0: the OpenMP default. Results do not depend on it beyond rounding order.
  int threads = 0;
  // Memory the reconstruction may use, MB; 0: 80 % of MemAvailable from /proc/meminfo. The estimate is
  // checked before any large allocation and the call refuses rather than risk the OOM killer.
  double memory_limit_mb = 0.0;

  // Throws tomorig::Error (bad_input) naming the field, its value and the allowed range.
  void validate() const;
};

struct IterationStats {
  int iteration = 0;         // 1-based
  double residual = 0.0;     // sum |I - I~| / sum I over all cameras' pixels (projections of this iteration)
  double mean_update = 0.0;  // mean |1 - P_j| over active voxels and cameras
  double seconds = 0.0;      // wall time of this iteration
  double elapsed_seconds = 0.0;  // since the start of reconstruct(), observer time excluded
  std::size_t live_voxels = 0;   // voxels still in the list after this iteration (pruning)
};

struct ReconstructionReport {
  std::string algorithm;
  int iterations = 0;
  std::vector<IterationStats> history;
  std::size_t active_voxels = 0;     // voxels carried by the sparse support (after MLOS)
  std::size_t nonzero_voxels = 0;    // voxels > 0 in the result
  double setup_seconds = 0.0;        // input checks, MLOS and the projection set-up
  double seconds = 0.0;              // whole call, without the time spent in the iteration observer
  double observer_seconds = 0.0;     // time spent in the iteration observer (not in `seconds`)
  double peak_rss_mb = 0.0;          // VmHWM of the process at the end of the call
  double estimated_memory_mb = 0.0;  // the estimate checked against the limit
  int threads = 0;                   // threads used

  std::string brief() const;  // one line for logs
};

// What an iteration observer sees (e.g. a benchmark recording Q per iteration). `iteration` 0
// is the initial volume (MLOS) before the first iteration; `stats` is null then. `volume()`
// builds the current volume on request only. The time spent in the observer is excluded from
// every time in the report.
struct IterationView {
  int iteration = 0;
  const IterationStats* stats = nullptr;
  double elapsed_seconds = 0.0;  // since the start of reconstruct(), observer time excluded
  std::function<SparseVolume()> volume;
};
using IterationObserver = std::function<void(const IterationView&)>;

// An algorithm implements run() only; reconstruct() owns what every algorithm shares: the
// report's reset and common fields, the timing, and keeping the observer's time out of it.
class Reconstructor {
 public:
  virtual ~Reconstructor() = default;
  // Called after the set-up (iteration 0) and after every iteration by SMART and FMART; the
  // other algorithms ignore it.
  void set_iteration_observer(IterationObserver observer) { observer_ = std::move(observer); }
  virtual std::string name() const = 0;
  // Throws tomorig::Error: bad_input for inconsistent, empty or non-finite input or a volume
  // too large for memory; the report is filled on success.
  SparseVolume reconstruct(const ReconstructionInput& input, ReconstructionReport& report);

 protected:
  // The algorithm: fills the report's algorithm-specific fields (history, active voxels,
  // set-up time, threads); the report arrives reset, with `algorithm` set.
  virtual SparseVolume run(const ReconstructionInput& input, ReconstructionReport& report) = 0;
  // Seconds since reconstruct() started, without the time spent in the observer.
  double elapsed_seconds() const;
  bool observed() const { return static_cast<bool>(observer_); }
  // Shows the observer iteration `iteration` (0: the initial volume, `stats` null); its time
  // is excluded from every time in the report.
  void notify(int iteration, const IterationStats* stats, std::function<SparseVolume()> volume);

 private:
  IterationObserver observer_;
  std::chrono::steady_clock::time_point start_{};
  double observer_seconds_ = 0.0;
};

// Throws tomorig::Error (bad_input) for an invalid option or an unknown algorithm.
std::unique_ptr<Reconstructor> make_reconstructor(const ReconstructionOptions& options);

// "mlos, mart, smart, fmart": the available algorithms, for messages and --help.
std::string algorithm_names();

}  // namespace tomorig::recon

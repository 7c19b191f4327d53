// The Δt check: FFT cross-correlation of windows of frame A against frame B (dt_check.h).
// OpenCV's DFT needs no plans, so it is safe next to the FFTW plans of the correlation module.
#include "tomorig/processing/quicklook/dt_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "tomorig/core/error.h"
#include "tomorig/processing/correlation/peak_fit.h"

namespace tomorig::quicklook {
namespace {

constexpr double kMaxPeakRatio = 100.0;
constexpr int kPeakExclusion = 2;  // a second peak must lie more than this many px from the first

void check_frame(const Image& image, const char* what, int window) {
  if (image.empty()) throw bad_input(fmt::format("Δt check: frame {} is missing (empty image)", what));
  if (image.type() == SampleType::f32)
    throw bad_input(fmt::format("Δt check: frame {} holds float samples; the check reads camera frames (Mono8, Mono12 "
                                "or Mono16)",
                                what));
  if (image.width() < window || image.height() < window)
    throw bad_input(fmt::format("Δt check: frame {} is {} x {} px, smaller than one {} px window; use a smaller "
                                "window_px",
                                what, image.width(), image.height(), window));
}

// Copies the window at (x0, y0) into `out` (float), minus its mean; returns the sum of squares.
template <typename T>
double load_window(const Image& image, int x0, int y0, cv::Mat& out) {
  const int n = out.rows;
  // Integer sums are exact and vectorise; the energy in float per row, double across rows.
  std::uint64_t sum = 0;
  for (int y = 0; y < n; ++y) {
    const T* src = image.row<T>(y0 + y) + x0;
    float* dst = out.ptr<float>(y);
    std::uint32_t row_sum = 0;
#pragma omp simd reduction(+ : row_sum)
    for (int x = 0; x < n; ++x) {
      dst[x] = static_cast<float>(src[x]);
      row_sum += src[x];
    }
    sum += row_sum;
  }
  const auto mean = static_cast<float>(static_cast<double>(sum) / (static_cast<double>(n) * n));
  double energy = 0;
  for (int y = 0; y < n; ++y) {
    float* row = out.ptr<float>(y);
    float e = 0;
#pragma omp simd reduction(+ : e)
    for (int x = 0; x < n; ++x) {
      row[x] -= mean;
      e += row[x] * row[x];
    }
    energy += e;
  }
  return energy;
}

double load(const Image& image, int x0, int y0, cv::Mat& out) {
  return image.type() == SampleType::u8 ? load_window<std::uint8_t>(image, x0, y0, out)
                                        : load_window<std::uint16_t>(image, x0, y0, out);
}

// Signed shift of plane index k on a circular plane of size n.
int shift_of(int k, int n) { return k < n / 2 ? k : k - n; }

double median_of(std::vector<double>& v) {
  if (v.empty()) return not_measured;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

void DtCheckOptions::validate() const {
  if (window_px < 8 || window_px > 512)
    throw bad_input(fmt::format("dt_check.window_px = {} is out of range: 8 to 512 px", window_px));
  if (windows_x < 1 || windows_y < 1 || windows_x > 64 || windows_y > 64)
    throw bad_input(fmt::format("dt_check.windows = {} x {} is out of range: 1 to 64 each", windows_x, windows_y));
  if (!(min_peak_ratio >= 1.0 && min_peak_ratio <= kMaxPeakRatio))
    throw bad_input(fmt::format("dt_check.min_peak_ratio = {} is out of range: 1 to {}", min_peak_ratio,
                                kMaxPeakRatio));
  for (const auto& [t, what] : {std::pair{&displacement_px, "dt_check.displacement_px"},
                                std::pair{&valid_fraction, "dt_check.valid_fraction"}})
    if (const std::string problem = t->validate(what); !problem.empty()) throw bad_input(problem);
}

struct DtCheck::Work {
  cv::Mat a, b, spectrum_a, spectrum_b, cross, plane;
  std::vector<double> scratch_x, scratch_y, scratch_m, scratch_r;

  explicit Work(int n)
      : a(n, n, CV_32F), b(n, n, CV_32F), spectrum_a(n, n, CV_32F), spectrum_b(n, n, CV_32F), cross(n, n, CV_32F),
        plane(n, n, CV_32F) {}
};

DtCheck::DtCheck(const DtCheckOptions& options) : options_(options) {
  options_.validate();
  work_ = std::make_unique<Work>(options_.window_px);
  const auto windows = static_cast<std::size_t>(options_.windows_x * options_.windows_y);
  for (auto* v : {&work_->scratch_x, &work_->scratch_y, &work_->scratch_m, &work_->scratch_r}) v->reserve(windows);
}
DtCheck::~DtCheck() = default;
DtCheck::DtCheck(DtCheck&&) noexcept = default;
DtCheck& DtCheck::operator=(DtCheck&&) noexcept = default;

void DtCheck::check(const Image& a, const Image& b, DtCheckResult& out) {
  const int n = options_.window_px;
  check_frame(a, "A", n);
  check_frame(b, "B", n);
  if (a.width() != b.width() || a.height() != b.height() || a.type() != b.type())
    throw bad_input(fmt::format("Δt check: frames A ({} x {} {}) and B ({} x {} {}) of a camera differ", a.width(),
                                a.height(), to_string(a.type()), b.width(), b.height(), to_string(b.type())));
  Work& w = *work_;
  const int nx = options_.windows_x, ny = options_.windows_y;
  out.windows.resize(static_cast<std::size_t>(nx * ny));
  out.displacement_histogram.assign(static_cast<std::size_t>(n / 2), 0u);
  w.scratch_x.clear();
  w.scratch_y.clear();
  w.scratch_m.clear();
  w.scratch_r.clear();

  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      DtWindow& win = out.windows[static_cast<std::size_t>(i + nx * j)];
      win = {};
      // Window centres spread evenly; windows kept inside the frame.
      win.x0 = std::clamp(static_cast<int>((i + 0.5) * a.width() / nx) - n / 2, 0, a.width() - n);
      win.y0 = std::clamp(static_cast<int>((j + 0.5) * a.height() / ny) - n / 2, 0, a.height() - n);
      const double energy_a = load(a, win.x0, win.y0, w.a), energy_b = load(b, win.x0, win.y0, w.b);
      if (!(energy_a > 0 && energy_b > 0)) {
        w.scratch_r.push_back(0.0);
        continue;  // a flat window: nothing to correlate
      }
      // Circular cross-correlation R(s) = sum_x a(x) b(x + s): B's spectrum times A's conjugate.
      cv::dft(w.a, w.spectrum_a);
      cv::dft(w.b, w.spectrum_b);
      cv::mulSpectrums(w.spectrum_b, w.spectrum_a, w.cross, 0, true);
      cv::dft(w.cross, w.plane, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
      const float norm = static_cast<float>(std::sqrt(energy_a * energy_b));

      // Highest value, then the highest local maximum away from it.
      int px = 0, py = 0;
      float best = -std::numeric_limits<float>::infinity();
      for (int y = 0; y < n; ++y) {
        const float* row = w.plane.ptr<float>(y);
        for (int x = 0; x < n; ++x)
          if (row[x] > best) {
            best = row[x];
            px = x;
            py = y;
          }
      }
      const auto at = [&](int x, int y) { return w.plane.at<float>((y + n) % n, (x + n) % n); };
      // The value test first: it rejects almost every point without the wrapped index sums.
      float second = -std::numeric_limits<float>::infinity();
      for (int y = 0; y < n; ++y) {
        const float* row = w.plane.ptr<float>(y);
        const int ddy = std::abs(shift_of((y - py + n) % n, n));
        for (int x = 0; x < n; ++x) {
          const float v = row[x];
          if (v <= second) continue;
          const int ddx = std::abs(shift_of((x - px + n) % n, n));
          if (std::max(ddx, ddy) <= kPeakExclusion) continue;
          bool maximum = true;
          for (int ey = -1; ey <= 1 && maximum; ++ey)
            for (int ex = -1; ex <= 1 && maximum; ++ex)
              if ((ex || ey) && at(x + ex, y + ey) > v) maximum = false;
          if (maximum) second = v;
        }
      }
      win.correlation = best / norm;
      win.peak_ratio = second > 0 ? std::min(kMaxPeakRatio, static_cast<double>(best / second)) : kMaxPeakRatio;
      w.scratch_r.push_back(win.peak_ratio);

      const int sx = shift_of(px, n), sy = shift_of(py, n);
      const bool off_edge = std::abs(sx) < n / 2 - 1 && std::abs(sy) < n / 2 - 1;
      const piv::PeakFit1d fx = piv::fit_peak_1d(at(px - 1, py), best, at(px + 1, py));
      const piv::PeakFit1d fy = piv::fit_peak_1d(at(px, py - 1), best, at(px, py + 1));
      win.dx = sx + fx.offset;
      win.dy = sy + fy.offset;
      win.valid = off_edge && win.peak_ratio >= options_.min_peak_ratio && win.correlation > 0;
      if (!win.valid) continue;
      const double magnitude = std::hypot(win.dx, win.dy);
      w.scratch_x.push_back(win.dx);
      w.scratch_y.push_back(win.dy);
      w.scratch_m.push_back(magnitude);
      const auto bin = std::min(out.displacement_histogram.size() - 1, static_cast<std::size_t>(magnitude));
      ++out.displacement_histogram[bin];
    }

  const double windows = static_cast<double>(nx) * ny;
  out.valid_fraction.set(static_cast<double>(w.scratch_m.size()) / windows, options_.valid_fraction);
  out.median_peak_ratio = median_of(w.scratch_r);
  out.median_dx = median_of(w.scratch_x);
  out.median_dy = median_of(w.scratch_y);
  out.displacement_px.set(median_of(w.scratch_m), options_.displacement_px);
}

}  // namespace tomorig::quicklook

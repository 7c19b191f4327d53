#include "tomorig/processing/optics/edge_psf.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::optics {
namespace {

// Solves the 4 x 4 system a x = b in place (Gaussian elimination with pivoting); false if singular.
bool solve4(std::array<std::array<double, 4>, 4> a, std::array<double, 4>& b) {
  for (int c = 0; c < 4; ++c) {
    int p = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::abs(a[r][c]) > std::abs(a[p][c])) p = r;
    if (std::abs(a[p][c]) < 1e-300) return false;
    std::swap(a[p], a[c]);
    std::swap(b[p], b[c]);
    for (int r = c + 1; r < 4; ++r) {
      const double f = a[r][c] / a[c][c];
      for (int k = c; k < 4; ++k) a[r][k] -= f * a[c][k];
      b[r] -= f * b[c];
    }
  }
  for (int c = 3; c >= 0; --c) {
    for (int k = c + 1; k < 4; ++k) b[c] -= a[c][k] * b[k];
    b[c] /= a[c][c];
  }
  return true;
}

// chi of the edge spread binned in sum / count (bins of o.bin_px from -o.half_width_px): its
// central differences fitted with a Gaussian, the differencing's own box removed. NaN if
// fewer than 5 line-spread samples.
double chi_from_edge_spread(const std::vector<double>& sum, const std::vector<double>& count,
                            const EdgeSpreadOptions& o, double* rms_residual);

struct Crossing {
  double u;
  int row;
  bool rising;
};

}  // namespace

double fit_line_spread_chi(const std::vector<double>& x, const std::vector<double>& y, double* rms_residual) {
  if (x.size() != y.size() || x.size() < 5) throw bad_input("line spread fit: needs at least 5 samples");
  // Start from the moments of the positive part.
  double s0 = 0, s1 = 0, s2 = 0, peak = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double w = std::max(0.0, y[i]);
    s0 += w;
    s1 += w * x[i];
    peak = std::max(peak, y[i]);
  }
  if (!(s0 > 0) || !(peak > 0)) throw bad_input("line spread fit: no peak");
  const double mean = s1 / s0;
  for (std::size_t i = 0; i < x.size(); ++i) s2 += std::max(0.0, y[i]) * (x[i] - mean) * (x[i] - mean);
  // p = (A, x0, chi, c)
  std::array<double, 4> p{peak, mean, std::max(0.5, 2.0 * std::sqrt(s2 / s0)), 0.0};
  for (int it = 0; it < 50; ++it) {
    std::array<std::array<double, 4>, 4> jtj{};
    std::array<double, 4> jtr{};
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double dx = x[i] - p[1];
      const double e = std::exp(-2.0 * dx * dx / (p[2] * p[2]));
      const double model = p[0] * e + p[3];
      const std::array<double, 4> j{e, p[0] * e * 4.0 * dx / (p[2] * p[2]), p[0] * e * 4.0 * dx * dx / (p[2] * p[2] * p[2]), 1.0};
      const double r = y[i] - model;
      for (int a = 0; a < 4; ++a) {
        jtr[a] += j[a] * r;
        for (int b = 0; b < 4; ++b) jtj[a][b] += j[a] * j[b];
      }
    }
    for (int a = 0; a < 4; ++a) jtj[a][a] *= 1.0 + 1e-6;
    if (!solve4(jtj, jtr)) break;
    double step = 1.0;
    // Keep chi positive: halve the step while it would not be.
    while (p[2] + step * jtr[2] <= 0.05 && step > 1e-6) step *= 0.5;
    for (int a = 0; a < 4; ++a) p[a] += step * jtr[a];
    if (std::abs(jtr[2]) < 1e-9 * p[2]) break;
  }
  if (rms_residual) {
    double ss = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double dx = x[i] - p[1];
      const double r = y[i] - (p[0] * std::exp(-2.0 * dx * dx / (p[2] * p[2])) + p[3]);
      ss += r * r;
    }
    *rms_residual = std::sqrt(ss / x.size()) / std::abs(p[0]);
  }
  return std::abs(p[2]);
}

namespace {

double chi_from_edge_spread(const std::vector<double>& sum, const std::vector<double>& count,
                            const EdgeSpreadOptions& o, double* rms_residual) {
  std::vector<double> esf_x, esf;
  for (std::size_t i = 0; i < sum.size(); ++i)
    if (count[i] > 0) {
      esf_x.push_back(-o.half_width_px + (static_cast<double>(i) + 0.5) * o.bin_px);
      esf.push_back(sum[i] / count[i]);
    }
  // Line spread: the derivative by central differences.
  std::vector<double> lsf_x, lsf;
  for (std::size_t i = 1; i + 1 < esf.size(); ++i) {
    lsf_x.push_back(esf_x[i]);
    lsf.push_back((esf[i + 1] - esf[i - 1]) / (esf_x[i + 1] - esf_x[i - 1]));
  }
  if (lsf.size() < 5) return std::nan("");
  const double chi = fit_line_spread_chi(lsf_x, lsf, rms_residual);
  // Differencing over +-1 bin widens the line spread by a box of 2 bins: remove its variance.
  const double sigma2 = 0.25 * chi * chi - (2.0 * o.bin_px) * (2.0 * o.bin_px) / 12.0;
  return 2.0 * std::sqrt(std::max(sigma2, 1e-6));
}

}  // namespace

EdgePsf measure_edge_psf(const Image& image, const EdgeSpreadOptions& o) {
  const int w = image.width(), h = image.height();
  if (image.empty() || w < 4 * o.half_width_px || h < o.min_rows)
    throw bad_input(fmt::format("edge PSF: image of {} x {} px is too small for edges of +-{} px over {} rows", w, h,
                                o.half_width_px, o.min_rows));
  // Crossings of each row's mid level (between its 5th and 95th percentiles), sub-pixel.
  std::vector<Crossing> crossings;
  std::vector<double> row(static_cast<std::size_t>(w)), sorted;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) row[u] = image.value(u, v);
    sorted = row;
    std::sort(sorted.begin(), sorted.end());
    const double dark = sorted[static_cast<std::size_t>(0.05 * (w - 1))], light = sorted[static_cast<std::size_t>(0.95 * (w - 1))];
    if (!(light > 0) || (light - dark) / light < o.min_contrast) continue;
    const double mid = 0.5 * (dark + light);
    for (int u = o.half_width_px; u + 1 < w - o.half_width_px; ++u) {
      const double a = row[u] - mid, b = row[u + 1] - mid;
      if ((a < 0) != (b < 0) && a != b) crossings.push_back({u + a / (a - b), v, b > a});
    }
  }
  // Group crossings into edges: seeded in the middle rows, followed row by row.
  EdgePsf out;
  std::vector<double> pooled_sum, pooled_count;
  std::vector<bool> used(crossings.size(), false);
  for (std::size_t seed = 0; seed < crossings.size(); ++seed) {
    if (used[seed]) continue;
    std::vector<std::size_t> members{seed};
    used[seed] = true;
    double last_u = crossings[seed].u;
    int last_row = crossings[seed].row;
    for (std::size_t k = seed + 1; k < crossings.size(); ++k) {
      if (crossings[k].row > last_row + 2) break;  // crossings are in row order
      if (used[k] || crossings[k].rising != crossings[seed].rising) continue;
      if (crossings[k].row > last_row && crossings[k].row <= last_row + 2 && std::abs(crossings[k].u - last_u) < 1.5) {
        members.push_back(k);
        used[k] = true;
        last_u = crossings[k].u;
        last_row = crossings[k].row;
      }
    }
    if (o.end_margin_rows > 0) {
      const int first = crossings[members.front()].row + o.end_margin_rows;
      const int last = crossings[members.back()].row - o.end_margin_rows;
      std::erase_if(members, [&](std::size_t m) { return crossings[m].row < first || crossings[m].row > last; });
    }
    if (static_cast<int>(members.size()) < o.min_rows) continue;
    // The edge line u = a + b v by least squares.
    double sv = 0, su = 0, svv = 0, suv = 0;
    const double n = static_cast<double>(members.size());
    for (std::size_t m : members) {
      sv += crossings[m].row;
      su += crossings[m].u;
      svv += double(crossings[m].row) * crossings[m].row;
      suv += double(crossings[m].row) * crossings[m].u;
    }
    const double b = (n * suv - sv * su) / std::max(1e-12, n * svv - sv * sv);
    const double a = (su - b * sv) / n;
    if (std::abs(b) > std::tan(30.0 * M_PI / 180.0)) continue;
    const double cos_t = 1.0 / std::sqrt(1.0 + b * b);
    // Edge spread: samples binned by their perpendicular distance to the line, oriented so it rises.
    const double sign = crossings[seed].rising ? 1.0 : -1.0;
    const int bins = static_cast<int>(std::ceil(2.0 * o.half_width_px / o.bin_px));
    std::vector<double> sum(static_cast<std::size_t>(bins), 0.0), count(static_cast<std::size_t>(bins), 0.0);
    const int first_row = crossings[members.front()].row, last = crossings[members.back()].row;
    for (int v = first_row; v <= last; ++v) {
      const double centre = a + b * v;
      for (int u = static_cast<int>(std::floor(centre)) - o.half_width_px; u <= static_cast<int>(std::ceil(centre)) + o.half_width_px; ++u) {
        if (u < 0 || u >= w) continue;
        const double d = sign * (u - centre) * cos_t;
        const int bin = static_cast<int>(std::floor((d + o.half_width_px) / o.bin_px));
        if (bin < 0 || bin >= bins) continue;
        sum[bin] += image.value(u, v);
        count[bin] += 1.0;
      }
    }
    EdgeMeasurement e;
    e.position_px = a + b * 0.5 * (h - 1);
    e.slope = b;
    e.rows = static_cast<int>(members.size());
    e.chi_px = chi_from_edge_spread(sum, count, o, &e.rms_residual);
    if (!std::isfinite(e.chi_px)) continue;
    out.edges.push_back(e);
    if (o.pool_edges) {
      pooled_sum.resize(sum.size(), 0.0);
      pooled_count.resize(count.size(), 0.0);
      for (std::size_t i = 0; i < sum.size(); ++i) {
        pooled_sum[i] += sum[i];
        pooled_count[i] += count[i];
      }
    }
  }
  if (out.edges.empty())
    throw bad_input(fmt::format("edge PSF: no measurable edge in the {} x {} px image (edges must be within 30 deg of "
                                "vertical, cross >= {} rows and have a contrast >= {})",
                                w, h, o.min_rows, o.min_contrast));
  if (o.pool_edges) {
    out.chi_px = chi_from_edge_spread(pooled_sum, pooled_count, o, &out.rms_residual);
    return out;
  }
  std::vector<double> chis;
  for (const EdgeMeasurement& e : out.edges) chis.push_back(e.chi_px);
  std::sort(chis.begin(), chis.end());
  out.chi_px = chis.size() % 2 ? chis[chis.size() / 2] : 0.5 * (chis[chis.size() / 2 - 1] + chis[chis.size() / 2]);
  return out;
}

}  // namespace tomorig::optics

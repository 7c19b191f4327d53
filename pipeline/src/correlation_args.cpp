#include "tomorig/pipeline/correlation_args.h"

#include <cstdio>

#include <CLI/CLI.hpp>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::pipeline {

void add_correlation_flags(CLI::App& cmd, CorrelationArgs& args) {
  cmd.add_option("--window", args.window,
                 "Final interrogation volume x,y,z in voxels (anisotropic allowed); the multigrid starts at twice "
                 "this on volumes binned 2x")
      ->capture_default_str();
  cmd.add_option("--overlap", args.overlap, "Overlap of neighbouring interrogation volumes, [0, 0.875]")
      ->capture_default_str();
  cmd.add_option("--deformation-passes", args.deformation_passes, "Volume deformation passes at the final window")
      ->capture_default_str();
  cmd.add_option("--weighting", args.weighting, "Window weighting: top-hat, gaussian or hann")
      ->check(CLI::IsMember({"top-hat", "gaussian", "hann"}))
      ->capture_default_str();
  cmd.add_option("--gaussian-sigma", args.gaussian_sigma,
                 "Standard deviation of --weighting gaussian as a fraction of the window edge, (0, 2]: 0.25 resolves "
                 "gradients best on clean volumes, 0.5 averages more particles against reconstruction ghosts")
      ->check(CLI::PositiveNumber & CLI::Range(0.0, 2.0))
      ->capture_default_str();
  cmd.add_option("--interpolation", args.interpolation, "Deformation interpolation: bspline or trilinear")
      ->check(CLI::IsMember({"bspline", "trilinear"}))
      ->capture_default_str();
  cmd.add_option("--min-peak", args.min_peak, "Minimum correlation coefficient of a valid vector (0: off)")
      ->capture_default_str();
  cmd.add_option("--max-displacement", args.max_displacement, "Largest accepted displacement, voxel (0: off)")
      ->capture_default_str();
}

piv::WindowSize parse_window(const std::string& text) {
  piv::WindowSize w;
  char tail = 0;
  const int n = std::sscanf(text.c_str(), "%d,%d,%d%c", &w.x, &w.y, &w.z, &tail);
  if (n == 1) w.y = w.z = w.x;
  if (!(n == 3 || (n == 1 && text.find(',') == std::string::npos)))
    throw bad_input(fmt::format("--window '{}' is not valid: give x,y,z in voxels, e.g. 32,32,16, or one size", text));
  return w;
}

piv::CorrelationOptions correlation_options(const CorrelationArgs& args) {
  if (args.deformation_passes < 0 || args.deformation_passes > 8)
    throw bad_input(fmt::format("--deformation-passes {} is out of range: use 0 to 8", args.deformation_passes));
  piv::CorrelationOptions o = piv::CorrelationOptions::multigrid(
      parse_window(args.window), args.overlap, args.deformation_passes,
      args.interpolation == "trilinear" ? piv::Interpolation::trilinear : piv::Interpolation::cubic_bspline);
  o.weighting = args.weighting == "hann"       ? piv::WindowWeighting::hann
                : args.weighting == "top-hat" ? piv::WindowWeighting::top_hat
                                              : piv::WindowWeighting::gaussian;
  o.gaussian_sigma = args.gaussian_sigma;
  o.min_peak = args.min_peak;
  o.max_displacement = args.max_displacement;
  o.threads = args.threads;
  return o;
}

nlohmann::json to_json(const piv::CorrelationOptions& o) {
  nlohmann::json passes = nlohmann::json::array();
  for (const piv::CorrelationPass& p : o.passes)
    passes.push_back({{"window", {p.window.x, p.window.y, p.window.z}},
                      {"overlap", p.overlap},
                      {"downsample", p.downsample},
                      {"deformation", p.deformation},
                      {"interpolation", p.interpolation == piv::Interpolation::trilinear ? "trilinear" : "bspline"}});
  const char* weighting = o.weighting == piv::WindowWeighting::hann       ? "hann"
                          : o.weighting == piv::WindowWeighting::gaussian ? "gaussian"
                                                                          : "top-hat";
  return {{"passes", passes},
          {"weighting", weighting},
          {"gaussian_sigma", o.gaussian_sigma},
          {"min_peak", o.min_peak},
          {"max_displacement", o.max_displacement},
          {"median_test", {{"enabled", o.median_test.enabled},
                           {"epsilon", o.median_test.epsilon},
                           {"threshold", o.median_test.threshold}}},
          {"smooth_predictor", o.smooth_predictor}};
}

nlohmann::json to_json(const piv::CorrelationReport& r) {
  nlohmann::json passes = nlohmann::json::array();
  for (const piv::PassReport& p : r.passes)
    passes.push_back({{"nodes", {p.nodes_x, p.nodes_y, p.nodes_z}},
                      {"low_peak", p.low_peak},
                      {"too_large", p.too_large},
                      {"median_outliers", p.median_outliers},
                      {"replaced", p.replaced},
                      {"masked", p.masked},
                      {"peak_fallbacks", p.peak_fallbacks},
                      {"empty_windows", p.empty_windows},
                      {"method", p.method},
                      {"fft_fallbacks", p.fft_fallbacks},
                      {"occupied_fraction", p.occupied_fraction},
                      {"seconds", p.seconds},
                      {"seconds_deformation", p.seconds_deformation},
                      {"seconds_windows", p.seconds_windows},
                      {"seconds_validation", p.seconds_validation},
                      {"thread_seconds_load", p.thread_seconds_load},
                      {"thread_seconds_correlation", p.thread_seconds_correlation},
                      {"thread_seconds_peak", p.thread_seconds_peak}});
  return {{"passes", passes},
          {"seconds_total", r.seconds_total},
          {"valid", r.valid},
          {"replaced", r.replaced},
          {"invalid", r.invalid},
          {"valid_fraction", r.valid_fraction()}};
}

}  // namespace tomorig::pipeline

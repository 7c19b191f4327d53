#pragma once
// Spray statistics (thesis Sect. 7.4, Fig. 7.12 right; Sect. 6.6, Fig. 6.21): the mean intensity
// volume of the reconstructions of many sets, marking where droplets appear frequently, written
// as a volume file (HDF5 + XDMF for ParaView) with PNG slices through it and a summary of where
// its intensity lies. `tomorig reconstruct --mean` is its command.
//
//   MeanVolumeOptions o{.session = "spray.h5", .chain = "shadow-a", .out = "mean.h5"};
//   o.recon.psf = "truth";
//   const MeanVolumeReport r = write_mean_volume(o);
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/processing/quality/intensity_moments.h"

namespace tomorig::pipeline {

struct MeanVolumeOptions {
  std::filesystem::path session;
  std::string calib;             // as `reconstruct --calib`
  std::string chain;             // preprocessing preset or chain TOML; empty: none
  ReconstructionChoices recon;   // algorithm, iterations, grid, PSF
  std::string sets;              // SetSelection text; empty: every set
  std::vector<Exposure> exposures{Exposure::A, Exposure::B};  // averaged alike
  std::vector<double> smooth;    // Gaussian sigma x, y, z (voxel) of each volume before averaging
  std::filesystem::path out;     // volume file; its .xdmf sidecar beside it
  std::filesystem::path slices;  // folder for the PNG slices; empty: none
  bool sparse_only = false;
  bool overwrite = false;
};

struct MeanVolumeReport {
  std::vector<std::uint64_t> sets;
  int volumes = 0;  // reconstructions averaged (sets x exposures)
  VoxelGrid grid;
  std::string algorithm;
  quality::IntensityMoments moments;  // of the mean (5 % tails)
  double mean_intensity = 0;          // per voxel
  std::vector<std::filesystem::path> slice_files;
  double seconds = 0;
};

// Reconstructs each chosen set's exposures as `reconstruct` would (after the chain), averages
// them voxel by voxel and writes volume "mean". The slices: one PNG each through the mean's
// centroid normal to x, y and z (mean_yz.png, mean_xz.png, mean_xy.png) and five equidistant
// x-y slices over the grid's depth (mean_z0.png .. mean_z4.png), grey levels linear from 0 to
// the 99.5th percentile of the mean's positive voxels (brighter ones white). Every output is checked before the first reconstruction; an
// existing one is refused (bad_input) without `overwrite`. `progress(done, total)` after each
// volume.
MeanVolumeReport write_mean_volume(const MeanVolumeOptions& options,
                                   const std::function<void(int done, int total)>& progress = {});

nlohmann::json to_json(const MeanVolumeReport& report);

}  // namespace tomorig::pipeline

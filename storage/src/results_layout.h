#pragma once
// Names of the results-file layout (docs/correlation.md, "Results file"), shared by the
// writer and the reader.
#include <cstdint>
#include <string>

#include <fmt/format.h>

namespace tomorig::storage::results_layout {

inline constexpr const char* kFormatName = "tomorig-results";
inline constexpr int kFormatVersion = 1;

// Root attributes and datasets.
inline constexpr const char* kAttrSessionPath = "session_path";
inline constexpr const char* kAttrSessionIdentity = "session_identity";
inline constexpr const char* kAttrVoxelSize = "voxel_size_mm";
inline constexpr const char* kParameters = "parameters";
inline constexpr const char* kSets = "sets";
inline constexpr const char* kStatistics = "statistics";

// Per set (/sets/<index>) and per field: node grid attributes.
inline constexpr const char* kAttrSetIndex = "set_index";
inline constexpr const char* kAttrDt = "dt_ns";
inline constexpr const char* kAttrSeconds = "seconds";
inline constexpr const char* kAttrCompleted = "completed_utc";
inline constexpr const char* kAttrComplete = "complete";  // 1: the set was finished
inline constexpr const char* kAttrNodes = "nodes";         // nx, ny, nz
inline constexpr const char* kAttrOrigin = "origin_mm";
inline constexpr const char* kAttrSpacing = "spacing_mm";
inline constexpr const char* kDisplacement = "displacement_voxel";  // [nz, ny, nx, 3] float32
inline constexpr const char* kVelocity = "velocity_m_s";            // [nz, ny, nx, 3] float32
inline constexpr const char* kStatus = "status";                    // [nz, ny, nx] uint8
inline constexpr const char* kPeak = "peak";                        // [nz, ny, nx] float32
inline constexpr const char* kReport = "report";

// Statistics (/statistics).
inline constexpr const char* kAttrSetCount = "sets";
inline constexpr const char* kValidCount = "valid_count";                   // uint32
inline constexpr const char* kMeanDisplacement = "mean_displacement_voxel";  // float64 x3
inline constexpr const char* kMeanVelocity = "mean_velocity_m_s";
inline constexpr const char* kRmsVelocity = "rms_velocity_m_s";
inline constexpr const char* kReynoldsStress = "reynolds_stress_m2_s2";     // uu vv ww uv uw vw

// Sets are named by their zero-padded index, so that h5ls lists them in order.
inline std::string set_name(std::uint64_t index) { return fmt::format("{:06d}", index); }

}  // namespace tomorig::storage::results_layout

#pragma once
// Names of the volume file layout, shared by writer and reader; documented for h5py, MATLAB
// and ParaView users in docs/file-formats.md ("Volume file"). Change both together.
#include <string>
#include <string_view>

namespace tomorig::storage::volume_layout {

inline constexpr std::string_view kFormatName = "tomorig-volume";
inline constexpr int kFormatVersion = 1;

// Root attributes (format, format_version, software_version, created_utc are as in sessions).
inline constexpr const char* kAttrSourceSession = "source_session";
inline constexpr const char* kAttrSetIndex = "set_index";
inline constexpr const char* kParameters = "parameters";  // scalar string dataset: JSON

inline constexpr const char* kVolumes = "volumes";
inline constexpr const char* kAttrOrder = "order";
// Per volume group.
inline constexpr const char* kAttrNx = "nx";  // int32 grid size in voxels
inline constexpr const char* kAttrNy = "ny";
inline constexpr const char* kAttrNz = "nz";
inline constexpr const char* kAttrOrigin = "origin_mm";  // float64 [3]: centre of voxel (0,0,0)
inline constexpr const char* kAttrVoxelSize = "voxel_size_mm";
inline constexpr const char* kAttrAlgorithm = "algorithm";
inline constexpr const char* kAttrExposure = "exposure";
inline constexpr const char* kReport = "report";  // scalar string dataset: JSON
inline constexpr const char* kDense = "dense";                   // float32 [nz, ny, nx]
inline constexpr const char* kSparseIndex = "sparse_index";      // uint32 [n], ascending
inline constexpr const char* kSparseIntensity = "sparse_intensity";  // float32 [n]

inline std::string volume_path(std::string_view name) { return "/volumes/" + std::string(name); }

}  // namespace tomorig::storage::volume_layout

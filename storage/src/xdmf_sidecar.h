#pragma once
// XDMF 3 text that makes ParaView (and VisIt) read dense volumes straight from an HDF5 file:
// one uniform 3DCoRectMesh grid per volume, the voxel intensities as a node-centred scalar.
#include <string>
#include <vector>

#include "tomorig/core/volume.h"

namespace tomorig::storage {

struct XdmfVolume {
  std::string name;          // grid name shown in ParaView
  VoxelGrid grid;
  std::string hdf5_dataset;  // "<file name>:/volumes/a/dense", relative to the .xdmf file
};

std::string xdmf_for_volumes(const std::vector<XdmfVolume>& volumes);

}  // namespace tomorig::storage

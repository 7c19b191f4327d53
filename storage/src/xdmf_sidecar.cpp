#include "xdmf_sidecar.h"

#include <iterator>
#include <string_view>

#include <fmt/format.h>

namespace tomorig::storage {
namespace {

std::string xml_escaped(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// XDMF lists dimensions slowest first (z, y, x), matching the C-order [nz, ny, nx] dataset.
void append_grid(std::string& out, const XdmfVolume& v) {
  const VoxelGrid& g = v.grid;
  fmt::format_to(std::back_inserter(out),
                 "    <Grid Name=\"{0}\" GridType=\"Uniform\">\n"
                 "      <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{1} {2} {3}\"/>\n"
                 "      <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
                 "        <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
                 "{4:.17g} {5:.17g} {6:.17g}</DataItem>\n"
                 "        <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
                 "{7:.17g} {7:.17g} {7:.17g}</DataItem>\n"
                 "      </Geometry>\n"
                 "      <Attribute Name=\"intensity\" AttributeType=\"Scalar\" Center=\"Node\">\n"
                 "        <DataItem Dimensions=\"{1} {2} {3}\" NumberType=\"Float\" Precision=\"4\" "
                 "Format=\"HDF\">{8}</DataItem>\n"
                 "      </Attribute>\n"
                 "    </Grid>\n",
                 xml_escaped(v.name), g.nz, g.ny, g.nx, g.origin.z, g.origin.y, g.origin.x, g.voxel_size,
                 xml_escaped(v.hdf5_dataset));
}

}  // namespace

std::string xdmf_for_volumes(const std::vector<XdmfVolume>& volumes) {
  std::string out =
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<!-- Written by tomorig: open this file in ParaView (Xdmf3 reader). Coordinates in mm. -->\n"
      "<Xdmf Version=\"3.0\">\n"
      "  <Domain>\n";
  for (const XdmfVolume& v : volumes) append_grid(out, v);
  out += "  </Domain>\n</Xdmf>\n";
  return out;
}

}  // namespace tomorig::storage

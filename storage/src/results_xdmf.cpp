#include "results_xdmf.h"

#include <algorithm>
#include <iterator>

#include <fmt/format.h>

#include "results_layout.h"

namespace tomorig::storage {
namespace {

namespace layout = results_layout;

struct XdmfAttribute {
  const char* name;
  const char* type;  // Scalar, Vector, Tensor6
  int components;
  const char* number;  // Float, UChar, UInt
  int precision;
};

// "nz ny nx" or "nz ny nx c": XDMF lists dimensions slowest first, matching the C-order datasets.
std::string node_dims(const XdmfFieldGrid& g, const XdmfAttribute& a) {
  return a.components == 1 ? fmt::format("{} {} {}", g.nz, g.ny, g.nx)
                           : fmt::format("{} {} {} {}", g.nz, g.ny, g.nx, a.components);
}

std::string attribute(const XdmfFieldGrid& g, const std::string& dataset, const XdmfAttribute& a) {
  return fmt::format(
      "      <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n"
      "        <DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}</DataItem>\n"
      "      </Attribute>\n",
      a.name, a.type, node_dims(g, a), a.number, a.precision, dataset);
}

std::string grid_header(const std::string& name, const XdmfFieldGrid& g) {
  return fmt::format(
      "    <Grid Name=\"{0}\" GridType=\"Uniform\">\n"
      "      <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{1} {2} {3}\"/>\n"
      "      <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
      "        <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
      "{4:.17g} {5:.17g} {6:.17g}</DataItem>\n"
      "        <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
      "{7:.17g} {8:.17g} {9:.17g}</DataItem>\n"
      "      </Geometry>\n",
      name, g.nz, g.ny, g.nx, g.origin.z, g.origin.y, g.origin.x, g.spacing.z, g.spacing.y, g.spacing.x);
}

std::string escaped(const std::string& file_name) {
  std::string file;
  for (char c : file_name) {
    if (c == '&') file += "&amp;";
    else if (c == '<') file += "&lt;";
    else if (c == '>') file += "&gt;";
    else if (c == '"') file += "&quot;";
    else file += c;
  }
  return file;
}

const char* kHeader =
    "<?xml version=\"1.0\" ?>\n"
    "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    "<!-- Written by tomorig: open this file in ParaView (Xdmf3ReaderS, Xdmf3ReaderT or XDMFReader). Coordinates "
    "in mm, velocities in m/s, displacements in voxels; each time step is a set, with the ensemble statistics "
    "beside its own arrays. -->\n"
    "<Xdmf Version=\"3.0\">\n"
    "  <Domain>\n";

std::string statistics_attributes(const std::string& file, const XdmfFieldGrid& g) {
  const std::string base = file + ":/" + layout::kStatistics + "/";
  std::string out;
  out += attribute(g, base + layout::kMeanVelocity, {"mean_velocity_m_s", "Vector", 3, "Float", 8});
  out += attribute(g, base + layout::kRmsVelocity, {"rms_velocity_m_s", "Vector", 3, "Float", 8});
  out += attribute(g, base + layout::kMeanDisplacement, {"mean_displacement_voxel", "Vector", 3, "Float", 8});
  out += attribute(g, base + layout::kReynoldsStress, {"reynolds_stress_m2_s2", "Tensor6", 6, "Float", 8});
  out += attribute(g, base + layout::kValidCount, {"valid_count", "Scalar", 1, "UInt", 4});
  return out;
}

// One row of a [rows, nz, ny, nx(, c)] dataset as a node-centred attribute, written so that both
// XDMF libraries in ParaView read it:
// - Xdmf3 (Xdmf3ReaderS/T) reads the item's own text, an HDF5 path with a hyperslab suffix
//   "file:/dataset|start:stride:count:dataspace". Its ItemType="HyperSlab" items are references
//   whose array type ParaView asks for before reading them, so they load as empty arrays
//   ("Skipping unrecognized array type"): the item must not carry ItemType.
// - XDMF 2 (XDMFReader) reads the legacy Type="HyperSlab" and its two child items (start, stride,
//   count; the whole dataset), which Xdmf3 ignores.
std::string row_attribute(const XdmfFieldGrid& g, const std::string& dataset, std::uint64_t row, std::uint64_t rows,
                          const XdmfAttribute& a) {
  const bool vector = a.components > 1;
  const std::string dims = node_dims(g, a);
  const int rank = vector ? 5 : 4;
  std::string start = fmt::format("{} 0 0 0", row), stride = "1 1 1 1",
              count = fmt::format("1 {} {} {}", g.nz, g.ny, g.nx), space = fmt::format("{} {}", rows, dims);
  if (vector) {
    start += " 0";
    stride += " 1";
    count += fmt::format(" {}", a.components);
  }
  return fmt::format(
      "      <Attribute Name=\"{0}\" AttributeType=\"{1}\" Center=\"Node\">\n"
      "        <DataItem Type=\"HyperSlab\" Dimensions=\"{2}\" NumberType=\"{3}\" Precision=\"{4}\" Format=\"HDF\">"
      "{5}|{6}:{7}:{8}:{9}\n"
      "          <DataItem Dimensions=\"3 {10}\" NumberType=\"UInt\" Precision=\"4\" Format=\"XML\">{6} {7} {8}</DataItem>\n"
      "          <DataItem Dimensions=\"{9}\" NumberType=\"{3}\" Precision=\"{4}\" Format=\"HDF\">{5}</DataItem>\n"
      "        </DataItem>\n"
      "      </Attribute>\n",
      a.name, a.type, dims, a.number, a.precision, dataset, start, stride, count, space, rank);
}

}  // namespace

std::string xdmf_for_result_rows(const std::string& file_name, const XdmfFieldGrid& g,
                                 const std::vector<XdmfSetRow>& sets, std::uint64_t rows, bool has_statistics) {
  const std::string file = escaped(file_name);
  std::string out = kHeader;
  if (sets.empty()) {
    if (has_statistics) out += grid_header("statistics", g) + statistics_attributes(file, g) + "    </Grid>\n";
    out += "  </Domain>\n</Xdmf>\n";
    return out;
  }
  // One temporal collection and nothing beside it: Xdmf3ReaderS and Xdmf3ReaderT show only the
  // collection of a domain that has one, so the statistics ride along in every set's grid.
  std::vector<XdmfSetRow> ordered = sets;
  std::sort(ordered.begin(), ordered.end(),
            [](const XdmfSetRow& a, const XdmfSetRow& b) { return a.set_index < b.set_index; });
  for (const XdmfSetRow& r : ordered) rows = std::max(rows, r.row + 1);
  const std::string statistics = has_statistics ? statistics_attributes(file, g) : std::string();
  out += "    <Grid Name=\"sets\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  const std::string base = file + ":/" + layout::kSets + "/";
  for (std::size_t i = 0; i < ordered.size(); ++i) {
    const std::uint64_t row = ordered[i].row;
    out += grid_header("set " + layout::set_name(ordered[i].set_index), g);
    out += fmt::format("      <Time Value=\"{}\"/>\n", i);
    out += row_attribute(g, base + layout::kDisplacement, row, rows, {"displacement_voxel", "Vector", 3, "Float", 4});
    out += row_attribute(g, base + layout::kVelocity, row, rows, {"velocity_m_s", "Vector", 3, "Float", 4});
    out += row_attribute(g, base + layout::kStatus, row, rows, {"status", "Scalar", 1, "UChar", 1});
    out += row_attribute(g, base + layout::kPeak, row, rows, {"peak", "Scalar", 1, "Float", 4});
    out += statistics;
    out += "    </Grid>\n";
  }
  out += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return out;
}

}  // namespace tomorig::storage

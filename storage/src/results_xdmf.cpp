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

std::string attribute(const XdmfFieldGrid& g, const std::string& dataset, const XdmfAttribute& a) {
  const std::string dims = a.components == 1 ? fmt::format("{} {} {}", g.nz, g.ny, g.nx)
                                             : fmt::format("{} {} {} {}", g.nz, g.ny, g.nx, a.components);
  return fmt::format(
      "      <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n"
      "        <DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}</DataItem>\n"
      "      </Attribute>\n",
      a.name, a.type, dims, a.number, a.precision, dataset);
}

std::string grid_header(const std::string& name, const XdmfFieldGrid& g) {
  // XDMF lists dimensions and geometry slowest first (z, y, x), matching the C-order datasets.
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
    else file += c;
  }
  return file;
}

const char* kHeader =
    "<?xml version=\"1.0\" ?>\n"
    "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    "<!-- Written by tomorig: open this file in ParaView (Xdmf3 reader). Coordinates in mm, velocities in m/s, "
    "displacements in voxels. -->\n"
    "<Xdmf Version=\"3.0\">\n"
    "  <Domain>\n";

std::string statistics_grid(const std::string& file, const XdmfFieldGrid& g) {
  const std::string base = file + ":/" + layout::kStatistics + "/";
  std::string out = grid_header("statistics", g);
  out += attribute(g, base + layout::kMeanVelocity, {"mean_velocity_m_s", "Vector", 3, "Float", 8});
  out += attribute(g, base + layout::kRmsVelocity, {"rms_velocity_m_s", "Vector", 3, "Float", 8});
  out += attribute(g, base + layout::kMeanDisplacement, {"mean_displacement_voxel", "Vector", 3, "Float", 8});
  out += attribute(g, base + layout::kReynoldsStress, {"reynolds_stress_m2_s2", "Tensor6", 6, "Float", 8});
  out += attribute(g, base + layout::kValidCount, {"valid_count", "Scalar", 1, "UInt", 4});
  out += "    </Grid>\n";
  return out;
}

// One row of a [rows, nz, ny, nx(, c)] dataset as a node-centred attribute.
std::string row_attribute(const XdmfFieldGrid& g, const std::string& dataset, std::uint64_t row, std::uint64_t rows,
                          const XdmfAttribute& a) {
  const bool vector = a.components > 1;
  const std::string dims = vector ? fmt::format("{} {} {} {}", g.nz, g.ny, g.nx, a.components)
                                  : fmt::format("{} {} {}", g.nz, g.ny, g.nx);
  const int rank = vector ? 5 : 4;
  std::string start = fmt::format("{} 0 0 0", row), stride = "1 1 1 1",
              count = fmt::format("1 {} {} {}", g.nz, g.ny, g.nx);
  if (vector) {
    start += " 0";
    stride += " 1";
    count += fmt::format(" {}", a.components);
  }
  return fmt::format(
      "      <Attribute Name=\"{0}\" AttributeType=\"{1}\" Center=\"Node\">\n"
      "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"{2}\" Type=\"HyperSlab\">\n"
      "          <DataItem Dimensions=\"3 {3}\" Format=\"XML\">{4} {5} {6}</DataItem>\n"
      "          <DataItem Dimensions=\"{7} {2}\" NumberType=\"{8}\" Precision=\"{9}\" Format=\"HDF\">{10}</DataItem>\n"
      "        </DataItem>\n"
      "      </Attribute>\n",
      a.name, a.type, dims, rank, start, stride, count, rows, a.number, a.precision, dataset);
}

}  // namespace

std::string xdmf_for_result_rows(const std::string& file_name, const XdmfFieldGrid& g,
                                 const std::vector<XdmfSetRow>& sets, std::uint64_t rows, bool has_statistics) {
  const std::string file = escaped(file_name);
  std::string out = kHeader;
  if (has_statistics) out += statistics_grid(file, g);
  if (!sets.empty()) {
    std::vector<XdmfSetRow> ordered = sets;
    std::sort(ordered.begin(), ordered.end(), [](const XdmfSetRow& a, const XdmfSetRow& b) { return a.set_index < b.set_index; });
    for (const XdmfSetRow& r : ordered) rows = std::max(rows, r.row + 1);
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
      out += "    </Grid>\n";
    }
    out += "    </Grid>\n";
  }
  out += "  </Domain>\n</Xdmf>\n";
  return out;
}

std::string xdmf_for_results(const std::string& file_name, const XdmfFieldGrid& g, const std::vector<std::string>& sets,
                             bool has_statistics) {
  // File names are written by tomorig from a path; escape the XML specials anyway.
  const std::string file = escaped(file_name);
  std::string out =
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<!-- Written by tomorig: open this file in ParaView (Xdmf3 reader). Coordinates in mm, velocities in m/s, "
      "displacements in voxels. -->\n"
      "<Xdmf Version=\"3.0\">\n"
      "  <Domain>\n";
  if (has_statistics) {
    const std::string base = file + ":/" + layout::kStatistics + "/";
    out += grid_header("statistics", g);
    out += attribute(g, base + layout::kMeanVelocity, {"mean_velocity_m_s", "Vector", 3, "Float", 8});
    out += attribute(g, base + layout::kRmsVelocity, {"rms_velocity_m_s", "Vector", 3, "Float", 8});
    out += attribute(g, base + layout::kMeanDisplacement, {"mean_displacement_voxel", "Vector", 3, "Float", 8});
    out += attribute(g, base + layout::kReynoldsStress, {"reynolds_stress_m2_s2", "Tensor6", 6, "Float", 8});
    out += attribute(g, base + layout::kValidCount, {"valid_count", "Scalar", 1, "UInt", 4});
    out += "    </Grid>\n";
  }
  if (!sets.empty()) {
    out += "    <Grid Name=\"sets\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (std::size_t i = 0; i < sets.size(); ++i) {
      const std::string base = file + ":/" + layout::kSets + "/" + sets[i] + "/";
      out += grid_header("set " + sets[i], g);
      out += fmt::format("      <Time Value=\"{}\"/>\n", i);
      out += attribute(g, base + layout::kDisplacement, {"displacement_voxel", "Vector", 3, "Float", 4});
      out += attribute(g, base + layout::kVelocity, {"velocity_m_s", "Vector", 3, "Float", 4});
      out += attribute(g, base + layout::kStatus, {"status", "Scalar", 1, "UChar", 1});
      out += attribute(g, base + layout::kPeak, {"peak", "Scalar", 1, "Float", 4});
      out += "    </Grid>\n";
    }
    out += "    </Grid>\n";
  }
  out += "  </Domain>\n</Xdmf>\n";
  return out;
}

}  // namespace tomorig::storage

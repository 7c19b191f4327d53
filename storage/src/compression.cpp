#include "compression.h"

#include <array>
#include <utility>

#include <fmt/format.h>

#include "h5_error.h"
#include "tomorig/core/error.h"

namespace tomorig::storage {
namespace {
constexpr std::array<std::pair<Compression, std::string_view>, 2> kNames{{
    {Compression::none, "none"}, {Compression::bitshuffle_lz4, "bitshuffle-lz4"}}};
}  // namespace

std::string_view to_string(Compression c) {
  for (const auto& [value, name] : kNames)
    if (value == c) return name;
  return "unknown";
}

std::optional<Compression> parse_compression(std::string_view name) {
  for (const auto& [value, n] : kNames)
    if (n == name) return value;
  return std::nullopt;
}

void require_filter(H5Z_filter_t filter, const std::string& purpose) {
  // H5Zfilter_avail also tries to load a plugin from HDF5's plugin path, so a positive answer
  // means the filter will work, not merely that its id is known.
  if (H5Zfilter_avail(filter) > 0) return;
  if (filter == kBitshuffleFilterId)
    throw runtime_error(fmt::format(
        "{} needs the bitshuffle-LZ4 HDF5 filter (id {}), which is not available: install the Debian package "
        "'bitshuffle' (it puts libh5bshuf.so into /usr/lib/x86_64-linux-gnu/hdf5/serial/plugins), or point "
        "HDF5_PLUGIN_PATH at a folder holding the plugin",
        purpose, kBitshuffleFilterId));
  throw runtime_error(fmt::format(
      "{} needs HDF5 filter {}, which is not available: install its plugin and point HDF5_PLUGIN_PATH at it "
      "(see https://portal.hdfgroup.org/documentation/hdf5-docs/registered_filter_plugins.html)",
      purpose, filter));
}

void add_compression_filter(hid_t dcpl, Compression compression, const std::string& purpose) {
  switch (compression) {
    case Compression::none: return;
    case Compression::bitshuffle_lz4: {
      require_filter(kBitshuffleFilterId, purpose);
      const unsigned options[2] = {kBitshuffleBlockSizeAuto, kBitshuffleLz4};
      h5::check(H5Pset_filter(dcpl, kBitshuffleFilterId, H5Z_FLAG_MANDATORY, 2, options), "cannot add",
                "the bitshuffle-LZ4 filter");
      return;
    }
  }
}

}  // namespace tomorig::storage

#include "tomorig/storage/output_path.h"

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::storage {

void check_output_path(const std::filesystem::path& path, bool overwrite, std::string_view kind) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw bad_input(fmt::format("cannot write {} '{}': it is a folder", kind, path.string()));
  if (fs::exists(path, ec) && !overwrite)
    throw bad_input(fmt::format("{} file '{}' already exists; choose another name or allow overwriting "
                                "(--overwrite)",
                                kind, path.string()));
  const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::exists(folder, ec))
    throw bad_input(fmt::format("cannot write {} '{}': folder '{}' does not exist", kind, path.string(),
                                folder.string()));
  if (!fs::is_directory(folder, ec))
    throw bad_input(fmt::format("cannot write {} '{}': '{}' is not a folder", kind, path.string(), folder.string()));
}

}  // namespace tomorig::storage

#include "image_sequence.h"

#include <glob.h>

#include <algorithm>
#include <cctype>
#include <system_error>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace {

bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

std::size_t digits_end(std::string_view s, std::size_t i) {
  while (i < s.size() && is_digit(s[i])) ++i;
  return i;
}

std::string_view strip_zeros(std::string_view digits) {
  const std::size_t first = digits.find_first_not_of('0');
  return first == std::string_view::npos ? std::string_view() : digits.substr(first);
}

// Frees glob(3)'s result on every path out.
struct GlobResult {
  glob_t result{};
  ~GlobResult() { globfree(&result); }
};

}  // namespace

bool natural_less(std::string_view a, std::string_view b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      const std::size_t ie = digits_end(a, i), je = digits_end(b, j);
      const std::string_view na = strip_zeros(a.substr(i, ie - i)), nb = strip_zeros(b.substr(j, je - j));
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      if (ie - i != je - j) return ie - i < je - j;  // equal values: fewer leading zeros first
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::vector<fs::path> find_sequence_files(const std::string& pattern, const std::string& camera_id) {
  if (pattern.empty()) throw bad_input(fmt::format("camera {}: the file pattern is empty", camera_id));
  GlobResult g;
  const int status = glob(pattern.c_str(), GLOB_TILDE, nullptr, &g.result);
  std::vector<fs::path> files;
  if (status == 0) {
    for (std::size_t i = 0; i < g.result.gl_pathc; ++i) {
      fs::path p(g.result.gl_pathv[i]);
      std::error_code ec;
      if (fs::is_regular_file(p, ec)) files.push_back(std::move(p));
    }
  } else if (status != GLOB_NOMATCH) {
    throw bad_input(fmt::format("camera {}: cannot list files for pattern '{}' (a folder is not readable)",
                                camera_id, pattern));
  }
  if (files.empty()) throw bad_input(fmt::format("camera {}: no files match '{}'", camera_id, pattern));
  std::sort(files.begin(), files.end(),
            [](const fs::path& x, const fs::path& y) { return natural_less(x.string(), y.string()); });
  return files;
}

}  // namespace tomorig::storage

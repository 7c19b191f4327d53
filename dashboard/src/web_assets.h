#pragma once
// The dashboard page's files, embedded at build time (dashboard/embed_web.cmake).
#include <string_view>
#include <vector>

namespace tomorig::dashboard {

struct WebAsset {
  std::string_view path;          // "/index.html"
  std::string_view content_type;  // "text/html; charset=utf-8"
  std::string_view bytes;
};

const std::vector<WebAsset>& web_assets();

}  // namespace tomorig::dashboard

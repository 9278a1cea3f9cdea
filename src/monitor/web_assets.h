#pragma once
// The monitor page's files, built into the binary by embed_web.cmake from src/monitor/web.
#include <cstddef>
#include <string_view>

namespace eamos::monitor {

struct WebAsset {
  const char* path;          ///< "/monitor.js"
  const char* content_type;
  const unsigned char* data;
  std::size_t size;
};

extern const WebAsset web_assets[];
extern const std::size_t web_asset_count;

/// The asset served at `path` ("/" is the page), or null.
inline const WebAsset* find_web_asset(std::string_view path) {
  if (path == "/") path = "/index.html";
  for (std::size_t i = 0; i < web_asset_count; ++i)
    if (path == web_assets[i].path) return &web_assets[i];
  return nullptr;
}

}  // namespace eamos::monitor

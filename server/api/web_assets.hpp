// The web page's files (clients/web), compiled into salientd by clients/web/embed_assets.cmake:
// each one's name (as under /web/) and bytes, which live as long as the program.
#pragma once

#include <span>
#include <string_view>

namespace salient::server {

struct WebAsset {
  std::string_view name;   // "index.html", "app.js", …
  std::string_view bytes;  // the file as it is in the source tree
};

std::span<const WebAsset> web_assets();

}  // namespace salient::server

#pragma once
// The web page's files, built into the binary (web/ and Debian's libjs-three at build time):
// a page served by hiveslam needs nothing from the internet or the disk at run time.
#include <string_view>

namespace hiveslam::viz::web {

struct WebAsset {
  std::string_view path;  // "/", "/viewer.js", ...
  std::string_view content_type;
  std::string_view body;
};

// Every file the page loads; nullptr for an unknown path.
const WebAsset* findAsset(std::string_view path);

}  // namespace hiveslam::viz::web

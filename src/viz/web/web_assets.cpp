#include "viz/web/web_assets.hpp"

#include <array>

// Each file is assembled into .rodata as it is: no conversion step, and a rebuild when it
// changes (OBJECT_DEPENDS in src/CMakeLists.txt). The paths come from CMake.
#define HIVESLAM_EMBED(symbol, file)                                                          \
  __asm__(".section .rodata\n.global " #symbol "_begin\n.balign 16\n" #symbol "_begin:\n" \
          ".incbin \"" file "\"\n.global " #symbol "_end\n" #symbol "_end:\n.byte 0\n.previous\n"); \
  extern "C" const char symbol##_begin[];                                                     \
  extern "C" const char symbol##_end[];

HIVESLAM_EMBED(hiveslam_web_index, HIVESLAM_WEB_DIR "/index.html")
HIVESLAM_EMBED(hiveslam_web_viewer_js, HIVESLAM_WEB_DIR "/viewer.js")
HIVESLAM_EMBED(hiveslam_web_viewer_css, HIVESLAM_WEB_DIR "/viewer.css")
HIVESLAM_EMBED(hiveslam_web_three, HIVESLAM_THREE_JS)
HIVESLAM_EMBED(hiveslam_web_orbit, HIVESLAM_ORBIT_CONTROLS_JS)

namespace hiveslam::viz::web {

namespace {

std::string_view span(const char* begin, const char* end) { return {begin, static_cast<size_t>(end - begin)}; }

}  // namespace

const WebAsset* findAsset(std::string_view path) {
  static const std::array<WebAsset, 5> assets{{
      {"/", "text/html; charset=utf-8", span(hiveslam_web_index_begin, hiveslam_web_index_end)},
      {"/viewer.js", "text/javascript", span(hiveslam_web_viewer_js_begin, hiveslam_web_viewer_js_end)},
      {"/viewer.css", "text/css", span(hiveslam_web_viewer_css_begin, hiveslam_web_viewer_css_end)},
      {"/three.min.js", "text/javascript", span(hiveslam_web_three_begin, hiveslam_web_three_end)},
      {"/OrbitControls.js", "text/javascript", span(hiveslam_web_orbit_begin, hiveslam_web_orbit_end)},
  }};
  for (const auto& a : assets)
    if (a.path == path) return &a;
  return nullptr;
}

}  // namespace hiveslam::viz::web

// The dashboard's static files (server/ui/*.html, *.css, *.js) and the
// example specs (examples/*.json), compiled into hmpm-server so that the
// binary serves /ui with nothing installed beside it. The table is
// generated at build time by server/ui/embed_ui.cmake; the server looks a
// request path up with find_asset and answers with the asset's body and
// content type.
#pragma once

#include <cstddef>
#include <string_view>

namespace hmpm::server::ui {

struct Asset {
  std::string_view path;          // request path: "/ui/app.js", "/ui/examples/terzaghi.json"
  std::string_view content_type;  // e.g. "text/javascript; charset=utf-8"
  std::string_view body;          // the file's bytes
};

// Every embedded file; `/ui/examples/index.json` (a JSON array
// of the example names) is generated with them. `/ui` itself is not listed:
// the server answers it with "/ui/index.html".
extern const Asset assets[];
extern const std::size_t asset_count;

// The asset served at `path`, or nullptr (answer 404).
const Asset* find_asset(std::string_view path);

}  // namespace hmpm::server::ui

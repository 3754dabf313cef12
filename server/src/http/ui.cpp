// ui.cpp — GET /ui, /ui/ and /ui/{file}: the dashboard (server/ui) and the
// example specs, compiled into the binary by server/ui/embed_ui.cmake.
//
// No token (the page must load before a person can type one in);
// `Cache-Control: no-cache` keeps a browser from mixing two versions' files.
#include "handlers.hpp"
#include "problem.hpp"
#include "ui_assets.hpp"

namespace hmpm::server::http {

void get_ui(Context&, const httplib::Request& req, httplib::Response& res) {
  const std::string path = req.path == "/ui" || req.path == "/ui/" ? "/ui/index.html" : req.path;
  const ui::Asset* asset = ui::find_asset(path);
  if (!asset) return send_not_found(res, "the dashboard has no file " + req.path);
  res.set_header("Cache-Control", "no-cache");
  res.set_content(std::string(asset->body), std::string(asset->content_type));
}

}  // namespace hmpm::server::http

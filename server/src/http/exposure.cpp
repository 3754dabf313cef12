// exposure.cpp — see exposure.hpp.
#include "exposure.hpp"

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>

#include "hmpm/server/options.hpp"

namespace hmpm::server::http {
namespace {

std::string ascii_lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

struct Authority {
  std::string name;  ///< lower case; an IPv6 address without its brackets
  std::string port;  ///< "" when none was given
  bool valid = false;
};

// NAME, NAME:PORT, [V6] or [V6]:PORT.
Authority parse_authority(std::string_view text) {
  Authority a;
  std::string_view rest;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos) return a;
    a.name = ascii_lower(text.substr(1, close - 1));
    rest = text.substr(close + 1);
  } else {
    const auto colon = text.find(':');
    a.name = ascii_lower(text.substr(0, colon));
    rest = colon == std::string_view::npos ? std::string_view() : text.substr(colon);
  }
  if (!rest.empty()) {
    if (rest.front() != ':' || rest.size() == 1) return a;
    a.port = std::string(rest.substr(1));
    if (!std::all_of(a.port.begin(), a.port.end(),
                     [](unsigned char c) { return std::isdigit(c) != 0; }))
      return a;
  }
  a.valid = !a.name.empty();
  return a;
}

std::string bare(std::string host) {
  if (host.size() > 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  return ascii_lower(host);
}

bool wildcard(const std::string& host) {
  return host == "0.0.0.0" || host == "::" || host == "[::]";
}

}  // namespace

bool host_allowed(const httplib::Request& req, const ServiceConfig& config) {
  if (!req.has_header("Host")) return true;  // HTTP/1.0 (1.1 without one is a 400 before)
  const Authority host = parse_authority(req.get_header_value("Host"));
  if (!host.valid) return false;
  for (const std::string& entry : config.allowed_hosts) {
    const Authority allowed = parse_authority(entry);
    if (allowed.valid && allowed.name == host.name &&
        (allowed.port.empty() || allowed.port == host.port))
      return true;
  }
  // The listening address: its port (or none), and the address itself, the
  // one the connection came to, or localhost on loopback.
  if (!host.port.empty() && host.port != std::to_string(req.local_port)) return false;
  if (!wildcard(config.host) && host.name == bare(config.host)) return true;
  if (!req.local_addr.empty() && host.name == bare(req.local_addr)) return true;
  return host.name == "localhost" &&
         is_loopback_host(req.local_addr.empty() ? config.host : req.local_addr);
}

bool origin_allowed(const httplib::Request& req, const ServiceConfig& config) {
  if (!req.has_header("Origin")) return true;
  const std::string origin = ascii_lower(req.get_header_value("Origin"));
  for (const std::string& allowed : config.allowed_origins) {
    if (origin == ascii_lower(allowed)) return true;
  }
  // The server's own origin (the dashboard's page): the same authority as
  // the Host it was sent to, which host_allowed has checked.
  const auto scheme = origin.find("://");
  if (scheme == std::string::npos || !req.has_header("Host")) return false;
  return origin.substr(scheme + 3) == ascii_lower(req.get_header_value("Host"));
}

void add_cors_headers(const httplib::Request& req, const ServiceConfig& config,
                      httplib::Response& res) {
  if (!req.has_header("Origin") || config.allowed_origins.empty()) return;
  const std::string origin = req.get_header_value("Origin");
  const auto match = std::find_if(
      config.allowed_origins.begin(), config.allowed_origins.end(),
      [&](const std::string& allowed) { return ascii_lower(allowed) == ascii_lower(origin); });
  if (match == config.allowed_origins.end()) return;
  res.set_header("Access-Control-Allow-Origin", origin);
  res.set_header("Vary", "Origin");
  if (req.method == "OPTIONS") {
    res.set_header("Access-Control-Allow-Methods", "GET, HEAD, POST, DELETE, OPTIONS");
    res.set_header("Access-Control-Allow-Headers", "Authorization, Content-Type, Idempotency-Key");
    res.set_header("Access-Control-Max-Age", "600");
  }
}

bool body_not_json(const httplib::Request& req) {
  if (req.method != "POST") return false;
  const std::string length = req.get_header_value("Content-Length");
  if (length.empty() || length == "0") return false;  // no body: cancel, for one
  const std::string type = req.get_header_value("Content-Type");
  std::string_view media(type);
  media = media.substr(0, media.find(';'));
  while (!media.empty() && (media.back() == ' ' || media.back() == '\t')) media.remove_suffix(1);
  while (!media.empty() && (media.front() == ' ' || media.front() == '\t')) media.remove_prefix(1);
  return ascii_lower(media) != "application/json";
}

void limit_ranges(const httplib::Request& req) {
  // The Request is a non-const local of httplib's process_request.
  auto& ranges = const_cast<httplib::Request&>(req).ranges;
  if (ranges.size() > 1) ranges.clear();
  if (req.has_header("If-Range") && req.path.find("/results/") == std::string::npos) ranges.clear();
}

}  // namespace hmpm::server::http

namespace hmpm::server::http {

void bound_compression(const httplib::Request& req, const httplib::Response& res) {
  if (res.body.size() <= brotli_max_bytes) return;
  auto& headers = const_cast<httplib::Request&>(req).headers;  // see limit_ranges
  for (auto& [name, value] : headers) {
    if (ascii_lower(name) != "accept-encoding") continue;
    std::string kept;
    std::string_view rest = value;
    while (!rest.empty()) {
      const auto comma = rest.find(',');
      std::string_view item = rest.substr(0, comma);
      rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
      while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
      if (ascii_lower(item.substr(0, item.find(';'))).find("br") == 0 &&
          item.substr(0, item.find(';')).size() == 2)
        continue;
      kept += (kept.empty() ? "" : ", ") + std::string(item);
    }
    value = kept;
  }
}

}  // namespace hmpm::server::http

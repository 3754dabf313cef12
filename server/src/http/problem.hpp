// problem.hpp — every response body the service writes: JSON documents and
// problem documents (RFC 9457, `application/problem+json`).
//
// Handlers never build a problem document by hand; they call send_problem
// (or one of the named cases below), so every error has `type`, `title`,
// `status` and `detail`, and the catalogue in docs/api.md stays true.
#pragma once

#include <httplib.h>

#include <nlohmann/json.hpp>
#include <string>

namespace hmpm::server::http {

using Json = nlohmann::ordered_json;

/// `doc` as one line of JSON (invalid UTF-8 replaced), newline-terminated.
std::string dump(const Json& doc);

void send_json(httplib::Response& res, int status, const Json& doc);

/// A problem document; members of `extra` (e.g. `errors`) are appended.
void send_problem(httplib::Response& res, int status, const std::string& type,
                  const std::string& title, const std::string& detail,
                  const Json& extra = Json::object());

void send_not_found(httplib::Response& res, const std::string& what);

/// 404 for a job id the store does not know.
void send_no_such_job(httplib::Response& res, const std::string& id);

/// 400 invalid-parameter for query parameter `name`; members of `extra` appended.
void send_invalid_parameter(httplib::Response& res, const std::string& detail,
                            const std::string& name, const std::string& message,
                            const Json& extra = Json::object());

/// 413 payload-too-large naming the limit.
void send_too_large(httplib::Response& res, std::size_t limit_bytes);

/// How long a client should wait before retrying when the store cannot
/// write (`Retry-After` of 503 store-unavailable and 507 insufficient-storage).
inline constexpr int store_retry_after_s = 10;

/// 507 insufficient-storage (`no_space`: the disk or a size limit is full) or
/// 503 store-unavailable (any other database failure), with Retry-After;
/// nothing of the request was stored.
void send_store_failure(httplib::Response& res, bool no_space);

/// The problem document for a status httplib chose by itself (400, 404, 413, 414 ...).
void send_default_problem(httplib::Response& res);

}  // namespace hmpm::server::http

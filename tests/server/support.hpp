// support.hpp — what the server and end-to-end tests share: job specs sized
// for a test, temporary folders, raw HTTP for requests a well-behaved client
// library will not send, and bounded polling.
#pragma once

#include <httplib.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace hmpm::server::testing {

using Json = nlohmann::json;

/// A vibrating bar, 13 particles, `end_s` / 1 ms steps: finishes in milliseconds.
std::string small_spec(const std::string& name = "small-bar", double end_s = 0.5);

/// A 1000-particle bar with 1 ms steps up to `end_s`: about 25 us of solver
/// time per step on one thread, so 60 s of simulated time take seconds and
/// 10 000 s take long enough to be cancelled or killed.
std::string long_spec(const std::string& name, double end_s);

/// A fresh empty folder under the system temp folder.
std::filesystem::path make_temp_dir(const std::string& tag);

/// Sends `request` as is to 127.0.0.1:`port` and returns everything the
/// server answers until it closes or `timeout_s` passes.
std::string raw_http(int port, const std::string& request, double timeout_s = 10.0);

/// The status code of a raw HTTP response (0 if there is none).
int raw_status(const std::string& response);

/// The body of a raw HTTP response (after the blank line).
std::string raw_body(const std::string& response);

/// Polls GET /jobs/{id} every 50 ms until `done(doc)` or `timeout_s`;
/// returns the last document (null if the job could never be read).
Json poll_job(httplib::Client& client, const std::string& id,
              const std::function<bool(const Json&)>& done, double timeout_s,
              const httplib::Headers& headers = {});

/// True when the document's status is a terminal one of the job-status table.
bool is_final(const Json& doc);

/// The body parsed as JSON, or null when it is not JSON.
Json json_of(const std::string& body);

/// The whole content of a file.
std::string read_file(const std::filesystem::path& path);

}  // namespace hmpm::server::testing

// ogc.cpp — OGC API – Processes – Part 1: Core 1.0 (core, json,
// ogc-process-description, job-list, dismiss) over the job service.
//
// The service offers one process, `hmpm`, whose one input `spec` is the job
// spec. Executing it is submitting a job: the same code path as POST /jobs
// (submit_job), answered the same way, so the job list, status documents,
// results and dismissal are the /jobs routes under the same ids. The
// documents here are static but for the Accept header of the landing page.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <string_view>

#include "documents.hpp"
#include "handlers.hpp"
#include "hmpm/api/job.hpp"
#include "job_schema.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

constexpr const char* process_id = "hmpm";
constexpr const char* rel_conformance = "http://www.opengis.net/def/rel/ogc/1.0/conformance";
constexpr const char* rel_processes = "http://www.opengis.net/def/rel/ogc/1.0/processes";
constexpr const char* rel_job_list = "http://www.opengis.net/def/rel/ogc/1.0/job-list";
constexpr const char* rel_execute = "http://www.opengis.net/def/rel/ogc/1.0/execute";
constexpr const char* no_such_process =
    "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/no-such-process";

// The output of the process: the manifest's `files`, so that the manifest at
// /jobs/{id}/results is the results document (output id -> inline value).
constexpr const char* output_id = "files";

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Calls `f(item, parameters)` for each comma-separated item of a header value.
template <class F>
void for_each_item(std::string_view header, F f) {
  // Plain index loops, not string_view::find: with the precompiled headers
  // GCC 12 inlines find's memchr and warns (-Wstringop-overread) about a
  // bound it cannot prove, which -Werror turns into a failed build.
  while (!header.empty()) {
    std::size_t comma = 0;
    while (comma < header.size() && header[comma] != ',') ++comma;
    const std::string_view item = header.substr(0, comma);
    std::size_t semi = 0;
    while (semi < item.size() && item[semi] != ';') ++semi;
    f(lower(trim(item.substr(0, semi))), item.substr(semi));
    header.remove_prefix(std::min(comma + 1, header.size()));
  }
}

// The q value of an Accept item's parameters (";q=0.8"); 1 without one.
double quality(std::string_view parameters) {
  const std::string p = lower(parameters);
  const std::size_t at = p.find("q=");
  if (at == std::string::npos) return 1.0;
  double q = 0.0;  // unreadable: not acceptable
  std::from_chars(p.data() + at + 2, p.data() + p.size(), q);
  return q;
}

// True when `accept` asks for text/html and does not prefer JSON: a higher
// q, or on a tie the range listed first (a browser: "text/html,...,*/*;q=0.8").
// Clients that send nothing, */* or JSON get JSON.
bool prefers_html(const std::string& accept) {
  struct Best {
    double q = 0.0;
    int position = 0;
  } html, json;
  int position = 0;
  for_each_item(accept, [&](const std::string& range, std::string_view parameters) {
    const double q = quality(parameters);
    ++position;
    Best* best = range == "text/html" ? &html
                 : (range == "application/json" || range == "application/*" || range == "*/*")
                     ? &json
                     : nullptr;
    if (best && q > best->q) *best = {q, position};
  });
  return html.q > 0.0 && (html.q > json.q || (html.q == json.q && html.position < json.position));
}

// True when the Prefer header (RFC 7240) asks for an asynchronous answer.
bool prefers_async(const std::string& prefer) {
  bool async = false;
  for_each_item(prefer, [&](const std::string& token, std::string_view) {
    async = async || token == "respond-async";
  });
  return async;
}

Json process_summary() {
  const std::string self = std::string("/processes/") + process_id;
  return Json{{"id", process_id},
              {"title", "Hydro-mechanical MPM simulation"},
              {"description",
               "Runs one hmpm job: a Material Point Method simulation of saturated soil (u-p "
               "formulation) described by a job spec, and writes its result files."},
              {"version", hmpm::api::version()},
              {"jobControlOptions", Json::array({"async-execute"})},
              {"outputTransmission", Json::array({"value"})},
              {"links", Json::array({link(self, "self", "application/json", "process description"),
                                     link(self + "/execution", rel_execute, "application/json",
                                          "execute the process (asynchronously)")})}};
}

const Json& process_description() {
  static const Json doc = [] {
    Json d = process_summary();
    d["inputs"] =
        Json{{"spec",
              {{"title", "Job spec"},
               {"description",
                "The hmpm job spec, the JSON document POST /jobs takes (docs/job-spec.md); the "
                "server's parser checks more than this schema can say."},
               {"minOccurs", 1},
               {"maxOccurs", 1},
               {"schema", Json::parse(generated::job_schema)}}}};
    const Json string{{"type", "string"}};
    d["outputs"] =
        Json{{output_id,
              {{"title", "Result files"},
               {"description",
                "The files the run wrote (summary.json always; series, snapshots and reactions as "
                "the spec asks), each with its size, media type, SHA-256 and the href to download "
                "it from. GET /jobs/{jobID}/results answers it."},
               {"schema",
                {{"type", "array"},
                 {"items",
                  {{"type", "object"},
                   {"required", Json::array({"name", "size", "media_type", "sha256", "href"})},
                   {"properties",
                    {{"name", string},
                     {"size", {{"type", "integer"}, {"minimum", 0}}},
                     {"media_type", string},
                     {"sha256", string},
                     {"href", {{"type", "string"}, {"format", "uri-reference"}}}}}}}}}}}};
    return d;
  }();
  return doc;
}

// A problem about the execute request itself (not the job spec): 400 with
// `errors` whose paths point into the request document.
void send_invalid_request(httplib::Response& res, const std::string& path,
                          const std::string& message) {
  send_problem(res, 400, "invalid-execute-request", "Invalid execute request",
               "the body must be an execute request {\"inputs\": {\"spec\": <job spec>}}",
               Json{{"errors", Json::array({Json{{"path", path}, {"message", message}}})}});
}

bool known_process(const httplib::Request& req, httplib::Response& res) {
  if (req.matches[1] == process_id) return true;
  send_problem(
      res, 404, no_such_process, "No such process",
      "no process with id '" + req.matches[1].str() + "'; the one process is '" + process_id + "'");
  return false;
}

// The job spec of an execute request, as text; nullopt (and the 400 sent)
// when the request is not one this process takes. `max_depth` bounds the
// nesting before anything is built.
std::optional<std::string> spec_of(const std::string& body, int max_depth, httplib::Response& res) {
  struct TooDeep {};
  Json request;
  try {
    request = Json::parse(body, [max_depth](int depth, Json::parse_event_t, Json&) {
      if (depth > max_depth) throw TooDeep{};
      return true;
    });
  } catch (const TooDeep&) {
    send_invalid_request(res, "", "nested deeper than " + std::to_string(max_depth) + " levels");
    return std::nullopt;
  } catch (const Json::exception& e) {
    send_invalid_request(res, "", std::string("not valid JSON: ") + e.what());
    return std::nullopt;
  }
  if (!request.is_object()) {
    send_invalid_request(res, "", "must be a JSON object");
    return std::nullopt;
  }
  for (const auto& [key, value] : request.items()) {
    if (key == "inputs") continue;
    if (key == "outputs") {
      if (!value.is_object()) {
        send_invalid_request(res, "/outputs", "must be an object");
        return std::nullopt;
      }
      for (const auto& [output, _] : value.items()) {
        if (output != output_id) {
          send_invalid_request(
              res, "/outputs/" + output,
              std::string("unknown output; the one output is '") + output_id + "'");
          return std::nullopt;
        }
      }
    } else if (key == "response") {
      if (value != "document" && value != "raw") {
        send_invalid_request(res, "/response", "must be \"document\" or \"raw\"");
        return std::nullopt;
      }
    } else if (key == "mode") {
      // Drafts of the standard asked here; any mode is run asynchronously.
      if (value != "async" && value != "sync" && value != "auto") {
        send_invalid_request(res, "/mode", "must be \"async\", \"sync\" or \"auto\"");
        return std::nullopt;
      }
    } else {
      send_invalid_request(res, "/" + key,
                           "unknown member (known: inputs, outputs, response, mode; subscriber "
                           "callbacks are not supported)");
      return std::nullopt;
    }
  }
  const auto inputs = request.find("inputs");
  if (inputs == request.end() || !inputs->is_object()) {
    send_invalid_request(res, "/inputs", "must be an object holding the input 'spec'");
    return std::nullopt;
  }
  for (const auto& [input, _] : inputs->items()) {
    if (input != "spec") {
      send_invalid_request(res, "/inputs/" + input, "unknown input; the one input is 'spec'");
      return std::nullopt;
    }
  }
  const auto spec = inputs->find("spec");
  if (spec == inputs->end()) {
    send_invalid_request(res, "/inputs/spec", "required: the job spec");
    return std::nullopt;
  }
  // A qualified value {"value": spec, "mediaType": ...} carries the spec too;
  // a reference {"href": ...} is not fetched.
  if (spec->is_object() && spec->contains("href")) {
    send_invalid_request(res, "/inputs/spec/href",
                         "references are not fetched; send the job spec inline");
    return std::nullopt;
  }
  if (spec->is_object() && spec->contains("value")) {
    for (const auto& [key, _] : spec->items()) {
      if (key != "value" && key != "mediaType" && key != "encoding" && key != "schema") {
        send_invalid_request(res, "/inputs/spec/" + key,
                             "unknown member of a qualified value (value, mediaType)");
        return std::nullopt;
      }
    }
    return dump((*spec)["value"]);
  }
  return dump(*spec);
}

// OGC's `f` parameter: `json` (the only encoding here) or absent; false
// after a 400 naming it otherwise.
bool json_requested(const httplib::Request& req, httplib::Response& res) {
  if (!req.has_param("f") || req.get_param_value("f") == "json") return true;
  send_invalid_parameter(res, "f must be json (the only encoding of this document)", "f",
                         "unknown encoding '" + req.get_param_value("f") + "'");
  return false;
}

}  // namespace

void get_landing_page(Context&, const httplib::Request& req, httplib::Response& res) {
  res.set_header("Vary", "Accept");
  const bool html = req.has_param("f") ? req.get_param_value("f") == "html"
                                       : prefers_html(req.get_header_value("Accept"));
  if (html) return res.set_redirect("/ui", 303);
  if (!json_requested(req, res)) return;
  send_json(
      res, 200,
      Json{{"title", "hmpm-server"},
           {"description",
            "Hydro-mechanical Material Point Method simulations as jobs, through OGC API - "
            "Processes (one process, 'hmpm') and the /jobs routes of docs/api.md."},
           {"links",
            Json::array({link("/", "self", "application/json", "this document"),
                         link("/ui", "alternate", "text/html", "the dashboard"),
                         link("/conformance", rel_conformance, "application/json",
                              "conformance classes implemented"),
                         link("/processes", rel_processes, "application/json", "the processes"),
                         link("/jobs", rel_job_list, "application/json", "the jobs")})}});
}

void get_conformance(Context&, const httplib::Request& req, httplib::Response& res) {
  if (!json_requested(req, res)) return;
  const std::string base = "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/";
  Json classes = Json::array();
  for (const char* c : {"core", "json", "ogc-process-description", "job-list", "dismiss"})
    classes.push_back(base + c);
  send_json(res, 200, Json{{"conformsTo", classes}});
}

void list_processes(Context&, const httplib::Request& req, httplib::Response& res) {
  if (!json_requested(req, res)) return;
  send_json(res, 200,
            Json{{"processes", Json::array({process_summary()})},
                 {"links",
                  Json::array({link("/processes", "self", "application/json", "the processes")})}});
}

void get_process(Context&, const httplib::Request& req, httplib::Response& res) {
  if (!json_requested(req, res) || !known_process(req, res)) return;
  send_json(res, 200, process_description());
}

void execute_process(Context& c, const httplib::Request& req, httplib::Response& res,
                     const std::string& body) {
  if (!known_process(req, res)) return;
  // Room for the request's own two levels around the spec.
  const auto spec = spec_of(body, c.limits.max_json_depth + 2, res);
  if (!spec) return;
  // The process executes asynchronously only, whatever the client prefers
  // (OGC 18-062r2, /req/core/process-execute-default-execution-mode).
  submit_job(c, req, res, *spec, body);
  if (res.status == 201 && prefers_async(req.get_header_value("Prefer")))
    res.set_header("Preference-Applied", "respond-async");
}

}  // namespace hmpm::server::http

// test_ogc.cpp — the OGC API – Processes routes (landing page, conformance,
// the process list and description, execution) against a real in-process
// server, and that an execution is a job of the /jobs routes.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <set>
#include <thread>

#include "service_fixture.hpp"

namespace hmpm::server {
namespace {

using namespace hmpm::server::testing;

const char* const browser_accept =
    "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,*/*;q=0.8";

// One service on an ephemeral port for each test, with a client for it.
class OgcTest : public ServiceTest {
 protected:
  OgcTest() : ServiceTest("ogc") {}

  httplib::Result execute(const Json& request, const httplib::Headers& headers = {},
                          const std::string& process = "hmpm") {
    return client_->Post(("/processes/" + process + "/execution").c_str(), headers, request.dump(),
                         "application/json");
  }

  // The rel -> href map of a document's links.
  static std::map<std::string, std::string> links(const Json& doc) {
    std::map<std::string, std::string> out;
    for (const Json& l : doc.value("links", Json::array())) out[l["rel"]] = l["href"];
    return out;
  }

  // The `type` and error paths of a problem document, checking its status.
  static std::pair<std::string, std::vector<std::string>> problem(const httplib::Result& res,
                                                                  int status) {
    EXPECT_TRUE(res);
    if (!res) return {};
    EXPECT_EQ(res->status, status) << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json");
    const Json doc = json_of(res->body);
    std::vector<std::string> paths;
    for (const Json& e : doc.value("errors", Json::array())) paths.push_back(e["path"]);
    return {doc.value("type", ""), paths};
  }
};

TEST_F(OgcTest, LandingPageLinksConformanceProcessesAndJobs) {
  start();
  const Json landing = get_json("/");
  EXPECT_FALSE(landing.value("title", "").empty());
  EXPECT_FALSE(landing.value("description", "").empty());
  const auto rels = links(landing);
  EXPECT_EQ(rels.at("self"), "/");
  EXPECT_EQ(rels.at("http://www.opengis.net/def/rel/ogc/1.0/conformance"), "/conformance");
  EXPECT_EQ(rels.at("http://www.opengis.net/def/rel/ogc/1.0/processes"), "/processes");
  EXPECT_EQ(rels.at("http://www.opengis.net/def/rel/ogc/1.0/job-list"), "/jobs");
  for (const auto& [rel, href] : rels) {
    if (href != "/ui") get_json(href);  // every JSON link answers
  }
}

TEST_F(OgcTest, ABrowserIsSentToTheDashboardAndEveryOtherClientGetsJson) {
  start();
  for (const char* accept : {browser_accept, "text/html", "text/html, application/json",
                             "application/json;q=0.5, text/html"}) {
    auto res = client_->Get("/", {{"Accept", accept}});
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 303) << accept;
    EXPECT_EQ(res->get_header_value("Location"), "/ui");
  }
  for (const char* accept : {"", "*/*", "application/json", "text/html;q=0.5, application/json",
                             "application/json, text/html", "text/html;q=0"}) {
    auto res = client_->Get("/", {{"Accept", accept}});
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200) << accept;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/json") << accept;
    EXPECT_EQ(res->get_header_value("Vary"), "Accept");
  }
}

TEST_F(OgcTest, TheEncodingParameterFIsJsonOrHtmlForTheLandingPage) {
  start();
  for (const char* path :
       {"/?f=json", "/conformance?f=json", "/processes?f=json", "/processes/hmpm?f=json"}) {
    auto res = client_->Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 200) << path;
  }
  auto html = client_->Get("/?f=html");
  ASSERT_TRUE(html);
  EXPECT_EQ(html->status, 303);
  EXPECT_EQ(html->get_header_value("Location"), "/ui");
  EXPECT_EQ(problem(client_->Get("/processes?f=xml"), 400).first, "invalid-parameter");
}

TEST_F(OgcTest, ConformanceNamesCoreJsonJobListAndDismiss) {
  start();
  const Json doc = get_json("/conformance");
  std::set<std::string> classes;
  for (const Json& c : doc["conformsTo"]) classes.insert(c.get<std::string>());
  const std::string base = "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/";
  for (const char* c : {"core", "json", "ogc-process-description", "job-list", "dismiss"})
    EXPECT_TRUE(classes.count(base + c)) << c;
}

TEST_F(OgcTest, TheProcessListAndDescriptionOfferHmpmWithTheJobSchema) {
  start();
  const Json list = get_json("/processes");
  ASSERT_EQ(list["processes"].size(), 1u) << list.dump();
  const Json& summary = list["processes"][0];
  EXPECT_EQ(summary["id"], "hmpm");
  for (const char* key : {"title", "description", "version"})
    EXPECT_FALSE(summary.value(key, "").empty()) << key;
  EXPECT_EQ(summary["jobControlOptions"], Json::array({"async-execute"}));
  EXPECT_EQ(links(summary).at("self"), "/processes/hmpm");
  EXPECT_EQ(links(list).at("self"), "/processes");

  const Json process = get_json("/processes/hmpm");
  EXPECT_EQ(process["id"], "hmpm");
  EXPECT_EQ(links(process).at("http://www.opengis.net/def/rel/ogc/1.0/execute"),
            "/processes/hmpm/execution");
  ASSERT_EQ(process["inputs"].size(), 1u);
  EXPECT_EQ(process["inputs"]["spec"]["minOccurs"], 1);
  EXPECT_EQ(process["inputs"]["spec"]["schema"], json_of(read_file(HMPM_JOB_SCHEMA)));
  EXPECT_EQ(process["outputs"]["files"]["schema"]["type"], "array");
}

TEST_F(OgcTest, AnUnknownProcessIsNoSuchProcess) {
  start();
  const std::string type =
      "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/no-such-process";
  EXPECT_EQ(problem(client_->Get("/processes/other"), 404).first, type);
  const Json request{{"inputs", {{"spec", json_of(small_spec())}}}};
  EXPECT_EQ(problem(execute(request, {}, "other"), 404).first, type);
  EXPECT_TRUE(get_json("/jobs")["jobs"].empty());
}

TEST_F(OgcTest, AnExecutionIsAJobOfTheJobsRoutes) {
  start();
  const Json spec = json_of(small_spec("ogc-bar"));
  auto res = execute(Json{{"inputs", {{"spec", spec}}}}, {{"Prefer", "respond-async"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 201) << res->body;
  const Json created = json_of(res->body);
  const std::string id = created["jobID"];
  EXPECT_EQ(res->get_header_value("Location"), "/jobs/" + id);
  EXPECT_EQ(res->get_header_value("Preference-Applied"), "respond-async");
  EXPECT_EQ(created["type"], "process");
  EXPECT_EQ(created["processID"], "hmpm");
  EXPECT_EQ(created["status"], "accepted");
  EXPECT_EQ(created["name"], "ogc-bar");
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + id + "/spec").c_str())->body), spec);

  const Json done = poll_job(*client_, id, is_final, 60);
  ASSERT_EQ(done.value("status", ""), "successful") << done.dump();
  const Json results = get_json("/jobs/" + id + "/results");
  std::set<std::string> names;
  for (const Json& f : results["files"]) names.insert(f["name"].get<std::string>());
  EXPECT_TRUE(names.count("summary.json") && names.count("series.json"));
  const Json jobs = get_json("/jobs");
  ASSERT_EQ(jobs["jobs"].size(), 1u);
  EXPECT_EQ(jobs["jobs"][0]["jobID"], id);
  // OGC's job-list filters: every job is of process hmpm and type process.
  EXPECT_EQ(get_json("/jobs?processID=hmpm&type=process")["jobs"].size(), 1u);
  EXPECT_EQ(get_json("/jobs?processID=other,hmpm")["jobs"].size(), 1u);
  EXPECT_EQ(get_json("/jobs?processID=other")["jobs"].size(), 0u);
  EXPECT_EQ(get_json("/jobs?type=coverage")["jobs"].size(), 0u);
  res = client_->Delete(("/jobs/" + id).c_str());  // dismiss
  ASSERT_TRUE(res);
  EXPECT_EQ(json_of(res->body).value("status", ""), "dismissed");
}

TEST_F(OgcTest, AQualifiedValueCarriesTheSpecAndASynchronousWishIsRunAsynchronously) {
  start();
  const Json request{
      {"inputs", {{"spec", {{"value", json_of(small_spec())}, {"mediaType", "application/json"}}}}},
      {"outputs", {{"files", Json::object()}}},
      {"response", "document"}};
  auto res = execute(request, {{"Prefer", "wait=10"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 201) << res->body;
  EXPECT_FALSE(res->has_header("Preference-Applied"));
  EXPECT_EQ(json_of(res->body)["status"], "accepted");
}

TEST_F(OgcTest, AnInvalidSpecGetsTheErrorsOfPostJobsWithPathsIntoTheSpec) {
  start();
  Json spec = json_of(small_spec());
  spec["materials"]["bar"]["youngs_modulus"] = -1.0;
  spec["time"].erase("end");
  const auto [type, paths] = problem(execute(Json{{"inputs", {{"spec", spec}}}}), 400);
  EXPECT_EQ(type, "invalid-spec");
  EXPECT_FALSE(paths.empty());
  const auto direct = problem(client_->Post("/jobs", spec.dump(), "application/json"), 400);
  EXPECT_EQ(paths, direct.second);
  EXPECT_TRUE(get_json("/jobs")["jobs"].empty());
}

TEST_F(OgcTest, RequestsThatAreNotExecuteRequestsNameWhatIsWrong) {
  start();
  const Json spec = json_of(small_spec());
  std::string deep;
  for (int i = 0; i < 100; ++i) deep += "[";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"not json", ""},
      {"[1]", ""},
      {"{}", "/inputs"},
      {R"({"inputs": []})", "/inputs"},
      {R"({"inputs": {}})", "/inputs/spec"},
      {Json{{"inputs", {{"spec", spec}, {"mesh", 1}}}}.dump(), "/inputs/mesh"},
      {R"({"inputs": {"spec": {"href": "http://example.org/spec.json"}}})", "/inputs/spec/href"},
      {Json{{"inputs", {{"spec", spec}}}, {"subscriber", Json::object()}}.dump(), "/subscriber"},
      {Json{{"inputs", {{"spec", spec}}}, {"outputs", {{"vtu", 1}}}}.dump(), "/outputs/vtu"},
      {Json{{"inputs", {{"spec", spec}}}, {"response", "xml"}}.dump(), "/response"},
      {R"({"inputs": {"spec": )" + deep, ""},
  };
  for (const auto& [body, path] : cases) {
    auto res = client_->Post("/processes/hmpm/execution", body, "application/json");
    const auto [type, paths] = problem(res, 400);
    EXPECT_EQ(type, "invalid-execute-request") << body.substr(0, 80);
    EXPECT_EQ(paths, std::vector<std::string>{path}) << body.substr(0, 80);
  }
  EXPECT_TRUE(get_json("/jobs")["jobs"].empty());
}

TEST_F(OgcTest, ExecutionSharesIdempotencyAndTheQueueLimitWithPostJobs) {
  start();
  const Json request{{"inputs", {{"spec", json_of(small_spec())}}}};
  auto first = execute(request, {{"Idempotency-Key", "ogc-1"}});
  auto again = execute(request, {{"Idempotency-Key", "ogc-1"}});
  ASSERT_TRUE(first && again);
  ASSERT_EQ(again->status, 201) << again->body;
  EXPECT_EQ(again->get_header_value("Idempotent-Replayed"), "true");
  EXPECT_EQ(json_of(again->body)["jobID"], json_of(first->body)["jobID"]);
  Json other = request;
  other["inputs"]["spec"]["name"] = "another";
  EXPECT_EQ(problem(execute(other, {{"Idempotency-Key", "ogc-1"}}), 422).first,
            "idempotency-key-reused");
}

TEST_F(OgcTest, AFullQueueIs503AndTheTokenGuardsEveryOgcRoute) {
  start(/*max_queue=*/0, /*token=*/"s3cret");
  for (const char* path : {"/conformance", "/processes", "/processes/hmpm"})
    EXPECT_EQ(problem(client_->Get(path), 401).first, "unauthorized") << path;
  // The landing page holds links only and is open, so that a browser on a
  // server with a token still reaches the dashboard through it.
  auto landing = client_->Get("/", {{"Accept", "text/html"}});
  ASSERT_TRUE(landing);
  EXPECT_EQ(landing->status, 303);
  EXPECT_EQ(landing->get_header_value("Location"), "/ui");
  const Json request{{"inputs", {{"spec", json_of(small_spec())}}}};
  EXPECT_EQ(problem(execute(request), 401).first, "unauthorized");
  auto res = execute(request, {{"Authorization", "Bearer s3cret"}});
  EXPECT_EQ(problem(res, 503).first, "queue-full");
  EXPECT_FALSE(res->get_header_value("Retry-After").empty());
}

TEST_F(OgcTest, AllowListsTheOgcMethods) {
  start();
  for (const auto& [path, allow] : std::vector<std::pair<std::string, std::string>>{
           {"/", "GET, HEAD, OPTIONS"},
           {"/conformance", "GET, HEAD, OPTIONS"},
           {"/processes", "GET, HEAD, OPTIONS"},
           {"/processes/hmpm", "GET, HEAD, OPTIONS"},
           {"/processes/hmpm/execution", "POST, OPTIONS"}}) {
    auto res = client_->Put(path.c_str(), "{}", "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 405) << path;
    EXPECT_EQ(res->get_header_value("Allow"), allow) << path;
  }
}

}  // namespace
}  // namespace hmpm::server

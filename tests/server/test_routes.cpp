// test_routes.cpp — the HTTP routes against a real in-process server.
//
// Each test starts hmpm::server::Service on an ephemeral loopback port with
// its own database file and data folder (the fixture runs it on a thread and
// stops it in TearDown), then talks to it with httplib::Client — or with raw
// bytes where a request must be malformed on purpose.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "digest.hpp"
#include "hmpm/server/service.hpp"
#include "hmpm/server/store.hpp"
#include "job_log.hpp"
#include "support.hpp"

namespace hmpm::server {
namespace {

using namespace hmpm::server::testing;
using Clock = std::chrono::steady_clock;

class RoutesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    set_logging_enabled(false);
    dir_ = make_temp_dir("routes");
  }
  void TearDown() override {
    stop();
    std::filesystem::remove_all(dir_);
  }

  ServiceConfig config() const {
    ServiceConfig c;
    c.port = 0;
    c.db_path = dir_ / "db" / "hmpm.sqlite";
    c.workers = 1;
    c.threads_per_job = 1;
    c.progress_interval_s = 0.2;
    c.heartbeat_interval_s = 0.5;
    return c;
  }

  void start(ServiceConfig c) {
    service_ = std::make_unique<Service>(std::move(c));
    port_ = service_->bind();
    ASSERT_GT(port_, 0);
    thread_ = std::thread([this] { service_->run(); });
    const auto deadline = Clock::now() + std::chrono::seconds(5);
    while (!service_->is_running() && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_TRUE(service_->is_running());
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
    client_->set_read_timeout(30, 0);
  }
  void start() { start(config()); }

  void stop() {
    if (!service_) return;
    service_->stop();
    thread_.join();
    service_.reset();
  }

  // POST /jobs; returns the new id ("" and a test failure otherwise).
  std::string submit(const std::string& spec, const httplib::Headers& headers = {}) {
    auto res = client_->Post("/jobs", headers, spec, "application/json");
    EXPECT_TRUE(res);
    if (!res) return "";
    EXPECT_EQ(res->status, 201) << res->body;
    const Json doc = json_of(res->body);
    return doc.is_object() && doc.contains("jobID") ? doc["jobID"].get<std::string>() : "";
  }

  Json wait_until(const std::string& id, const std::string& status, double timeout_s = 60) {
    return poll_job(
        *client_, id, [&](const Json& d) { return d.value("status", "") == status; }, timeout_s);
  }

  // Submits a job that runs for hours and waits until a worker runs it.
  std::string submit_running(const std::string& name) {
    std::string id = submit(long_spec(name, 10000));
    EXPECT_EQ(wait_until(id, "running", 30).value("status", ""), "running");
    return id;
  }

  Json wait_final(const std::string& id, double timeout_s = 60) {
    return poll_job(*client_, id, is_final, timeout_s);
  }

  // Checks a problem document and returns it.
  static Json expect_problem(const httplib::Result& res, int status, const std::string& type) {
    EXPECT_TRUE(res);
    if (!res) return {};
    EXPECT_EQ(res->status, status) << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json");
    Json doc = json_of(res->body);
    EXPECT_TRUE(doc.is_object()) << res->body;
    if (!doc.is_object()) return {};
    EXPECT_EQ(doc.value("type", ""), type);
    EXPECT_EQ(doc.value("status", 0), status);
    EXPECT_FALSE(doc.value("title", "").empty());
    EXPECT_FALSE(doc.value("detail", "").empty());
    return doc;
  }

  std::filesystem::path dir_;
  std::unique_ptr<Service> service_;
  std::thread thread_;
  int port_ = 0;
  std::unique_ptr<httplib::Client> client_;
};

TEST_F(RoutesTest, WallTimeEstimateScalesWithTheServersCalibration) {
  ServiceConfig c = config();
  c.seconds_per_particle_step = 1e-3;  // a very slow machine
  start(c);
  const Json slow = json_of(client_->Post("/validate", small_spec("s"), "application/json")->body);
  EXPECT_EQ(slow["cost"]["calibrated"], true);
  EXPECT_EQ(slow["cost"]["seconds_per_particle_step"], 1e-3);
  const auto res = client_->Post("/jobs", small_spec("s"), "application/json");
  ASSERT_EQ(res->status, 201) << res->body;
  EXPECT_EQ(json_of(res->body)["cost"]["wall_seconds"], slow["cost"]["wall_seconds"]);
  // The model: at least one reference particle-step per step for this
  // 1D bar (13 particles of weight 1/4 plus the per-step overhead of 12).
  EXPECT_GT(slow["cost"]["wall_seconds"].get<double>(), 50 * 1e-3);
}

const std::regex rfc3339(R"(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}(\.\d+)?Z)");

TEST_F(RoutesTest, SubmitPollAndDownloadResults) {
  start();
  auto res = client_->Post("/jobs", small_spec("walk"), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 201) << res->body;
  const Json created = json_of(res->body);
  const std::string id = created["jobID"];
  EXPECT_TRUE(looks_like_uuid(id));
  EXPECT_EQ(res->get_header_value("Location"), "/jobs/" + id);
  EXPECT_EQ(created["status"], "accepted");
  EXPECT_EQ(created["progress"], 0);
  EXPECT_EQ(created["name"], "walk");
  EXPECT_TRUE(std::regex_match(created["created"].get<std::string>(), rfc3339));
  EXPECT_TRUE(created["started"].is_null());
  EXPECT_GT(created["cost"]["particles"].get<int>(), 0);
  std::set<std::string> rels;
  for (const auto& l : created["links"]) rels.insert(l["rel"].get<std::string>());
  EXPECT_EQ(rels, (std::set<std::string>{"self", "results", "events", "log"}));

  auto stored = client_->Get(("/jobs/" + id + "/spec").c_str());
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->body, small_spec("walk"));  // byte for byte

  const Json done = wait_final(id);
  ASSERT_EQ(done.value("status", ""), "successful") << done.dump();
  EXPECT_EQ(done["progress"], 100);
  EXPECT_EQ(done["attempts"], 1);
  for (const char* key : {"created", "started", "finished", "updated"}) {
    EXPECT_TRUE(std::regex_match(done[key].get<std::string>(), rfc3339)) << key;
  }

  res = client_->Get(("/jobs/" + id + "/results").c_str());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  const Json manifest = json_of(res->body);
  std::set<std::string> names;
  for (const Json& f : manifest["files"]) {
    const std::string name = f["name"];
    names.insert(name);
    EXPECT_EQ(f["href"], "/jobs/" + id + "/results/" + name);
    auto file = client_->Get(f["href"].get<std::string>().c_str());
    ASSERT_TRUE(file);
    ASSERT_EQ(file->status, 200) << name;
    EXPECT_EQ(f["size"].get<std::size_t>(), file->body.size()) << name;
    EXPECT_EQ(f["sha256"], sha256_hex(file->body)) << name;
    EXPECT_EQ(file->get_header_value("Content-Type"), f["media_type"]) << name;
    // A conditional request with the ETag is answered without the body.
    auto again = client_->Get(f["href"].get<std::string>().c_str(),
                              {{"If-None-Match", file->get_header_value("ETag")}});
    ASSERT_TRUE(again);
    EXPECT_EQ(again->status, 304);
  }
  EXPECT_TRUE(names.count("summary.json"));
  EXPECT_TRUE(names.count("series.json"));
  EXPECT_TRUE(names.count("series.csv"));
  // Without --data-dir the files live beside the database, one folder per
  // job holding the log and one folder per attempt (its claim's fencing
  // token; the first claim's is 1), and nothing else once the job has ended.
  EXPECT_EQ(service_->config().data_dir, dir_ / "db" / "results");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "db" / "results" / id / "attempt-1" / "series.json"));
  std::set<std::string> entries;
  for (const auto& e : std::filesystem::directory_iterator(dir_ / "db" / "results" / id))
    entries.insert(e.path().filename().string());
  EXPECT_EQ(entries, (std::set<std::string>{"attempt-1", "job.log"}));
}

// A runnable spec with something worth knowing: the 201 carries the
// warnings with JSON pointers, and the finished run's summary repeats them.
// The bar made saturated with a fluid far softer than the skeleton
// (E_oed Q = 3e4, far above the u-p stability limit 0.7 of docs/verification.md).
TEST_F(RoutesTest, SubmitReturnsTheSpecWarnings) {
  start();
  Json spec = json_of(small_spec("soft-fluid", 0.05));
  spec["materials"]["bar"]["density"] = 2000.0;
  spec["materials"]["bar"]["hydraulic"] = {
      {"porosity", 0.3}, {"hydraulic_conductivity", 1e-6}, {"fluid_bulk_modulus", 1.0}};
  auto res = client_->Post("/jobs", spec.dump(), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 201) << res->body;
  const Json created = json_of(res->body);
  ASSERT_EQ(created["warnings"].size(), 1u) << res->body;
  EXPECT_EQ(created["warnings"][0]["path"], "/materials/bar/hydraulic");
  EXPECT_NE(created["warnings"][0]["message"].get<std::string>().find("What to change"),
            std::string::npos);
  const std::string id = created["jobID"];
  ASSERT_EQ(wait_final(id).value("status", ""), "successful");
  // The status document carries them too, as in the 201.
  const Json status = json_of(client_->Get(("/jobs/" + id).c_str())->body);
  EXPECT_EQ(status["warnings"], created["warnings"]) << status.dump();
  auto summary = client_->Get(("/jobs/" + id + "/results/summary.json").c_str());
  ASSERT_TRUE(summary);
  ASSERT_EQ(summary->status, 200);
  const Json s = json_of(summary->body);
  ASSERT_EQ(s["warnings"].size(), 1u) << summary->body;
  EXPECT_NE(s["warnings"][0].get<std::string>().find("materials/bar/hydraulic"), std::string::npos);
  // Specs without warnings carry no "warnings" key.
  res = client_->Post("/jobs", small_spec("plain"), "application/json");
  ASSERT_TRUE(res);
  EXPECT_FALSE(json_of(res->body).contains("warnings"));
}

// A warning found during the run (pore pressure below cavitation: the bar
// saturated, nearly impermeable and pulled at its free end) reaches the
// job log and summary.json; the run still ends successful.
TEST_F(RoutesTest, RunWarningsReachTheJobLogAndTheSummary) {
  start();
  Json spec = json_of(small_spec("pulled", 0.05));
  spec["materials"]["bar"]["youngs_modulus"] = 1e7;
  spec["materials"]["bar"]["density"] = 2650.0;
  spec["materials"]["bar"]["hydraulic"] = {
      {"porosity", 0.3}, {"hydraulic_conductivity", 1e-9}, {"fluid_bulk_modulus", 2.2e9}};
  spec["bodies"][0].erase("initial");
  spec["tractions"] = Json::array({{{"particles", {{"box", {{"min", {0.9}}, {"max", {1.0}}}}}},
                                    {"face", "x+"},
                                    {"traction", {5e5}}}});
  spec["time"] = {{"end", 0.05}};
  auto res = client_->Post("/jobs", spec.dump(), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 201) << res->body;
  const std::string id = json_of(res->body)["jobID"];
  ASSERT_EQ(wait_final(id).value("status", ""), "successful");
  const std::string log = client_->Get(("/jobs/" + id + "/log").c_str())->body;
  EXPECT_NE(log.find("warning: during the run: pore pressure below cavitation"), std::string::npos)
      << log;
  const Json s = json_of(client_->Get(("/jobs/" + id + "/results/summary.json").c_str())->body);
  ASSERT_FALSE(s["warnings"].empty()) << s.dump();
  EXPECT_NE(s["warnings"].back().get<std::string>().find("below cavitation"), std::string::npos);
}

TEST_F(RoutesTest, HostileBodiesGetProblemDocumentsAndTheServerKeepsAnswering) {
  start();
  const std::vector<std::string> bodies{
      "this is not JSON", "", std::string(100000, '[') + std::string(100000, ']'),
      std::string(100000, '{'), std::string("\xff\xfe\x00\x01", 4)};
  for (const std::string& body : bodies) {
    const Json doc =
        expect_problem(client_->Post("/jobs", body, "application/json"), 400, "invalid-spec");
    ASSERT_TRUE(doc.contains("errors"));
    ASSERT_FALSE(doc["errors"].empty());
    EXPECT_TRUE(doc["errors"][0].contains("path"));
    EXPECT_TRUE(doc["errors"][0].contains("message"));
  }
  Json spec = json_of(small_spec());
  spec["materials"]["bar"]["youngs_modulus"] = -1.0;
  spec["time"].erase("end");
  const Json doc =
      expect_problem(client_->Post("/jobs", spec.dump(), "application/json"), 400, "invalid-spec");
  std::set<std::string> paths;
  for (const Json& e : doc["errors"]) paths.insert(e["path"].get<std::string>());
  EXPECT_TRUE(paths.count("/materials/bar/youngs_modulus")) << doc.dump();
  EXPECT_TRUE(paths.count("/time/end")) << doc.dump();

  expect_problem(client_->Get("/jobs/00000000-0000-4000-8000-000000000000"), 404, "not-found");
  expect_problem(client_->Get("/jobs/not-a-job"), 404, "not-found");
  expect_problem(client_->Get("/nothing/here"), 404, "not-found");
  expect_problem(client_->Put("/jobs", "{}", "application/json"), 405, "method-not-allowed");
  expect_problem(client_->Get("/jobs?status=bogus"), 400, "invalid-parameter");
  expect_problem(client_->Get("/jobs?limit=0"), 400, "invalid-parameter");
  auto health = client_->Get("/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  EXPECT_TRUE(json_of(client_->Get("/jobs")->body)["jobs"].empty());  // nothing was stored
}

// Allow on a 405 names exactly the methods the path serves: each one listed
// answers something other than 405, and the expected sets are complete.
// (Before the route table, every path but /jobs claimed "GET, DELETE".)
TEST_F(RoutesTest, AllowListsExactlyTheMethodsServed) {
  start();
  const std::string job = "/jobs/00000000-0000-4000-8000-000000000000";
  const std::string ensemble = "/ensembles/00000000-0000-4000-8000-000000000000";
  const std::vector<std::pair<std::string, std::string>> expected{
      {"/health", "GET, HEAD, OPTIONS"},
      {"/metrics", "GET, HEAD, OPTIONS"},
      {"/jobs", "GET, HEAD, POST, OPTIONS"},
      {job, "GET, HEAD, DELETE, OPTIONS"},
      {job + "/spec", "GET, HEAD, OPTIONS"},
      {job + "/results", "GET, HEAD, OPTIONS"},
      {job + "/results/summary.json", "GET, HEAD, OPTIONS"},
      {job + "/events", "GET, HEAD, OPTIONS"},
      {"/ensembles", "GET, HEAD, POST, OPTIONS"},
      {ensemble, "GET, HEAD, DELETE, OPTIONS"},
      {ensemble + "/cancel", "POST, OPTIONS"},
      {ensemble + "/results", "GET, HEAD, OPTIONS"},
      {ensemble + "/results/statistics.json", "GET, HEAD, OPTIONS"},
  };
  for (const auto& [path, allow] : expected) {
    auto res = client_->Patch(path.c_str(), "{}", "application/json");
    expect_problem(res, 405, "method-not-allowed");
    EXPECT_EQ(res->get_header_value("Allow"), allow) << path;
    std::stringstream methods(allow);
    for (std::string method; std::getline(methods >> std::ws, method, ',');) {
      const std::string body = method == "POST" ? "{}" : "";
      const std::string answer =
          raw_http(port_,
                   method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n" +
                       "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body,
                   5.0);
      EXPECT_NE(raw_status(answer), 405) << method << " " << path << " is listed in Allow";
      EXPECT_NE(raw_status(answer), 0) << method << " " << path;
    }
  }
}

TEST_F(RoutesTest, BodiesWithoutLengthOrOverTheLimitAreRefused) {
  ServiceConfig c = config();
  c.max_body_bytes = std::size_t{64} * 1024;
  start(c);
  std::string res =
      raw_http(port_, "POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n{}");
  EXPECT_EQ(raw_status(res), 411) << res;
  EXPECT_EQ(json_of(raw_body(res)).value("type", ""), "length-required");
  res = raw_http(
      port_,
      "POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\nConnection: "
      "close\r\n\r\n2\r\n{}\r\n0\r\n\r\n");
  EXPECT_EQ(raw_status(res), 411) << res;
  res = raw_http(
      port_,
      "POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: abc\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(res), 400) << res;

  const std::string big(std::size_t{200} * 1024, ' ');
  expect_problem(client_->Post("/jobs", big, "application/json"), 413, "payload-too-large");
  res = raw_http(port_, "POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: " +
                            std::to_string(big.size()) +
                            "\r\nExpect: 100-continue\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(res), 413) << res;  // refused before the body is sent
  EXPECT_EQ(client_->Get("/health")->status, 200);
}

TEST_F(RoutesTest, TokenGuardsEverythingButHealth) {
  ServiceConfig c = config();
  c.token = "s3cret";
  start(c);
  EXPECT_EQ(client_->Get("/health")->status, 200);
  auto res = client_->Get("/jobs");
  expect_problem(res, 401, "unauthorized");
  EXPECT_EQ(res->get_header_value("WWW-Authenticate").rfind("Bearer", 0), 0u);
  expect_problem(client_->Get("/jobs", {{"Authorization", "Bearer wrong"}}), 401, "unauthorized");
  expect_problem(client_->Get("/jobs", {{"Authorization", "Bearer s3cre"}}), 401, "unauthorized");
  expect_problem(client_->Get("/metrics"), 401, "unauthorized");
  expect_problem(client_->Post("/jobs", small_spec(), "application/json"), 401, "unauthorized");
  expect_problem(client_->Delete("/jobs/00000000-0000-4000-8000-000000000000"), 401,
                 "unauthorized");
  res = client_->Get("/jobs", {{"Authorization", "bearer s3cret"}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_TRUE(json_of(res->body)["jobs"].empty());  // the unauthorised POST stored nothing
  const std::string id = submit(small_spec(), {{"Authorization", "Bearer s3cret"}});
  EXPECT_FALSE(id.empty());
}

TEST_F(RoutesTest, ResultNamesOutsideTheManifestAreRefused) {
  start();
  const std::string id = submit(small_spec());
  ASSERT_EQ(wait_final(id).value("status", ""), "successful");
  const std::string base = "/jobs/" + id + "/results/";
  const std::vector<std::string> names{"..%2F..%2Fdb%2Fhmpm.sqlite", "%2E%2E%2Fsummary.json",
                                       "nope.json", "..%2F" + id + "%2Fsummary.json"};
  for (const std::string& name : names) {
    expect_problem(client_->Get((base + name).c_str()), 404, "not-found");
  }
  const std::string res = raw_http(
      port_,
      "GET " + base +
          "../../../db/hmpm.sqlite HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(res), 404) << res;
  EXPECT_EQ(client_->Get((base + "summary.json").c_str())->status, 200);
}

TEST_F(RoutesTest, CancelDismissesTheRunningJobWithinASecondAndTheWorkerTakesTheNext) {
  start();
  const std::string long_id = submit(long_spec("long", 10000));
  ASSERT_EQ(wait_until(long_id, "running", 30).value("status", ""), "running");
  const std::string next_id = submit(small_spec("next"));
  expect_problem(client_->Get(("/jobs/" + next_id + "/results").c_str()), 404, "result-not-ready");
  expect_problem(client_->Get(("/jobs/" + long_id + "/results").c_str()), 404, "result-not-ready");

  const auto t0 = Clock::now();
  auto res = client_->Delete(("/jobs/" + long_id).c_str());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(json_of(res->body)["status"], "dismissed");
  // The worker is free again within a second: it has started the next job.
  const Json next = poll_job(
      *client_, next_id, [](const Json& d) { return d.value("status", "") != "accepted"; }, 1.0);
  EXPECT_NE(next.value("status", ""), "accepted")
      << "worker still busy after " << std::chrono::duration<double>(Clock::now() - t0).count()
      << " s";
  EXPECT_EQ(wait_final(next_id).value("status", ""), "successful");
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + long_id).c_str())->body)["status"], "dismissed");
  expect_problem(client_->Get(("/jobs/" + long_id + "/results").c_str()), 410, "job-dismissed");
  EXPECT_FALSE(std::filesystem::exists(service_->config().data_dir / long_id));
  // Dismissing a finished job removes its files too; dismissing again is harmless.
  EXPECT_EQ(client_->Delete(("/jobs/" + next_id).c_str())->status, 200);
  EXPECT_EQ(client_->Delete(("/jobs/" + next_id).c_str())->status, 200);
  EXPECT_FALSE(std::filesystem::exists(service_->config().data_dir / next_id));
}

TEST_F(RoutesTest, IdempotencyKeyReturnsTheOriginalJob) {
  start();
  const httplib::Headers key{{"Idempotency-Key", "abc-123"}};
  const std::string id = submit(small_spec("once"), key);
  auto res = client_->Post("/jobs", key, small_spec("once"), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 201);
  EXPECT_EQ(json_of(res->body)["jobID"], id);
  EXPECT_EQ(res->get_header_value("Idempotent-Replayed"), "true");
  const Json conflict =
      expect_problem(client_->Post("/jobs", key, small_spec("twice"), "application/json"), 422,
                     "idempotency-key-reused");
  EXPECT_EQ(conflict.value("jobID", ""), id);
  EXPECT_EQ(json_of(client_->Get("/jobs")->body)["jobs"].size(), 1u);
}

TEST_F(RoutesTest, FullQueueAnswers503WithRetryAfter) {
  ServiceConfig c = config();
  c.max_queue = 1;
  start(c);
  const std::string long_id = submit_running("long");
  submit(small_spec("waits"));
  auto res = client_->Post("/jobs", small_spec("refused"), "application/json");
  expect_problem(res, 503, "queue-full");
  EXPECT_FALSE(res->get_header_value("Retry-After").empty());
  client_->Delete(("/jobs/" + long_id).c_str());
}

TEST_F(RoutesTest, EventsStreamProgressAndTheFinalState) {
  start();
  const std::string id = submit(long_spec("streamed", 20));
  std::string stream;
  auto res =
      client_->Get(("/jobs/" + id + "/events").c_str(), [&](const char* data, std::size_t n) {
        stream.append(data, n);
        return stream.size() < (1 << 20);
      });
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Type"), "text/event-stream");
  EXPECT_NE(stream.find("event: progress\n"), std::string::npos) << stream.substr(0, 500);
  const auto done = stream.find("event: done\ndata: ");
  ASSERT_NE(done, std::string::npos) << stream.substr(0, 2000);
  const Json final_doc =
      json_of(stream.substr(done + 18, stream.find('\n', done + 18) - done - 18));
  EXPECT_EQ(final_doc.value("status", ""), "successful");
  EXPECT_EQ(final_doc.value("jobID", ""), id);
}

TEST_F(RoutesTest, EventStreamsAreCapped) {
  ServiceConfig c = config();
  c.max_event_streams = 0;
  start(c);
  const std::string id = submit(small_spec());
  auto res = client_->Get(("/jobs/" + id + "/events").c_str());
  expect_problem(res, 503, "too-many-streams");
  EXPECT_FALSE(res->get_header_value("Retry-After").empty());
  expect_problem(client_->Get("/jobs/00000000-0000-4000-8000-000000000000/events"), 404,
                 "not-found");
}

TEST_F(RoutesTest, EventStreamsSendHeartbeatsWhenNothingChanges) {
  start();  // one worker, kept busy, so the streamed job waits without any change
  const std::string busy = submit(long_spec("busy", 10000));
  const std::string id = submit(small_spec("quiet"));
  std::string stream;
  const auto t0 = Clock::now();
  client_->Get(("/jobs/" + id + "/events").c_str(), [&](const char* data, std::size_t n) {
    stream.append(data, n);
    return stream.find(": heartbeat\n") == std::string::npos &&
           Clock::now() - t0 < std::chrono::seconds(10);
  });
  EXPECT_NE(stream.find(": heartbeat\n"), std::string::npos) << stream.substr(0, 1000);
  EXPECT_NE(stream.find("\"status\":\"accepted\""), std::string::npos) << stream.substr(0, 1000);
  EXPECT_EQ(client_->Delete(("/jobs/" + busy).c_str())->status, 200);
}

// A failing store is the server's trouble, not a bug: 503 store-unavailable
// with Retry-After (507 when for want of space), and no internal text.
TEST_F(RoutesTest, StoreFailuresAre503WithRetryAfterWithoutInternalText) {
  start();
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir_ / "db" / "hmpm.sqlite").c_str(), &db), SQLITE_OK);
  // The server's own connection may hold the file's lock for a moment (its
  // queue poll and retention sweep): wait for it rather than fail to drop.
  sqlite3_busy_timeout(db, 10000);
  ASSERT_EQ(sqlite3_exec(db, "DROP TABLE results; DROP TABLE jobs;", nullptr, nullptr, nullptr),
            SQLITE_OK)
      << sqlite3_errmsg(db);
  sqlite3_close(db);
  auto res = client_->Get("/jobs");
  expect_problem(res, 503, "store-unavailable");
  EXPECT_EQ(res->get_header_value("Retry-After"), "10");
  EXPECT_EQ(res->body.find("no such table"), std::string::npos) << res->body;
  for (const auto& [name, value] : res->headers) {
    EXPECT_EQ(value.find("no such table"), std::string::npos) << name << ": " << value;
  }
  EXPECT_EQ(client_->Get("/health")->status, 200);  // the file itself is still readable
}

TEST_F(RoutesTest, ListFiltersAndMetricsCount) {
  start();
  const std::string a = submit(small_spec("a"));
  ASSERT_EQ(wait_final(a).value("status", ""), "successful");
  submit(small_spec("b"));
  auto res = client_->Get("/jobs?status=successful&limit=10");
  ASSERT_TRUE(res);
  const Json list = json_of(res->body);
  ASSERT_GE(list["jobs"].size(), 1u);
  for (const Json& j : list["jobs"]) EXPECT_EQ(j["status"], "successful");
  EXPECT_EQ(json_of(client_->Get("/jobs?limit=1")->body)["jobs"].size(), 1u);
  EXPECT_EQ(json_of(client_->Get("/jobs?status=accepted,running,successful")->body)["jobs"].size(),
            2u);

  // cpp-httplib calls the logger, which counts requests, after the response
  // is written: the client can see the second 201 before it is counted, so
  // poll briefly (bounded) for the count instead of reading it once.
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  do {
    res = client_->Get("/metrics");
    ASSERT_TRUE(res);
  } while (res->body.find("hmpm_http_requests_total{code=\"201\"} 2") == std::string::npos &&
           Clock::now() < deadline);
  EXPECT_EQ(res->status, 200);
  EXPECT_NE(res->body.find("hmpm_jobs{status=\"successful\"} "), std::string::npos) << res->body;
  EXPECT_NE(res->body.find("hmpm_queue_length "), std::string::npos);
  EXPECT_NE(res->body.find("hmpm_job_duration_seconds_count "), std::string::npos);
  EXPECT_NE(res->body.find("hmpm_http_requests_total{code=\"201\"} 2"), std::string::npos)
      << res->body;
}

TEST_F(RoutesTest, StopRequeuesTheRunningJobAndTheNextStartFinishesIt) {
  start();
  const std::string id = submit(long_spec("interrupted", 100));
  ASSERT_EQ(wait_until(id, "running", 30).value("status", ""), "running");
  const auto t0 = Clock::now();
  stop();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 5.0);
  {
    const auto store = open_sqlite_store(config().db_path);
    const auto job = store->find(id);
    ASSERT_TRUE(job);
    EXPECT_EQ(job->status, JobStatus::accepted);
    EXPECT_EQ(job->attempts, 0);  // a graceful stop is not the job's fault
  }
  start();
  const Json done = wait_final(id, 90);
  EXPECT_EQ(done.value("status", ""), "successful") << done.dump();
  EXPECT_EQ(done.value("attempts", 0), 1);
  // One log across both runs: the stop, then the second run to its end.
  const std::string log = client_->Get(("/jobs/" + id + "/log").c_str())->body;
  const auto stopped = log.find("the server is shutting down; queued again");
  ASSERT_NE(stopped, std::string::npos) << log;
  EXPECT_NE(log.find("started", stopped), std::string::npos) << log;
  EXPECT_NE(log.find("successful after", stopped), std::string::npos) << log;
}

// The heartbeat renews the lease of a running job: with a 0.3 s lease, the
// job is still held long after the lease would have lapsed unrenewed.
TEST_F(RoutesTest, TheHeartbeatKeepsARunningJobsLeaseLive) {
  ServiceConfig c = config();
  c.lease_s = 0.3;
  start(c);
  const std::string id = submit_running("leased");
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir_ / "db" / "hmpm.sqlite").c_str(), &db), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db,
                               "SELECT lease_expires_ms - CAST((julianday('now') - 2440587.5) * "
                               "86400000 AS INTEGER), owner FROM jobs WHERE id = ?1",
                               -1, &stmt, nullptr),
            SQLITE_OK);
  sqlite3_bind_text(stmt, 1, id.c_str(), -1, SQLITE_TRANSIENT);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
  const auto remaining_ms = sqlite3_column_int64(stmt, 0);
  const std::string owner = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 1));
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  EXPECT_GT(remaining_ms, 0) << "the lease lapsed while the job ran";
  EXPECT_LE(remaining_ms, 300);
  EXPECT_FALSE(owner.empty());
  EXPECT_EQ(client_->Delete(("/jobs/" + id).c_str())->status, 200);
}

TEST_F(RoutesTest, WallTimeLimitFailsTheJobWithAReason) {
  ServiceConfig c = config();
  c.job_wall_time_s = 0.5;
  start(c);
  const std::string id = submit(long_spec("too-long", 10000));
  const Json done = wait_final(id, 30);
  EXPECT_EQ(done.value("status", ""), "failed") << done.dump();
  EXPECT_FALSE(done.value("reason", "").empty()) << done.dump();
  EXPECT_FALSE(done.value("message", "").empty());
}

// --- Issue 19: the job lifecycle, logs, names, query parameters, id prefixes,
// validation and the dashboard.

TEST_F(RoutesTest, CancelStopsARunningJobAndKeepsWhatItWrote) {
  start();
  const std::string id = submit_running("to-cancel");
  const std::string queued = submit(long_spec("queued", 10000));
  auto res = client_->Post(("/jobs/" + id + "/cancel").c_str());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  EXPECT_EQ(json_of(res->body)["status"], "dismissed");
  // The files it wrote stay downloadable: at least summary.json.
  res = client_->Get(("/jobs/" + id + "/results").c_str());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const Json manifest = json_of(res->body);
  EXPECT_EQ(manifest["status"], "dismissed");
  std::set<std::string> names;
  for (const Json& f : manifest["files"]) names.insert(f["name"].get<std::string>());
  ASSERT_TRUE(names.count("summary.json")) << res->body;
  res = client_->Get(("/jobs/" + id + "/results/summary.json").c_str());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(json_of(res->body)["status"], "dismissed") << res->body;  // the run's own word
  // The worker moved on to the queued job; cancelling that one works while queued or running.
  res = client_->Post(("/jobs/" + queued + "/cancel").c_str());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202) << res->body;
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + queued).c_str())->body)["status"], "dismissed");
  // Once ended: 409, nothing changes.
  const Json again =
      expect_problem(client_->Post(("/jobs/" + id + "/cancel").c_str()), 409, "job-finished");
  EXPECT_EQ(again.value("jobStatus", ""), "dismissed");
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + id + "/results").c_str())->body)["files"],
            manifest["files"]);
  // DELETE still dismisses and deletes the results, also of a cancelled job.
  EXPECT_EQ(client_->Delete(("/jobs/" + id).c_str())->status, 200);
  expect_problem(client_->Get(("/jobs/" + id + "/results").c_str()), 410, "job-dismissed");
  EXPECT_FALSE(std::filesystem::exists(service_->config().data_dir / id));
}

TEST_F(RoutesTest, CancellingAFinishedJobIs409AndChangesNothing) {
  start();
  const std::string id = submit(small_spec("done"));
  ASSERT_EQ(wait_final(id).value("status", ""), "successful");
  const std::string before = client_->Get(("/jobs/" + id + "/results").c_str())->body;
  const Json problem =
      expect_problem(client_->Post(("/jobs/" + id + "/cancel").c_str()), 409, "job-finished");
  EXPECT_EQ(problem.value("jobStatus", ""), "successful");
  EXPECT_EQ(problem.value("jobID", ""), id);
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + id).c_str())->body)["status"], "successful");
  EXPECT_EQ(client_->Get(("/jobs/" + id + "/results").c_str())->body, before);
  EXPECT_EQ(client_->Get(("/jobs/" + id + "/results/summary.json").c_str())->status, 200);
  expect_problem(client_->Post("/jobs/00000000-0000-4000-8000-000000000000/cancel"), 404,
                 "not-found");
}

TEST_F(RoutesTest, RetentionPurgesOldEndedJobsWithTheirFilesAndTheyAre404) {
  using std::chrono::hours;
  start();
  const std::string done = submit(small_spec("old-done"));
  ASSERT_EQ(wait_final(done).value("status", ""), "successful");
  const std::string running = submit_running("still-running");
  const std::filesystem::path data = service_->config().data_dir;
  ASSERT_TRUE(std::filesystem::exists(data / done / "attempt-1" / "summary.json"));
  // A folder a crash left behind (no job), and one that is not a job's.
  const std::string orphan = "0123abcd-0000-4000-8000-000000000000";
  std::filesystem::create_directories(data / orphan);
  std::filesystem::create_directories(data / "not-a-job");
  const auto now = std::chrono::system_clock::now();

  // The default keeps ended jobs 30 days: 29 days on, nothing goes.
  EXPECT_TRUE(service_->purge_expired(now + hours(24 * 29)).empty());
  EXPECT_EQ(client_->Get(("/jobs/" + done).c_str())->status, 200);
  EXPECT_TRUE(std::filesystem::exists(data / done));

  // 31 days on: the finished job and its folder go; the running one stays.
  EXPECT_EQ(service_->purge_expired(now + hours(24 * 31)), std::vector<std::string>{done});
  expect_problem(client_->Get(("/jobs/" + done).c_str()), 404, "not-found");
  expect_problem(client_->Get(("/jobs/" + done + "/results").c_str()), 404, "not-found");
  EXPECT_FALSE(std::filesystem::exists(data / done));
  EXPECT_FALSE(std::filesystem::exists(data / orphan));
  EXPECT_TRUE(std::filesystem::exists(data / "not-a-job"));
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + running).c_str())->body)["status"], "running");
  EXPECT_TRUE(std::filesystem::exists(data / running));
  const Json list = json_of(client_->Get("/jobs")->body);
  ASSERT_TRUE(list.contains("jobs")) << list.dump();
  ASSERT_EQ(list["jobs"].size(), 1u);
  EXPECT_EQ(list["jobs"][0]["jobID"], running);
}

TEST_F(RoutesTest, RetainDaysZeroKeepsEndedJobsForever) {
  ServiceConfig c = config();
  c.retain_days = 0;
  start(c);
  const std::string done = submit(small_spec("kept"));
  ASSERT_EQ(wait_final(done).value("status", ""), "successful");
  EXPECT_TRUE(
      service_->purge_expired(std::chrono::system_clock::now() + std::chrono::hours(24 * 3650))
          .empty());
  EXPECT_EQ(client_->Get(("/jobs/" + done + "/results/summary.json").c_str())->status, 200);
}

TEST_F(RoutesTest, TheJobLogIsTextReadableWhileItRunsAndEndsWithTheOutcome) {
  start();
  const std::string id = submit_running("logged");
  std::string log;
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  do {  // progress lines: every 10 % or 10 s
    auto res = client_->Get(("/jobs/" + id + "/log").c_str());
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200);
    EXPECT_EQ(res->get_header_value("Content-Type").rfind("text/plain", 0), 0u);
    log = res->body;
    if (log.find("progress") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  } while (Clock::now() < deadline);
  EXPECT_NE(log.find("attempt 1 started"), std::string::npos) << log;
  EXPECT_NE(log.find("progress 0 %"), std::string::npos) << log;
  ASSERT_EQ(client_->Post(("/jobs/" + id + "/cancel").c_str())->status, 202);
  log = client_->Get(("/jobs/" + id + "/log").c_str())->body;
  EXPECT_NE(log.find("cancelled by the client while running"), std::string::npos) << log;
  EXPECT_NE(log.find("result files kept"), std::string::npos) << log;

  const std::string done = submit(small_spec("logged-done"));
  ASSERT_EQ(wait_final(done).value("status", ""), "successful");
  log = client_->Get(("/jobs/" + done + "/log").c_str())->body;
  EXPECT_NE(log.find("progress 100 %"), std::string::npos) << log;
  EXPECT_NE(log.find("successful after"), std::string::npos) << log;
  // The log is not a result file.
  EXPECT_EQ(client_->Get(("/jobs/" + done + "/results").c_str())->body.find("job.log"),
            std::string::npos);
}

TEST_F(RoutesTest, ListItemsCarryNamesAndTheNameFilterSelects) {
  start();
  const std::string a = submit(small_spec("terzaghi"));
  const std::string b = submit(small_spec("other"));
  const std::string a2 = submit(small_spec("terzaghi"));
  const Json all = json_of(client_->Get("/jobs")->body);
  ASSERT_EQ(all["jobs"].size(), 3u);
  EXPECT_EQ(all["jobs"][1]["name"], "other");
  const Json named = json_of(client_->Get("/jobs?name=terzaghi")->body);
  ASSERT_EQ(named["jobs"].size(), 2u) << named.dump();
  EXPECT_EQ(named["jobs"][0]["jobID"], a2);
  EXPECT_EQ(named["jobs"][1]["jobID"], a);
  EXPECT_EQ(json_of(client_->Get("/jobs?name=nobody")->body)["jobs"].size(), 0u);
  EXPECT_EQ(json_of(client_->Get("/jobs?name=other&status=accepted,running,successful")
                        ->body)["jobs"][0]["jobID"],
            b);
}

TEST_F(RoutesTest, UnknownQueryParametersAre400NamingTheAcceptedOnes) {
  start();
  const std::string id = submit(small_spec("q"));
  Json p = expect_problem(client_->Get("/jobs?nmae=x"), 400, "invalid-parameter");
  EXPECT_EQ(p["errors"][0]["path"], "nmae");
  EXPECT_EQ(p["accepted"], Json::array({"status", "name", "limit", "processID", "type"}));
  EXPECT_NE(p.value("detail", "").find("status, name, limit"), std::string::npos);
  p = expect_problem(client_->Get(("/jobs/" + id + "?verbose=1").c_str()), 400,
                     "invalid-parameter");
  EXPECT_EQ(p["accepted"], Json::array());
  expect_problem(client_->Get("/health?x=1"), 400, "invalid-parameter");
  expect_problem(client_->Post("/jobs?priority=high", small_spec(), "application/json"), 400,
                 "invalid-parameter");
  expect_problem(client_->Get(("/jobs/" + id + "/results?zip=1").c_str()), 400,
                 "invalid-parameter");
  EXPECT_EQ(json_of(client_->Get("/jobs")->body)["jobs"].size(), 1u);  // nothing was queued
}

TEST_F(RoutesTest, ShortIdPrefixesNameOneJobAndAmbiguousOnesAreRefused) {
  // Two jobs whose ids share their first 8 characters, stored before the start.
  {
    std::filesystem::create_directories(config().db_path.parent_path());
    auto store = open_sqlite_store(config().db_path);
    for (const char* id :
         {"abcdef01-0000-4000-8000-000000000001", "abcdef01-0000-4000-8000-000000000002"}) {
      NewJob j;
      j.id = id;
      j.name = "twin";
      j.spec = small_spec("twin");
      ASSERT_EQ(store->submit(j, 10).outcome, SubmitOutcome::created);
    }
  }
  start();
  const std::string id = submit(small_spec("short"));
  ASSERT_EQ(wait_final(id).value("status", ""), "successful");
  for (const std::size_t n : {4u, 8u, 13u}) {
    const std::string ref = id.substr(0, n);
    auto res = client_->Get(("/jobs/" + ref).c_str());
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << ref << ": " << res->body;
    EXPECT_EQ(json_of(res->body)["jobID"], id);
  }
  const std::string short_id = id.substr(0, 8);
  EXPECT_EQ(client_->Get(("/jobs/" + short_id + "/results/summary.json").c_str())->status, 200);
  EXPECT_EQ(client_->Get(("/jobs/" + short_id + "/log").c_str())->status, 200);
  EXPECT_EQ(client_->Get(("/jobs/" + short_id + "/spec").c_str())->status, 200);
  const Json p = expect_problem(client_->Get("/jobs/abcdef01"), 409, "ambiguous-id");
  EXPECT_EQ(p["candidates"], Json::array({"abcdef01-0000-4000-8000-000000000001",
                                          "abcdef01-0000-4000-8000-000000000002"}));
  expect_problem(client_->Delete("/jobs/abcdef01"), 409, "ambiguous-id");
  EXPECT_EQ(client_->Get("/jobs/abcdef01-0000-4000-8000-000000000002")->status, 200);
  expect_problem(client_->Get("/jobs/0000"), 404, "not-found");
  expect_problem(client_->Get("/jobs/abc"), 404, "not-found");  // fewer than 4 characters
  EXPECT_EQ(client_->Delete(("/jobs/" + short_id).c_str())->status, 200);
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + id).c_str())->body)["status"], "dismissed");
}

// Issue 22 items 6 and 7: a job over a limit of the server is refused at
// submit (and by /validate) with 422 limit-exceeded naming the limit, its
// value, the job's estimate and the option; nothing is stored.
TEST_F(RoutesTest, JobOverALimitIsRefusedNamingTheLimitAndItsOption) {
  ServiceConfig c = config();
  c.max_particle_steps = 1000;  // the small spec has 13 particles x 50 steps = 650
  c.max_job_memory = 1 << 20;   // below the estimate's 16 MiB process base
  start(c);
  const std::string spec = small_spec("small", 0.1);  // 100 steps: 1300 particle-steps
  for (const char* path : {"/jobs", "/validate"}) {
    auto res = client_->Post(path, spec, "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 422) << path << ": " << res->body;
    const Json doc = json_of(res->body);
    EXPECT_EQ(doc["type"], "limit-exceeded");
    ASSERT_EQ(doc["limits"].size(), 2u) << res->body;
    EXPECT_EQ(doc["limits"][0]["limit"], "max_particle_steps");
    EXPECT_EQ(doc["limits"][0]["option"], "--max-particle-steps");
    EXPECT_EQ(doc["limits"][0]["value"], 1000.0);
    EXPECT_EQ(doc["limits"][0]["estimate"], 1300.0);
    EXPECT_EQ(doc["limits"][1]["limit"], "max_job_memory");
    EXPECT_EQ(doc["limits"][1]["option"], "--max-job-memory");
    EXPECT_NE(doc["detail"].get<std::string>().find("--max-particle-steps"), std::string::npos);
  }
  EXPECT_EQ(json_of(client_->Get("/jobs")->body)["numberReturned"], 0);
}

TEST_F(RoutesTest, FullQueueIsAnsweredBeforeTheSpecIsRead) {
  ServiceConfig c = config();
  c.max_queue = 0;
  start(c);
  // Not even JSON: a 503 queue-full, not a 400, shows nothing was parsed.
  auto res = client_->Post("/jobs", "{not json", "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 503) << res->body;
  EXPECT_EQ(json_of(res->body)["type"], "queue-full");
}

TEST_F(RoutesTest, ValidateAnswersValidWithWarningsAndCostOrTheInvalidSpecProblem) {
  start();
  Json spec = json_of(small_spec("check", 0.05));
  spec["materials"]["bar"]["density"] = 2000.0;
  spec["materials"]["bar"]["hydraulic"] = {
      {"porosity", 0.3}, {"hydraulic_conductivity", 1e-6}, {"fluid_bulk_modulus", 1.0}};
  auto res = client_->Post("/validate", spec.dump(), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/json");
  Json doc = json_of(res->body);
  EXPECT_EQ(doc["valid"], true);
  ASSERT_EQ(doc["warnings"].size(), 1u);
  EXPECT_EQ(doc["warnings"][0]["path"], "/materials/bar/hydraulic");
  EXPECT_EQ(doc["cost"]["particles"], 13);
  EXPECT_EQ(doc["cost"]["steps"], 50);
  EXPECT_GT(doc["cost"]["dt"].get<double>(), 0.0);
  res = client_->Post("/validate", small_spec("plain"), "application/json");
  EXPECT_EQ(json_of(res->body)["warnings"], Json::array());
  // The cost is the one the job gets.
  const std::string id = submit(small_spec("plain"));
  EXPECT_EQ(json_of(client_->Get(("/jobs/" + id).c_str())->body)["cost"],
            json_of(res->body)["cost"]);
  // With the expected wall time of each scheme, from the server's
  // calibration (the built-in default here: the fixture measures none).
  const Json cost = json_of(res->body)["cost"];
  EXPECT_EQ(cost["scheme"], "explicit");
  EXPECT_GT(cost["wall_seconds"].get<double>(), 0.0);
  EXPECT_EQ(cost["calibrated"], false);
  ASSERT_EQ(cost["schemes"].size(), 3u);
  EXPECT_EQ(cost["schemes"][0]["scheme"], "explicit");
  EXPECT_EQ(cost["schemes"][0]["steps"], cost["steps"]);
  EXPECT_EQ(cost["schemes"][0]["wall_seconds"], cost["wall_seconds"]);
  EXPECT_EQ(cost["schemes"][2]["scheme"], "quasi_static");

  spec["materials"]["bar"]["youngs_modulus"] = -1;
  Json p = expect_problem(client_->Post("/validate", spec.dump(), "application/json"), 400,
                          "invalid-spec");
  ASSERT_FALSE(p["errors"].empty());
  EXPECT_EQ(p["errors"][0]["path"], "/materials/bar/youngs_modulus");
  EXPECT_FALSE(p["errors"][0].value("message", "").empty());
  p = expect_problem(client_->Post("/validate", "{not json", "application/json"), 400,
                     "invalid-spec");
  EXPECT_EQ(p["errors"][0]["path"], "");
  EXPECT_EQ(json_of(client_->Get("/jobs")->body)["jobs"].size(), 1u);  // validate queues nothing
}

TEST_F(RoutesTest, TheDashboardIsServedWithoutATokenAndNotCached) {
  ServiceConfig c = config();
  c.token = "s3cret";
  start(c);
  for (const char* path : {"/ui", "/ui/", "/ui/index.html"}) {
    auto res = client_->Get(path);
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << path;
    EXPECT_EQ(res->get_header_value("Content-Type"), "text/html; charset=utf-8");
    EXPECT_EQ(res->get_header_value("Cache-Control"), "no-cache");
    EXPECT_EQ(res->body,
              read_file(std::filesystem::path(HMPM_SOURCE_DIR) / "server/ui/index.html"));
  }
  auto res = client_->Get("/ui/app.js");
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
  res = client_->Get("/ui/style.css");
  EXPECT_EQ(res->get_header_value("Content-Type"), "text/css; charset=utf-8");
  res = client_->Get("/ui/examples/index.json");
  ASSERT_EQ(res->status, 200);
  const Json names = json_of(res->body);
  ASSERT_TRUE(names.is_array());
  ASSERT_FALSE(names.empty());
  res = client_->Get(("/ui/examples/" + names[0].get<std::string>() + ".json").c_str());
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/json");
  EXPECT_TRUE(json_of(res->body).is_object());
  expect_problem(client_->Get("/ui/README.md"), 404, "not-found");
  expect_problem(client_->Get("/ui/../db/hmpm.sqlite"), 404, "not-found");
  // The API itself still needs the token.
  expect_problem(client_->Get("/jobs"), 401, "unauthorized");
  expect_problem(client_->Post("/validate", small_spec(), "application/json"), 401, "unauthorized");
}

}  // namespace
}  // namespace hmpm::server

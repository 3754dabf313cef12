// test_ensemble_routes.cpp — the ensemble routes of contract v3 against a
// real in-process server over loopback: a request's problems with their
// JSON paths, the samples as ordinary jobs, the status derived from them,
// statistics.json against figures recomputed here from the samples' own
// series.json (downloaded through /jobs), the same seed giving the same
// samples, cancel, delete, the list and the guards every write route has.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "digest.hpp"
#include "service_fixture.hpp"

namespace hmpm::server {
namespace {

using namespace hmpm::server::testing;

class EnsembleRoutesTest : public ServiceTest {
 protected:
  EnsembleRoutesTest() : ServiceTest("ensemble-routes") {}

  httplib::Result post(const Json& body, const httplib::Headers& headers = {}) {
    return client_->Post("/ensembles", headers, body.dump(), "application/json");
  }

  // POST /ensembles expecting 201; the document.
  Json submit(const Json& body) {
    auto res = post(body);
    EXPECT_TRUE(res);
    if (!res) return {};
    EXPECT_EQ(res->status, 201) << res->body;
    Json doc = json_of(res->body);
    EXPECT_EQ(res->get_header_value("Location"), "/ensembles/" + doc.value("ensembleID", ""));
    return doc;
  }

  // Polls the ensemble until it has ended (or 60 s).
  Json wait_ended(const std::string& id) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    Json doc;
    while (std::chrono::steady_clock::now() < deadline) {
      doc = get_json("/ensembles/" + id);
      if (is_final(doc)) return doc;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ADD_FAILURE() << "ensemble " << id << " did not end: " << doc.dump();
    return doc;
  }
};

// A small vibrating bar with its stiffness drawn (lognormal) and its
// initial velocity amplitude swept: each sample's series differs.
Json request(int samples, std::int64_t seed) {
  Json spec = json_of(small_spec("bar", 0.2));
  spec["bodies"][0]["initial"]["velocity"] = {"0.1*sin(pi/2*x)"};
  Json values = Json::array();
  for (int k = 0; k < samples; ++k) values.push_back(2000.0 + 100.0 * k);
  return {{"spec", spec},
          {"samples", samples},
          {"seed", seed},
          {"vary", Json::array({{{"path", "/materials/bar/youngs_modulus"},
                                 {"distribution", {{"lognormal", {{"mean", 1e5}, {"cov", 0.3}}}}}},
                                {{"path", "/materials/bar/density"}, {"values", values}}})}};
}

std::vector<std::string> error_paths(const Json& problem) {
  std::vector<std::string> out;
  for (const Json& e : problem.value("errors", Json::array())) out.push_back(e["path"]);
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

TEST_F(EnsembleRoutesTest, EveryProblemOfARequestComesWithItsJsonPath) {
  start();
  Json bad = request(3, 1);
  bad["vary"][0]["path"] = "/materials/bar/colour";
  bad["vary"][1]["values"] = {1.0, 2.0};
  bad["extra"] = true;
  auto res = post(bad);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  Json problem = json_of(res->body);
  EXPECT_EQ(problem["type"], "invalid-spec");
  auto paths = error_paths(problem);
  EXPECT_TRUE(contains(paths, "/vary/0/path")) << res->body;
  EXPECT_TRUE(contains(paths, "/vary/1/values")) << res->body;
  EXPECT_TRUE(contains(paths, "/extra")) << res->body;

  // A sample whose drawn value the spec's own checks refuse: the path into
  // the request's spec, and which sample.
  Json negative = request(3, 1);
  negative["vary"][1]["values"] = {2000.0, -1.0, 2000.0};
  res = post(negative);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400) << res->body;
  problem = json_of(res->body);
  paths = error_paths(problem);
  EXPECT_TRUE(contains(paths, "/spec/materials/bar/density")) << res->body;
  EXPECT_NE(problem["errors"][0]["message"].get<std::string>().find("sample 1"), std::string::npos);

  res = client_->Post("/ensembles", "{not json", "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  // The guards of every write route: JSON only.
  res = client_->Post("/ensembles", request(2, 1).dump(), "text/plain");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 415);
  // Nothing was stored by any of them.
  EXPECT_EQ(get_json("/ensembles")["numberReturned"], 0);
  EXPECT_EQ(get_json("/jobs")["numberReturned"], 0);
}

TEST_F(EnsembleRoutesTest, TheTokenAndTheOriginAreCheckedAsForJobs) {
  start(1000, "secret");
  auto res = post(request(2, 1));
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 401);
  const httplib::Headers auth{{"Authorization", "Bearer secret"}};
  res = client_->Get("/ensembles");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 401);
  res = post(request(2, 1), {{"Authorization", "Bearer secret"}, {"Origin", "http://evil.test"}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 403);
  res = post(request(2, 1), auth);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 201) << res->body;
}

TEST_F(EnsembleRoutesTest, TooManySamplesForTheQueueAreRefusedAndNothingIsStored) {
  start(4);
  auto res = post(request(5, 1));
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422) << res->body;
  EXPECT_EQ(json_of(res->body)["limits"][0]["limit"], "max_queue");
  EXPECT_EQ(get_json("/jobs")["numberReturned"], 0);
}

// Independent figures of one scalar over the samples: mean, sample standard
// deviation, and percentiles interpolated linearly between order statistics.
Json figures(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const double n = static_cast<double>(v.size());
  double mean = 0;
  for (double x : v) mean += x / n;
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  auto pct = [&](double q) {
    const double h = q * (n - 1);
    const auto lo = static_cast<std::size_t>(h);
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  return {{"mean", mean},
          {"std", std::sqrt(ss / (n - 1))},
          {"p05", pct(0.05)},
          {"p50", pct(0.5)},
          {"p95", pct(0.95)}};
}

TEST_F(EnsembleRoutesTest, SamplesRunAsJobsAndStatisticsEqualTheSamplesOwnSeries) {
  start();
  const int n = 6;
  const Json created = submit(request(n, 2026));
  const std::string id = created["ensembleID"];
  EXPECT_EQ(created["samples"], n);
  EXPECT_EQ(created["seed"], 2026);
  ASSERT_EQ(created["jobs"].size(), static_cast<std::size_t>(n));
  EXPECT_TRUE(created["status"] == "accepted" || created["status"] == "running");
  EXPECT_EQ(created["counts"]["accepted"].get<int>() + created["counts"]["running"].get<int>() +
                created["counts"]["successful"].get<int>(),
            n);
  // Results are not ready before the end.
  if (!is_final(get_json("/ensembles/" + id))) {
    auto res = client_->Get(("/ensembles/" + id + "/results").c_str());
    ASSERT_TRUE(res);
    if (res->status != 200) {
      EXPECT_EQ(json_of(res->body)["type"], "result-not-ready");
    }
  }
  const Json ended = wait_ended(id);
  EXPECT_EQ(ended["status"], "successful");
  EXPECT_EQ(ended["progress"], 100);
  EXPECT_EQ(ended["counts"]["successful"], n);

  // The manifest: both files, with their sha256.
  const Json manifest = get_json("/ensembles/" + id + "/results");
  ASSERT_EQ(manifest["files"].size(), 2u);
  std::map<std::string, Json> files;
  for (const Json& f : manifest["files"]) {
    auto res = client_->Get(f["href"].get<std::string>().c_str());
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200);
    EXPECT_EQ(sha256_hex(res->body), f["sha256"]);
    EXPECT_EQ(res->body.size(), f["size"].get<std::size_t>());
    files[f["name"]] = json_of(res->body);
  }
  const Json& samples = files["samples.json"];
  const Json& stats = files["statistics.json"];
  ASSERT_EQ(samples["samples"].size(), static_cast<std::size_t>(n));

  // Each sample is an ordinary job whose spec holds the values samples.json names.
  std::vector<Json> series;
  for (int k = 0; k < n; ++k) {
    const Json& s = samples["samples"][static_cast<std::size_t>(k)];
    const std::string job = s["jobID"];
    EXPECT_EQ(job, created["jobs"][static_cast<std::size_t>(k)]);
    EXPECT_EQ(s["index"], k);
    EXPECT_EQ(s["status"], "successful");
    const Json status = get_json("/jobs/" + job);
    EXPECT_EQ(status["ensemble"]["ensembleID"], id);
    EXPECT_EQ(status["ensemble"]["index"], k);
    const Json spec = get_json("/jobs/" + job + "/spec");
    EXPECT_EQ(spec["materials"]["bar"]["youngs_modulus"],
              s["values"]["/materials/bar/youngs_modulus"]);
    EXPECT_EQ(spec["materials"]["bar"]["density"].get<double>(), 2000.0 + 100.0 * k);
    EXPECT_EQ(spec["name"], "bar-" + std::to_string(k));
    series.push_back(get_json("/jobs/" + job + "/results/series.json"));
  }
  // statistics.json against figures recomputed here, for every field of
  // every particle at every time, component by component.
  EXPECT_EQ(stats["samples"], n);
  EXPECT_TRUE(stats["missing"].empty());
  EXPECT_EQ(stats["time"], series[0]["time"]);
  const std::size_t times = series[0]["time"].size();
  ASSERT_GT(times, 10u);
  ASSERT_EQ(stats["particles"].size(), series[0]["particles"].size());
  int checked = 0;
  for (std::size_t p = 0; p < series[0]["particles"].size(); ++p) {
    for (const char* field : {"displacement", "velocity"}) {
      for (std::size_t t = 0; t < times; ++t) {
        std::vector<double> v;
        v.reserve(series.size());
        for (const Json& s : series) v.push_back(s["particles"][p][field][t][0].get<double>());
        const Json expected = figures(v);
        for (const char* f : {"mean", "std", "p05", "p50", "p95"}) {
          const double got = stats["particles"][p][field][f][t][0].get<double>();
          const double want = expected[f].get<double>();
          EXPECT_NEAR(got, want, 1e-12 * (1 + std::abs(want)))
              << "particle " << p << " " << field << " " << f << " t " << t;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 100);
  // The samples differ (the statistics are not of one series repeated).
  EXPECT_GT(stats["particles"][3]["displacement"]["std"][times - 1][0].get<double>(), 0.0);
}

TEST_F(EnsembleRoutesTest, TheSameSeedGivesTheSameSamples) {
  start();
  const Json a = submit(request(3, 99));
  const Json b = submit(request(3, 99));
  const Json other = submit(request(3, 100));
  ASSERT_EQ(a["jobs"].size(), 3u);
  EXPECT_NE(a["ensembleID"], b["ensembleID"]);
  for (std::size_t k = 0; k < 3; ++k) {
    const auto spec = [&](const Json& e) {
      auto res = client_->Get(("/jobs/" + e["jobs"][k].get<std::string>() + "/spec").c_str());
      return res ? res->body : std::string();
    };
    EXPECT_EQ(spec(a), spec(b)) << "sample " << k;
    EXPECT_NE(spec(a), spec(other)) << "sample " << k;
  }
  // An Idempotency-Key replays the whole ensemble.
  const httplib::Headers key{{"Idempotency-Key", "ensemble-once"}};
  auto first = post(request(2, 5), key);
  auto again = post(request(2, 5), key);
  ASSERT_TRUE(first && again);
  EXPECT_EQ(first->status, 201);
  EXPECT_EQ(again->status, 201);
  EXPECT_EQ(again->get_header_value("Idempotent-Replayed"), "true");
  EXPECT_EQ(json_of(first->body)["jobs"], json_of(again->body)["jobs"]);
  auto conflict = post(request(2, 6), key);
  ASSERT_TRUE(conflict);
  EXPECT_EQ(conflict->status, 422);
  for (const Json& e : {a, b, other}) wait_ended(e["ensembleID"]);
  // The list: newest first, with a status filter and a limit.
  const Json all = get_json("/ensembles");
  EXPECT_EQ(all["numberReturned"], 4);
  EXPECT_EQ(all["ensembles"][3]["ensembleID"], a["ensembleID"]);
  EXPECT_EQ(get_json("/ensembles?limit=2")["numberReturned"], 2);
  EXPECT_EQ(get_json("/ensembles?status=failed")["numberReturned"], 0);
  EXPECT_EQ(get_json("/ensembles?colour=red", 400)["type"], "invalid-parameter");
  EXPECT_EQ(get_json("/ensembles?status=done", 400)["type"], "invalid-parameter");
  get_json("/ensembles/00000000-0000-4000-8000-000000000000", 404);
}

// A sweep over a random field's seed (values at the pointer into the
// field): one field per seed, so two samples of the same seed run the
// same job to the same series, and another seed another one.
TEST_F(EnsembleRoutesTest, ASweepOfARandomFieldsSeedGivesOneFieldPerSeed) {
  start();
  Json spec = json_of(small_spec("field-bar", 0.2));
  spec["materials"]["bar"]["youngs_modulus"] = {
      {"random_field",
       {{"distribution", {{"lognormal", {{"mean", 1e5}, {"cov", 0.3}}}}},
        {"correlation_length", {0.2}},
        {"seed", 0}}}};
  const std::string at = "/materials/bar/youngs_modulus/random_field/seed";
  const Json created = submit({{"spec", spec},
                               {"seed", 1},
                               {"vary", Json::array({{{"path", at}, {"values", {5, 6, 5}}}})}});
  ASSERT_EQ(created["jobs"].size(), 3u);
  const Json ended = wait_ended(created["ensembleID"]);
  EXPECT_EQ(ended["status"], "successful") << ended.dump();
  std::vector<std::string> series;
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string job = created["jobs"][k];
    const Json job_spec = get_json("/jobs/" + job + "/spec");
    const Json& seed = job_spec[Json::json_pointer(at)];
    EXPECT_TRUE(seed.is_number_integer()) << seed.dump();
    EXPECT_EQ(seed, (Json{5, 6, 5}[k])) << "sample " << k;
    auto res = client_->Get(("/jobs/" + job + "/results/series.json").c_str());
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    series.push_back(res->body);
  }
  EXPECT_EQ(series[0], series[2]) << "the same seed, the same field and run";
  EXPECT_NE(series[0], series[1]) << "another seed, another field";
}

TEST_F(EnsembleRoutesTest, CancelDismissesTheUnfinishedSamplesAndDeleteRemovesThemAll) {
  start();
  Json body = request(3, 7);
  body["spec"] = json_of(long_spec("long", 10000.0));
  body["vary"] = Json::array({{{"path", "/materials/bar/youngs_modulus"},
                               {"distribution", {{"uniform", {{"min", 9e4}, {"max", 1.1e5}}}}}}});
  const Json created = submit(body);
  const std::string id = created["ensembleID"];
  // Wait for the first sample to run, then cancel.
  const std::string first = created["jobs"][0];
  poll_job(
      *client_, first, [](const Json& d) { return d.value("status", "") == "running"; }, 30);
  auto res = client_->Post(("/ensembles/" + id + "/cancel").c_str(), "", "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202) << res->body;
  const Json ended = wait_ended(id);
  EXPECT_EQ(ended["status"], "dismissed");
  EXPECT_EQ(ended["state"], "cancelled");
  EXPECT_EQ(ended["counts"]["dismissed"], 3);
  res = client_->Post(("/ensembles/" + id + "/cancel").c_str(), "", "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 409);
  EXPECT_EQ(json_of(res->body)["type"], "ensemble-finished");
  // Ended: the results are there, with no successful sample in the statistics.
  const Json manifest = get_json("/ensembles/" + id + "/results");
  EXPECT_EQ(manifest["status"], "dismissed");
  EXPECT_EQ(get_json("/ensembles/" + id + "/results/statistics.json")["samples"], 0);
  get_json("/ensembles/" + id + "/results/other.json", 404);

  ASSERT_TRUE(std::filesystem::exists(dir_ / "results" / first));  // the sample that ran
  res = client_->Delete(("/ensembles/" + id).c_str());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(json_of(res->body)["state"], "deleted");
  EXPECT_EQ(get_json("/ensembles/" + id + "/results", 410)["type"], "ensemble-dismissed");
  for (const Json& job : created["jobs"]) {
    get_json("/jobs/" + job.get<std::string>() + "/results", 410);
    EXPECT_FALSE(std::filesystem::exists(dir_ / "results" / job.get<std::string>()));
  }
}

}  // namespace
}  // namespace hmpm::server

// test_options.cpp — the hmpm-server command line: defaults, every flag,
// HMPM_TOKEN, and the ways to get it wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hmpm/server/options.hpp"

namespace hmpm::server {
namespace {

TEST(Options, DefaultsNeedOnlyTheDatabase) {
  const auto parsed = parse_options({"--db", "x/db.sqlite"}, nullptr);
  ASSERT_TRUE(parsed.config) << parsed.error;
  EXPECT_EQ(parsed.config->host, "127.0.0.1");
  EXPECT_EQ(parsed.config->port, 8080);
  EXPECT_EQ(parsed.config->workers, 2);  // a short job runs beside a long one
  EXPECT_EQ(parsed.config->max_attempts, 3);
  EXPECT_TRUE(parsed.config->token.empty());
  EXPECT_TRUE(parsed.config->data_dir.empty());  // resolved to <db dir>/results by the service
  EXPECT_EQ(parsed.config->retain_days, 30);
  // The limits of a shared server: a day of wall time, 2 M particles,
  // 1e12 particle-steps; memory 0 = half the physical memory / workers.
  EXPECT_DOUBLE_EQ(parsed.config->job_wall_time_s, 86'400.0);
  EXPECT_EQ(parsed.config->max_particles, 2'000'000);
  EXPECT_EQ(parsed.config->max_particle_steps, 1'000'000'000'000);
  EXPECT_EQ(parsed.config->max_job_memory, 0);
}

TEST(Options, JobLimitsAreReadAndZeroMeansNone) {
  const auto set = parse_options({"--db", "d", "--max-particles", "1000", "--max-particle-steps",
                                  "5000000", "--max-job-memory", "1048576"},
                                 nullptr);
  ASSERT_TRUE(set.config) << set.error;
  EXPECT_EQ(set.config->max_particles, 1000);
  EXPECT_EQ(set.config->max_particle_steps, 5'000'000);
  EXPECT_EQ(set.config->max_job_memory, 1 << 20);
  const auto none = parse_options(
      {"--db", "d", "--max-particle-steps", "0", "--max-job-memory", "0", "--job-wall-time", "0"},
      nullptr);
  ASSERT_TRUE(none.config) << none.error;
  EXPECT_EQ(none.config->max_particle_steps, 0);
  EXPECT_LT(none.config->max_job_memory, 0);  // none, not "the default"
  EXPECT_DOUBLE_EQ(none.config->job_wall_time_s, 0.0);
  EXPECT_NE(
      parse_options({"--db", "d", "--max-particles", "0"}, nullptr).error.find("--max-particles"),
      std::string::npos);
  for (const char* flag : {"--max-particles N", "--max-particle-steps N", "--max-job-memory B"})
    EXPECT_NE(usage().find(flag), std::string::npos) << flag;
}

TEST(Options, RetainDaysZeroKeepsForeverAndNegativeIsRefused) {
  const auto kept = parse_options({"--db", "d", "--retain-days", "0"}, nullptr);
  ASSERT_TRUE(kept.config) << kept.error;
  EXPECT_EQ(kept.config->retain_days, 0);
  const auto week = parse_options({"--db", "d", "--retain-days=7"}, nullptr);
  ASSERT_TRUE(week.config) << week.error;
  EXPECT_EQ(week.config->retain_days, 7);
  EXPECT_NE(
      parse_options({"--db", "d", "--retain-days", "-1"}, nullptr).error.find("--retain-days"),
      std::string::npos);
  EXPECT_NE(usage().find("--retain-days N"), std::string::npos);
}

TEST(Options, CheckpointIntervalDefaultsToAMinuteAndZeroTurnsItOff) {
  EXPECT_EQ(parse_options({"--db", "d"}, nullptr).config->checkpoint_interval_s, 60.0);
  const auto off = parse_options({"--db", "d", "--checkpoint-interval", "0"}, nullptr);
  ASSERT_TRUE(off.config) << off.error;
  EXPECT_EQ(off.config->checkpoint_interval_s, 0.0);
  const auto often = parse_options({"--db", "d", "--checkpoint-interval=1.5"}, nullptr);
  ASSERT_TRUE(often.config) << often.error;
  EXPECT_EQ(often.config->checkpoint_interval_s, 1.5);
  EXPECT_NE(parse_options({"--db", "d", "--checkpoint-interval", "-1"}, nullptr)
                .error.find("--checkpoint-interval"),
            std::string::npos);
  EXPECT_NE(usage().find("--checkpoint-interval S"), std::string::npos);
}

TEST(Options, EveryFlagIsRead) {
  const auto parsed =
      parse_options({"--host",   "0.0.0.0",           "--port=0", "--db",
                     "d.sqlite", "--workers",         "3",        "--data-dir",
                     "res",      "--threads-per-job", "2",        "--token",
                     "t",        "--max-queue",       "5",        "--job-wall-time",
                     "1.5",      "--max-attempts",    "4",        "--charge-after",
                     "12.5",     "--max-body-bytes",  "4096",     "--max-event-streams",
                     "2",        "--http-threads",    "6"},
                    "env-token");
  ASSERT_TRUE(parsed.config) << parsed.error;
  const ServiceConfig& c = *parsed.config;
  EXPECT_EQ(c.host, "0.0.0.0");
  EXPECT_EQ(c.port, 0);
  EXPECT_EQ(c.workers, 3);
  EXPECT_EQ(c.data_dir, "res");
  EXPECT_EQ(c.threads_per_job, 2);
  EXPECT_EQ(c.token, "t");  // --token wins over HMPM_TOKEN
  EXPECT_EQ(c.max_queue, 5);
  EXPECT_DOUBLE_EQ(c.job_wall_time_s, 1.5);
  EXPECT_EQ(c.max_attempts, 4);
  EXPECT_DOUBLE_EQ(c.charge_after_s, 12.5);
  EXPECT_EQ(c.max_body_bytes, 4096u);
  EXPECT_EQ(c.max_event_streams, 2);
  EXPECT_EQ(c.http_threads, 6);
}

TEST(Options, TokenComesFromTheEnvironment) {
  const auto parsed = parse_options({"--db", "d"}, "s3cret");
  ASSERT_TRUE(parsed.config);
  EXPECT_EQ(parsed.config->token, "s3cret");
}

TEST(Options, MistakesAreReportedNotFatal) {
  EXPECT_NE(parse_options({}, nullptr).error.find("--db"), std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--port", "70000"}, nullptr).error.find("--port"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--workers", "two"}, nullptr).error.find("--workers"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--workers", "0"}, nullptr).error.find("--workers"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--job-wall-time", "-1"}, nullptr).error.find("seconds"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--bogus", "1"}, nullptr).error.find("unknown option"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db"}, nullptr).error.find("needs a value"), std::string::npos);
  // A URI that is not PostgreSQL's is refused, not taken for a SQLite path.
  EXPECT_NE(parse_options({"--db", "mysql://u@127.0.0.1/db"}, nullptr).error.find("postgresql://"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "postgresq://u@127.0.0.1/db"}, nullptr).error.find("URI"),
            std::string::npos);
  EXPECT_TRUE(parse_options({"--help"}, nullptr).help);
}

// A server reachable from other machines needs a token, or an explicit
// --allow-no-token; an empty token is always a mistake.
TEST(Options, InsecureStartsAreRefused) {
  EXPECT_NE(parse_options({"--db", "d", "--host", "0.0.0.0"}, nullptr).error.find("token"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--host", "::"}, nullptr).error.find("token"),
            std::string::npos);
  EXPECT_NE(parse_options({"--db", "d", "--host", "example.org"}, nullptr).error.find("token"),
            std::string::npos);
  for (const char* loopback : {"127.0.0.1", "127.1.2.3", "::1", "[::1]", "localhost"}) {
    EXPECT_TRUE(parse_options({"--db", "d", "--host", loopback}, nullptr).config) << loopback;
  }
  const auto allowed =
      parse_options({"--db", "d", "--host", "0.0.0.0", "--allow-no-token"}, nullptr);
  ASSERT_TRUE(allowed.config) << allowed.error;
  EXPECT_TRUE(allowed.config->allow_no_token);
  EXPECT_TRUE(parse_options({"--db", "d", "--host", "0.0.0.0"}, "env").config);
  // --token '' does not quietly switch HMPM_TOKEN off, and the error shows no value.
  const auto empty = parse_options({"--db", "d", "--token", ""}, "env");
  EXPECT_FALSE(empty.config);
  EXPECT_NE(empty.error.find("--token"), std::string::npos);
  EXPECT_FALSE(parse_options({"--db", "d", "--token="}, nullptr).config);
  EXPECT_FALSE(parse_options({"--db", "d"}, "").config);
}

TEST(Options, TokenFileKeepsTheSecretOffTheCommandLine) {
  const auto dir = std::filesystem::temp_directory_path() / "hmpm-options-token";
  std::filesystem::create_directories(dir);
  const auto file = dir / "token";
  std::ofstream(file) << "from-file\n";
  const auto parsed = parse_options({"--db", "d", "--token-file", file.string()}, "env");
  ASSERT_TRUE(parsed.config) << parsed.error;
  EXPECT_EQ(parsed.config->token, "from-file");  // wins over HMPM_TOKEN, newline dropped
  EXPECT_FALSE(
      parse_options({"--db", "d", "--token-file", file.string(), "--token", "t"}, nullptr).config);
  std::ofstream(file) << "\n";
  EXPECT_NE(
      parse_options({"--db", "d", "--token-file", file.string()}, nullptr).error.find("empty"),
      std::string::npos);
  EXPECT_FALSE(
      parse_options({"--db", "d", "--token-file", (dir / "missing").string()}, nullptr).config);
  std::filesystem::remove_all(dir);
}

// Each event stream holds an HTTP thread: a cap at or above the thread
// count would let streams starve /health.
TEST(Options, StreamCapMustStayBelowTheHttpThreads) {
  EXPECT_NE(parse_options({"--db", "d", "--max-event-streams", "24"}, nullptr)
                .error.find("--http-threads"),
            std::string::npos);
  EXPECT_TRUE(
      parse_options({"--db", "d", "--max-event-streams", "23", "--http-threads", "24"}, nullptr)
          .config);
  const auto parsed =
      parse_options({"--db", "d", "--max-connections", "64", "--request-head-timeout", "2.5",
                     "--request-body-timeout", "30", "--event-stream-max-seconds", "5"},
                    nullptr);
  ASSERT_TRUE(parsed.config) << parsed.error;
  EXPECT_EQ(parsed.config->max_connections, 64);
  EXPECT_DOUBLE_EQ(parsed.config->head_timeout_s, 2.5);
  EXPECT_DOUBLE_EQ(parsed.config->body_timeout_s, 30.0);
  EXPECT_DOUBLE_EQ(parsed.config->event_stream_max_s, 5.0);
  EXPECT_FALSE(parse_options({"--db", "d", "--request-head-timeout", "0"}, nullptr).config);
}

}  // namespace
}  // namespace hmpm::server

// service_fixture.hpp — a test fixture that runs one hmpm::server::Service
// on an ephemeral loopback port with its own SQLite file and data folder
// (under a fresh temporary folder, removed afterwards), with an
// httplib::Client for it. For test files of hmpm_server_tests (they link
// the server library); test_routes.cpp keeps its own, with more knobs.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "hmpm/server/service.hpp"
#include "job_log.hpp"
#include "support.hpp"

namespace hmpm::server::testing {

class ServiceTest : public ::testing::Test {
 protected:
  explicit ServiceTest(std::string tag) : tag_(std::move(tag)) {}

  void SetUp() override {
    set_logging_enabled(false);
    dir_ = make_temp_dir(tag_);
  }
  void TearDown() override {
    if (service_) {
      service_->stop();
      thread_.join();
    }
    std::filesystem::remove_all(dir_);
  }

  /// Starts the service: one worker of one thread, `max_queue`, `token`.
  void start(long max_queue = 1000, const std::string& token = "") {
    ServiceConfig c;
    c.port = 0;
    c.db_path = dir_ / "hmpm.sqlite";
    c.workers = 1;
    c.threads_per_job = 1;
    c.max_queue = max_queue;
    c.token = token;
    service_ = std::make_unique<Service>(std::move(c));
    const int port = service_->bind();
    ASSERT_GT(port, 0);
    thread_ = std::thread([this] { service_->run(); });
    for (int i = 0; i < 1000 && !service_->is_running(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_TRUE(service_->is_running());
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port);
    client_->set_read_timeout(30, 0);
  }

  /// GET `path`, expecting `status`; the body parsed (null if not JSON).
  Json get_json(const std::string& path, int status = 200) {
    auto res = client_->Get(path.c_str());
    EXPECT_TRUE(res) << path;
    if (!res) return {};
    EXPECT_EQ(res->status, status) << path << ": " << res->body;
    return json_of(res->body);
  }

  std::string tag_;
  std::filesystem::path dir_;  ///< the database and, in results/, the data folder
  std::unique_ptr<Service> service_;
  std::thread thread_;
  std::unique_ptr<httplib::Client> client_;
};

}  // namespace hmpm::server::testing

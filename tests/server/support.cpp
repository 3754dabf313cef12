// support.cpp — see support.hpp.
#include "support.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "hmpm/server/job_status.hpp"

namespace hmpm::server::testing {

std::string small_spec(const std::string& name, double end_s) {
  Json spec = {{"name", name},
               {"dimension", 1},
               {"grid", {{"min", {0.0}}, {"max", {1.0}}, {"cells", {13}}}},
               {"materials",
                {{"bar",
                  {{"model", "linear_elastic"},
                   {"density", 2000.0},  // plausible values: no warnings (docs/job-spec.md)
                   {"youngs_modulus", 1.0e5},
                   {"poisson_ratio", 0.0}}}}},
               {"bodies", Json::array({{{"material", "bar"},
                                        {"box", {{"min", {0.0}}, {"max", {1.0}}}},
                                        {"particles_per_cell", 1},
                                        {"initial", {{"velocity", {"0.1*sin(pi/2*x)"}}}}}})},
               {"gravity", {0.0}},
               {"boundaries", Json::array({{{"nodes", {{"box", {{"min", {0.0}}, {"max", {0.0}}}}}},
                                            {"velocity", {0.0}}}})},
               {"time", {{"end", end_s}, {"dt", 1.0e-3}}},
               {"output",
                {{"series",
                  {{"particles", {0, 3, 6, 12}},
                   {"fields", {"displacement", "velocity"}},
                   {"interval", 0.01}}}}}};
  return spec.dump(2);
}

std::string long_spec(const std::string& name, double end_s) {
  Json spec = Json::parse(small_spec(name, end_s));
  spec["grid"] = {{"min", {0.0}}, {"max", {12.0}}, {"cells", {600}}};
  spec["bodies"][0]["box"] = {{"min", {0.0}}, {"max", {10.0}}};
  spec["bodies"][0]["particles_per_cell"] = 2;
  spec["bodies"][0]["initial"] = {{"velocity", {"0.01*sin(pi/20*x)"}}};
  spec["output"] = {
      {"series", {{"particles", {0, 999}}, {"fields", {"displacement"}}, {"interval", 1.0}}}};
  return spec.dump(2);
}

std::filesystem::path make_temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  std::random_device random;
  auto dir = std::filesystem::temp_directory_path() /
             ("hmpm-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
              "-" + std::to_string(random() % 100000));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string raw_http(int port, const std::string& request, double timeout_s) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return {};
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string response;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    std::size_t sent = 0;
    while (sent < request.size()) {
      const auto n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;  // the server may answer and close before reading it all
      sent += static_cast<std::size_t>(n);
    }
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    char buffer[8192];
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      const auto n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      response.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return response;
}

int raw_status(const std::string& response) {
  if (response.rfind("HTTP/1.", 0) != 0 || response.size() < 12) return 0;
  return std::atoi(response.substr(9, 3).c_str());
}

std::string raw_body(const std::string& response) {
  const auto end = response.find("\r\n\r\n");
  return end == std::string::npos ? std::string() : response.substr(end + 4);
}

bool is_final(const Json& doc) {
  if (!doc.is_object() || !doc.contains("status") || !doc["status"].is_string()) return false;
  const auto status = parse_status(doc["status"].get<std::string>());
  return status && is_terminal(*status);
}

Json json_of(const std::string& body) {
  return Json::parse(body, nullptr, false);
}

Json poll_job(httplib::Client& client, const std::string& id,
              const std::function<bool(const Json&)>& done, double timeout_s,
              const httplib::Headers& headers) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  Json last;
  for (;;) {
    if (auto res = client.Get(("/jobs/" + id).c_str(), headers); res && res->status == 200) {
      last = json_of(res->body);
      if (done(last)) return last;
    }
    if (std::chrono::steady_clock::now() > deadline) return last;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace hmpm::server::testing

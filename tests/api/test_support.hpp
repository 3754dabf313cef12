// test_support.hpp — small helpers shared by the api tests: files, the
// source tree, and running the built `hmpm` executable as a black box.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace hmpm::api::testing {

inline std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(HMPM_SOURCE_DIR) / relative;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// A fresh directory under the system temp dir, removed by the destructor.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("hmpm-api-") +
                       (info ? info->test_suite_name() + std::string("-") + info->name() : "x");
    for (char& c : name)
      if (c == '/') c = '_';
    // The pid keeps concurrent runs (two build trees, ctest -j) apart.
    path_ = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs `command` through the shell with stdout and stderr captured.
/// `scratch` receives cmd.stdout and cmd.stderr: a folder of the test's own
/// (tests run in parallel; two sharing one folder read each other's output).
inline CommandResult run_command(const std::string& command, const std::filesystem::path& scratch) {
  const auto out = scratch / "cmd.stdout", err = scratch / "cmd.stderr";
  const std::string full = command + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(full.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

/// The built command line, quoted for the shell.
inline std::string hmpm_exe() {
  return std::string("'") + HMPM_EXE + "'";
}

/// The Python interpreter with meshio/numpy (scripts/python.sh), quoted.
inline std::string python_exe(const std::filesystem::path& scratch) {
  const CommandResult r =
      run_command("bash '" + source_path("scripts/python.sh").string() + "'", scratch);
  std::string py = r.out;
  while (!py.empty() && (py.back() == '\n' || py.back() == '\r')) py.pop_back();
  return "'" + py + "'";
}

}  // namespace hmpm::api::testing

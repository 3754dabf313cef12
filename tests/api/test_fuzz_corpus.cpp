// test_fuzz_corpus.cpp — replays every input of fuzz/corpus/ through
// parse_job (what the libFuzzer target does), so inputs that once crashed
// stay fixed in a normal build. Valid inputs must parse to a job; every
// rejected input must carry at least one error with a pointer-shaped path.
#include <filesystem>

#include <gtest/gtest.h>

#include "hmpm/api/job.hpp"
#include "test_support.hpp"

namespace hmpm::api {
namespace {

namespace fs = std::filesystem;

TEST(FuzzCorpus, EveryInputParsesWithoutCrashing) {
  const fs::path dir = testing::source_path("fuzz/corpus");
  ASSERT_TRUE(fs::is_directory(dir));
  int inputs = 0, valid = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    SCOPED_TRACE(entry.path().filename().string());
    const ParseResult r = parse_job(testing::read_text(entry.path()));
    ++inputs;
    if (r.ok()) {
      ++valid;
      EXPECT_TRUE(r.job.has_value());
    }
    for (const SpecError& e : r.errors) {
      EXPECT_TRUE(e.path.empty() || e.path[0] == '/') << e.path;
      EXPECT_FALSE(e.message.empty());
    }
  }
  EXPECT_GE(inputs, 10);
  EXPECT_GE(valid, 3);  // the examples
}

}  // namespace
}  // namespace hmpm::api

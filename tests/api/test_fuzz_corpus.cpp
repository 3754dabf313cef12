// test_fuzz_corpus.cpp — replays every input of fuzz/corpus/ through
// parse_job (what the libFuzzer target does), so inputs that once crashed
// stay fixed in a normal build. Each file's name says what it is (seed-*,
// found-valid-*: accepted; bad-*, found-errors-*: rejected) and the test
// holds it to that; every error carries a pointer-shaped path.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "test_support.hpp"

namespace hmpm::api {
namespace {

namespace fs = std::filesystem;

// What a corpus file's name promises: "seed-*" and "found-valid-*" are
// valid specs, "bad-*" and "found-errors-*" are rejected ones.
enum class Promise { valid, rejected, unknown };

Promise promise_of(const std::string& name) {
  for (const char* prefix : {"seed-", "found-valid-"})
    if (name.rfind(prefix, 0) == 0) return Promise::valid;
  for (const char* prefix : {"bad-", "found-errors-"})
    if (name.rfind(prefix, 0) == 0) return Promise::rejected;
  return Promise::unknown;
}

TEST(FuzzCorpus, EveryInputIsWhatItsNameSays) {
  const fs::path dir = testing::source_path("fuzz/corpus");
  ASSERT_TRUE(fs::is_directory(dir));
  int valid = 0, rejected = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    const ParseResult r = parse_job(testing::read_text(entry.path()));
    for (const SpecError& e : r.errors) {
      EXPECT_TRUE(e.path.empty() || e.path[0] == '/') << e.path;
      EXPECT_FALSE(e.message.empty());
    }
    switch (promise_of(name)) {
      case Promise::valid:
        ++valid;
        EXPECT_TRUE(r.ok()) << "named as valid but rejected, first error: "
                            << (r.errors.empty() ? ""
                                                 : r.errors[0].path + ": " + r.errors[0].message);
        EXPECT_TRUE(r.job.has_value());
        break;
      case Promise::rejected:
        ++rejected;
        EXPECT_FALSE(r.ok()) << "named as invalid but accepted";
        EXPECT_FALSE(r.job.has_value());
        break;
      case Promise::unknown:
        ADD_FAILURE() << "the name promises nothing: start it with seed-, found-valid-, bad- or "
                         "found-errors-";
        break;
    }
  }
  EXPECT_GE(valid, 3);     // the examples
  EXPECT_GE(rejected, 3);  // the malformed seeds
}

// fuzz/spec.dict keeps mutations close to real specs: it must name every key
// and every enumerated value of the parser's tables (hmpm spec-keys).
TEST(FuzzCorpus, DictionaryNamesEveryKeyAndValueOfTheParser) {
  const std::string dict = testing::read_text(testing::source_path("fuzz/spec.dict"));
  const nlohmann::json tables = nlohmann::json::parse(spec_tables_json());
  std::vector<std::string> words;
  for (const auto& [location, keys] : tables["objects"].items())
    for (const auto& k : keys) words.push_back(k.get<std::string>());
  for (const auto& [location, values] : tables["values"].items())
    for (const auto& v : values) words.push_back(v.get<std::string>());
  for (const std::string& w : words)
    EXPECT_NE(dict.find("\"\\\"" + w + "\\\"\""), std::string::npos)
        << "fuzz/spec.dict has no entry for \"" << w << "\"";
}

}  // namespace
}  // namespace hmpm::api

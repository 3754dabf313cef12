// spec_reader.hpp — typed, error-collecting access to a parsed JSON document.
//
// Every accessor takes the value and its JSON pointer, checks type and
// range, and on failure records a SpecError (pointer + what was expected)
// instead of throwing, so one pass over a spec reports every problem.
// `parse_json_guarded` turns text into a document without recursing deeper
// than a limit, so hostile nesting cannot overflow the stack.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "hmpm/format.hpp"

namespace hmpm::api {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling

/// RFC 6901: "~" -> "~0", "/" -> "~1".
std::string escape_pointer_token(std::string_view token);
/// `parent` + "/" + escaped `token`.
std::string child_pointer(const std::string& parent, std::string_view token);
std::string child_pointer(const std::string& parent, std::size_t index);

/// A top-level array the pre-scan of parse_json_guarded counts: more than
/// `max_elements` in the array under `key` is refused before anything is
/// built (building a 16 MB document's values costs seconds).
struct TopArrayLimit {
  std::string_view key;
  std::size_t max_elements = 0;
  std::string_view advice;  ///< appended to the error
};

/// Parses `text` into `out`. Refuses nesting deeper than `max_depth`, and
/// a top-level array beyond `limit` (error at "/KEY"), before building
/// anything. On failure returns false and appends an error.
bool parse_json_guarded(std::string_view text, int max_depth, json& out,
                        std::vector<SpecError>& errors, const TopArrayLimit& limit);
bool parse_json_guarded(std::string_view text, int max_depth, json& out,
                        std::vector<SpecError>& errors);

/// An interval for numeric checks; bounds are open or closed.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() {
    return {0.0, std::numeric_limits<double>::infinity(), false, false};
  }
  static Range any() { return {}; }
  bool contains(double v) const;
  std::string describe() const;  ///< "> 0", "in (0, 1)", ...
};

/// Numbers in messages: hmpm::format_number (shortest text that reads back the same).
/// A count for messages: digits when integral and below 1e18 ("9000000").
std::string format_count(double v);

/// Nearest of `candidates` to `word` by edit distance (empty if none).
std::string nearest_word(std::string_view word, std::span<const std::string_view> candidates);

class SpecReader {
 public:
  void error(std::string path, std::string message);
  const std::vector<SpecError>& errors() const { return errors_; }
  std::vector<SpecError>& errors() { return errors_; }
  std::size_t error_count() const { return errors_.size(); }

  /// Checks that `j` is an object, every key is in `known` (else names the
  /// nearest) and every key of `required` is present.
  bool object(const json& j, const std::string& path, std::span<const std::string_view> known,
              std::span<const std::string_view> required = {});
  /// Checks that `j` is an array (with at least `min_size` entries).
  bool array(const json& j, const std::string& path, std::size_t min_size = 0);
  /// A finite number in `range`.
  std::optional<double> number(const json& j, const std::string& path, const Range& range = {});
  /// When object `j` has `key`, reads it as a number in `range` into
  /// `target` (left unchanged on error). Returns whether the value was valid.
  template <typename T>
  bool number_at(const json& j, const std::string& path, std::string_view key, const Range& range,
                 T& target) {
    if (!j.contains(key)) return false;
    const auto v = number(j[std::string(key)], child_pointer(path, key), range);
    if (v) target = *v;
    return v.has_value();
  }
  /// true or false.
  std::optional<bool> boolean(const json& j, const std::string& path);
  /// An integer (a number with an integral value) in [lo, hi].
  std::optional<std::int64_t> integer(const json& j, const std::string& path, std::int64_t lo,
                                      std::int64_t hi);
  std::optional<std::string> string(const json& j, const std::string& path,
                                    std::size_t max_length = 256);
  /// A string that is one of `allowed`; the message lists them.
  std::optional<std::string> one_of(const json& j, const std::string& path,
                                    std::span<const std::string_view> allowed);
  /// Checks that `j` is an array with one entry per axis (any length when
  /// dim <= 0, i.e. the dimension is unknown); `entry` says what an entry is.
  bool per_axis(const json& j, const std::string& path, int dim, std::string_view entry);
  /// An array of exactly `dim` finite numbers.
  std::optional<Vec3> vector(const json& j, const std::string& path, int dim);

 private:
  std::vector<SpecError> errors_;
};

}  // namespace hmpm::api

// spec_reader.cpp — see spec_reader.hpp.
#include "spec_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace hmpm::api {

std::string escape_pointer_token(std::string_view token) {
  std::string out;
  out.reserve(token.size());
  for (char c : token) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string child_pointer(const std::string& parent, std::string_view token) {
  return parent + "/" + escape_pointer_token(token);
}

std::string child_pointer(const std::string& parent, std::size_t index) {
  return parent + "/" + std::to_string(index);
}

bool parse_json_guarded(std::string_view text, int max_depth, json& out,
                        std::vector<SpecError>& errors) {
  // Pre-scan the nesting outside strings: nlohmann's DOM builder and
  // destructor are fine with depth, but nothing downstream needs more than a
  // handful of levels and a hostile document should cost O(n) and no stack.
  int depth = 0;
  bool in_string = false, escaped = false;
  std::size_t line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        errors.push_back({"", "not accepted: brackets nested deeper than " + std::to_string(max_depth) +
                                  " levels (byte " + std::to_string(i + 1) + ", line " +
                                  std::to_string(line) + ")"});
        return false;
      }
    } else if (c == ']' || c == '}') {
      depth = std::max(depth - 1, 0);
    }
  }
  try {
    out = json::parse(text.begin(), text.end());
  } catch (const json::exception& e) {
    std::string what = e.what();
    // Drop nlohmann's "[json.exception.parse_error.101] " prefix.
    if (const auto pos = what.find("] "); what.rfind("[json.exception.", 0) == 0 && pos != std::string::npos)
      what = what.substr(pos + 2);
    errors.push_back({"", "not valid JSON: " + what});
    return false;
  }
  return true;
}

bool Range::contains(double v) const {
  const bool lo_ok = lo_open ? v > lo : v >= lo;
  const bool hi_ok = hi_open ? v < hi : v <= hi;
  return lo_ok && hi_ok;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string("in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
           (hi_open ? ")" : "]");
  if (has_lo) return std::string(lo_open ? "> " : ">= ") + format_number(lo);
  if (has_hi) return std::string(hi_open ? "< " : "<= ") + format_number(hi);
  return "finite";
}

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

namespace {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string join(std::span<const std::string_view> words) {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (i) out += ", ";
    out += '\'';
    out.append(words[i]);
    out += '\'';
  }
  return out;
}

}  // namespace

std::string nearest_word(std::string_view word, std::span<const std::string_view> candidates) {
  std::string best;
  std::size_t best_d = std::string::npos;
  // Very long words are not typos of short keys; keep the O(n m) cost bounded.
  const std::string_view w = word.substr(0, 64);
  for (std::string_view c : candidates) {
    const std::size_t d = edit_distance(w, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  if (best.empty()) return best;
  // Only suggest when the word is plausibly a typo of it.
  return best_d <= std::max<std::size_t>(2, best.size() / 3) ? best : std::string();
}

void SpecReader::error(std::string path, std::string message) {
  errors_.push_back({std::move(path), std::move(message)});
}

bool SpecReader::object(const json& j, const std::string& path, std::span<const std::string_view> known,
                        std::span<const std::string_view> required) {
  if (!j.is_object()) {
    error(path, std::string("expected an object, got ") + j.type_name());
    return false;
  }
  for (const auto& [key, value] : j.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    const std::string near = nearest_word(key, known);
    const std::string shown = key.size() > 64 ? key.substr(0, 64) + "..." : key;
    error(child_pointer(path, key), "unknown key '" + shown + "'; " +
                                        (near.empty() ? "expected one of " + join(known)
                                                      : "did you mean '" + near + "'?"));
  }
  for (std::string_view key : required)
    if (!j.contains(key)) error(child_pointer(path, key), "is required");
  return true;
}

bool SpecReader::array(const json& j, const std::string& path, std::size_t min_size) {
  if (!j.is_array()) {
    error(path, std::string("expected an array, got ") + j.type_name());
    return false;
  }
  if (j.size() < min_size) {
    error(path, "is empty; at least " + std::to_string(min_size) + " entry needed");
    return false;
  }
  return true;
}

std::optional<double> SpecReader::number(const json& j, const std::string& path, const Range& range) {
  if (!j.is_number()) {
    error(path, "expected a number " + range.describe() + ", got " + j.type_name());
    return std::nullopt;
  }
  const double v = j.get<double>();
  if (!std::isfinite(v)) {
    error(path, "is not a finite number (overflow); expected a number " + range.describe());
    return std::nullopt;
  }
  if (!range.contains(v)) {
    error(path, "is " + format_number(v) + "; must be " + range.describe());
    return std::nullopt;
  }
  return v;
}

std::optional<std::int64_t> SpecReader::integer(const json& j, const std::string& path, std::int64_t lo,
                                                std::int64_t hi) {
  const std::string want = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!j.is_number()) {
    error(path, "expected " + want + ", got " + j.type_name());
    return std::nullopt;
  }
  if (j.is_number_integer() && !j.is_number_unsigned()) {
    const auto v = j.get<std::int64_t>();
    if (v < lo || v > hi) {
      error(path, "is " + std::to_string(v) + "; expected " + want);
      return std::nullopt;
    }
    return v;
  }
  const double v = j.get<double>();
  if (!std::isfinite(v) || v != std::floor(v)) {
    error(path, "is " + format_number(v) + "; expected " + want);
    return std::nullopt;
  }
  if (v < static_cast<double>(lo) || v > static_cast<double>(hi)) {
    error(path, "is " + format_number(v) + "; expected " + want);
    return std::nullopt;
  }
  return static_cast<std::int64_t>(v);
}

std::optional<std::string> SpecReader::string(const json& j, const std::string& path,
                                              std::size_t max_length) {
  if (!j.is_string()) {
    error(path, std::string("expected a string, got ") + j.type_name());
    return std::nullopt;
  }
  const auto& s = j.get_ref<const std::string&>();
  if (s.size() > max_length) {
    error(path, "is " + std::to_string(s.size()) + " characters long; at most " +
                    std::to_string(max_length));
    return std::nullopt;
  }
  return s;
}

std::optional<std::string> SpecReader::one_of(const json& j, const std::string& path,
                                              std::span<const std::string_view> allowed) {
  if (!j.is_string()) {
    error(path, "expected one of " + join(allowed) + ", got " + j.type_name());
    return std::nullopt;
  }
  const auto& s = j.get_ref<const std::string&>();
  if (std::find(allowed.begin(), allowed.end(), s) != allowed.end()) return s;
  const std::string near = nearest_word(s, allowed);
  const std::string shown = s.size() > 64 ? s.substr(0, 64) + "..." : s;
  error(path, "unknown value '" + shown + "'; expected one of " + join(allowed) +
                  (near.empty() ? "" : " (did you mean '" + near + "'?)"));
  return std::nullopt;
}

bool SpecReader::per_axis(const json& j, const std::string& path, int dim, std::string_view entry) {
  if (!j.is_array()) {
    error(path, "expected an array with one " + std::string(entry) + " per axis, got " + j.type_name());
    return false;
  }
  if (dim > 0 && j.size() != static_cast<std::size_t>(dim)) {
    error(path, "has " + std::to_string(j.size()) + " entries; expected " + std::to_string(dim) +
                    " (one per axis, dimension " + std::to_string(dim) + ")");
    return false;
  }
  return true;
}

std::optional<Vec3> SpecReader::vector(const json& j, const std::string& path, int dim) {
  if (!per_axis(j, path, dim, "number")) return std::nullopt;
  Vec3 v{0.0, 0.0, 0.0};
  bool ok = true;
  for (std::size_t i = 0; i < j.size() && i < 3; ++i) {
    const auto c = number(j[i], child_pointer(path, i));
    if (c) v[i] = *c;
    else ok = false;
  }
  if (!ok || dim <= 0) return std::nullopt;
  return v;
}

}  // namespace hmpm::api

// spec_reader.cpp — see spec_reader.hpp.
#include "spec_reader.hpp"

#include <algorithm>
#include <cmath>

namespace hmpm::api {

std::string escape_pointer_token(std::string_view token) {
  std::string out;
  out.reserve(token.size());
  for (char c : token) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

std::string child_pointer(const std::string& parent, std::string_view token) {
  return parent + "/" + escape_pointer_token(token);
}

std::string child_pointer(const std::string& parent, std::size_t index) {
  return parent + "/" + std::to_string(index);
}

namespace {

// Builds the document through nlohmann's SAX interface so that it knows,
// at every moment, the JSON pointer of the value being read: a number that
// overflows double is reported at its pointer, and so is a key that appears
// twice in one object (nlohmann's DOM parser would silently keep the last).
class DomBuilder {
 public:
  DomBuilder(json& root, std::vector<SpecError>& errors) : root_(root), errors_(errors) {}
  bool failed() const { return failed_; }

  bool null() { return value(json(nullptr)); }
  bool boolean(bool v) { return value(json(v)); }
  bool number_integer(json::number_integer_t v) { return value(json(v)); }
  bool number_unsigned(json::number_unsigned_t v) { return value(json(v)); }
  bool number_float(json::number_float_t v, const std::string&) { return value(json(v)); }
  bool string(json::string_t& v) { return value(json(std::move(v))); }
  bool binary(json::binary_t&) { return false; }  // not produced by JSON text
  bool start_object(std::size_t) { return open(json::object()); }
  bool start_array(std::size_t) { return open(json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(json::string_t& k) {
    if (stack_.back()->contains(k)) {
      errors_.push_back(
          {child_pointer(paths_.back(), k),
           "duplicate key '" + k.substr(0, 64) + "'; each key may appear once in an object"});
      failed_ = true;
    }
    key_ = std::move(k);
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) {
    std::string what = e.what();
    // Drop nlohmann's "[json.exception.parse_error.101] " prefix.
    if (const auto pos = what.find("] ");
        what.rfind("[json.exception.", 0) == 0 && pos != std::string::npos)
      what = what.substr(pos + 2);
    // A number too large for a double is well-formed JSON: say where it is.
    if (e.id == 406)
      errors_.push_back({next_pointer(), "is not a finite number: " + what});
    else
      errors_.push_back({"", "not valid JSON: " + what});
    failed_ = true;
    return false;
  }

 private:
  std::string next_pointer() const {
    if (stack_.empty()) return "";
    return stack_.back()->is_object() ? child_pointer(paths_.back(), key_)
                                      : child_pointer(paths_.back(), stack_.back()->size());
  }
  // Places `v` in the current container (or as the root); returns where.
  json* place(json&& v) {
    if (stack_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    json& parent = *stack_.back();
    if (parent.is_object()) {
      json& slot = parent[key_];
      slot = std::move(v);
      return &slot;
    }
    parent.push_back(std::move(v));
    return &parent.back();
  }
  bool value(json&& v) {
    place(std::move(v));
    return true;
  }
  bool open(json&& container) {
    std::string path = next_pointer();
    stack_.push_back(place(std::move(container)));
    paths_.push_back(std::move(path));
    return true;
  }
  bool close() {
    stack_.pop_back();
    paths_.pop_back();
    return true;
  }

  json& root_;
  std::vector<SpecError>& errors_;
  std::vector<json*> stack_;        // open containers, innermost last
  std::vector<std::string> paths_;  // their JSON pointers
  std::string key_;                 // last key read in the innermost object
  bool failed_ = false;
};

}  // namespace

bool parse_json_guarded(std::string_view text, int max_depth, json& out,
                        std::vector<SpecError>& errors) {
  return parse_json_guarded(text, max_depth, out, errors, TopArrayLimit{});
}

bool parse_json_guarded(std::string_view text, int max_depth, json& out,
                        std::vector<SpecError>& errors, const TopArrayLimit& limit) {
  // Pre-scan the nesting outside strings, so a hostile document costs O(n)
  // and no stack before anything is built; nothing in a spec needs more
  // than a handful of levels. It also counts the elements of the top-level
  // array `limit.key` (its commas at depth 2).
  int depth = 0;
  bool in_string = false, escaped = false;
  std::size_t line = 1;
  std::size_t string_start = 0;
  bool last_string_is_key = false;  // the last string closed at depth 1 is limit.key
  bool key_pending = false;         // ... and only its ':' followed it
  bool counting = false;            // inside the limited array
  std::size_t elements = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"') {
        in_string = false;
        last_string_is_key = depth == 1 && !limit.key.empty() &&
                             text.substr(string_start, i - string_start) == limit.key;
      }
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') continue;
    if (c == ':') {
      key_pending = last_string_is_key;
      last_string_is_key = false;
      continue;
    }
    const bool opens_array = c == '[' && key_pending && depth == 1;
    key_pending = last_string_is_key = false;
    if (opens_array) {
      counting = true;
      elements = 0;
    }
    if (counting && depth == 2 && (c == ',' || (elements == 0 && c != ']'))) {
      if (++elements > limit.max_elements) {
        errors.push_back({"/" + std::string(limit.key),
                          "has more than " + std::to_string(limit.max_elements) +
                              " elements; the limit is " + std::to_string(limit.max_elements) +
                              std::string(limit.advice)});
        return false;
      }
    }
    if (c == '"') {
      in_string = true;
      string_start = i + 1;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        errors.push_back({"", "not accepted: brackets nested deeper than " +
                                  std::to_string(max_depth) + " levels (byte " +
                                  std::to_string(i + 1) + ", line " + std::to_string(line) + ")"});
        return false;
      }
    } else if (c == ']' || c == '}') {
      depth = std::max(depth - 1, 0);
      if (depth == 1) counting = false;
    }
  }
  DomBuilder builder(out, errors);
  bool ok = false;
  try {
    ok = json::sax_parse(text.begin(), text.end(), &builder);
  } catch (const json::exception& e) {
    // sax_parse reports errors through the handler; this is a safety net.
    errors.push_back({"", std::string("not valid JSON: ") + e.what()});
    return false;
  }
  return ok && !builder.failed();
}

bool Range::contains(double v) const {
  const bool lo_ok = lo_open ? v > lo : v >= lo;
  const bool hi_ok = hi_open ? v < hi : v <= hi;
  return lo_ok && hi_ok;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string("in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " +
           format_number(hi) + (hi_open ? ")" : "]");
  if (has_lo) return std::string(lo_open ? "> " : ">= ") + format_number(lo);
  if (has_hi) return std::string(hi_open ? "< " : "<= ") + format_number(hi);
  return "finite";
}

std::string format_count(double v) {
  if (v >= 0 && v < 1e18 && v == std::floor(v)) return std::to_string(static_cast<std::int64_t>(v));
  return format_number(v);
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

bool SpecReader::object(const json& j, const std::string& path,
                        std::span<const std::string_view> known,
                        std::span<const std::string_view> required) {
  if (!j.is_object()) {
    error(path, std::string("expected an object, got ") + j.type_name());
    return false;
  }
  for (const auto& [key, value] : j.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    const std::string near = nearest_word(key, known);
    const std::string shown = key.size() > 64 ? key.substr(0, 64) + "..." : key;
    error(child_pointer(path, key),
          "unknown key '" + shown + "'; " +
              (near.empty() ? "expected one of " + join(known) : "did you mean '" + near + "'?"));
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

std::optional<double> SpecReader::number(const json& j, const std::string& path,
                                         const Range& range) {
  if (j.is_object() && j.contains("random_field")) {
    // The parameters that may vary are read before they get here (parse/materials.cpp).
    error(path,
          "cannot vary: a random field is allowed only for a material's youngs_modulus, "
          "cohesion, friction_angle and hydraulic.hydraulic_conductivity; expected a number " +
              range.describe());
    return std::nullopt;
  }
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

std::optional<bool> SpecReader::boolean(const json& j, const std::string& path) {
  if (j.is_boolean()) return j.get<bool>();
  error(path, std::string("expected true or false, got ") + j.type_name());
  return std::nullopt;
}

std::optional<std::int64_t> SpecReader::integer(const json& j, const std::string& path,
                                                std::int64_t lo, std::int64_t hi) {
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
  // Characters, not bytes (UTF-8, which the JSON parser has checked): every
  // byte but a continuation byte starts one.
  if (s.size() > max_length) {
    const auto characters = static_cast<std::size_t>(std::count_if(
        s.begin(), s.end(), [](char b) { return (static_cast<unsigned char>(b) & 0xC0) != 0x80; }));
    if (characters > max_length) {
      error(path, "is " + std::to_string(characters) + " characters long; at most " +
                      std::to_string(max_length));
      return std::nullopt;
    }
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
    error(path,
          "expected an array with one " + std::string(entry) + " per axis, got " + j.type_name());
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
    if (c)
      v[i] = *c;
    else
      ok = false;
  }
  if (!ok || dim <= 0) return std::nullopt;
  return v;
}

}  // namespace hmpm::api

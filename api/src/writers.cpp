// writers.cpp — see writers.hpp.
#include "writers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "hmpm/format.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path path) : path_(std::move(path)), tmp_(path_) {
  tmp_ += ".tmp";
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error("cannot create " + tmp_.string());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ec;
  fs::remove(tmp_, ec);
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) throw std::runtime_error("cannot write " + tmp_.string());
  out_.close();
  std::error_code ec;
  fs::rename(tmp_, path_, ec);
  if (ec)
    throw std::runtime_error("cannot rename " + tmp_.string() + " to " + path_.string() + ": " +
                             ec.message());
  committed_ = true;
}

namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

const char* const vector_suffix[] = {"x", "y", "z"};
const char* const tensor_suffix[] = {"xx", "yy", "zz", "xy", "yz", "zx"};

// Value of `field` (index f) for series particle p, row r, component c.
double series_value(const Series& s, std::size_t f, std::size_t r, std::size_t p, int nc, int c) {
  const std::size_t np = s.particles.size();
  const std::size_t i = (r * np + p) * static_cast<std::size_t>(nc) + static_cast<std::size_t>(c);
  return i < s.values[f].size() ? s.values[f][i] : std::nan("");
}

// Appends field f of series particle p at row r as JSON: a number for a
// scalar, an array of components for vectors and tensors (also with one
// component, 1D); then, past 64 KiB, flushes `line` to `out`.
void append_series_value(std::string& line, std::ostream& out, const Series& s, std::size_t f,
                         std::size_t r, std::size_t p) {
  const int nc = field_components(s.fields[f], s.dimension);
  const bool scalar = field_info(s.fields[f]).kind == FieldKind::scalar;
  if (!scalar) line += "[";
  for (int c = 0; c < nc; ++c) {
    if (c) line += ", ";
    append_json_number(line, series_value(s, f, r, p, nc, c));
  }
  if (!scalar) line += "]";
  if (line.size() > (1u << 16)) {
    out << line;
    line.clear();
  }
}

std::size_t series_rows(const Series& s) {
  return s.time.size();
}

}  // namespace

void write_summary(const fs::path& path, const std::string& job_name, const RunResult& run,
                   const CostEstimate& cost, const std::vector<std::string>& files) {
  std::string o = "{\n";
  auto field = [&](const char* key, const std::string& raw, bool last = false) {
    o += "  \"";
    o += key;
    o += "\": " + raw + (last ? "\n" : ",\n");
  };
  auto num = [](double v) {
    std::string s;
    append_json_number(s, v);
    return s;
  };
  field("status", json_string(status_name(run.status)));
  field("message", json_string(run.message));
  field("steps", std::to_string(run.steps));
  field("end_time", num(run.end_time));
  field("dt", num(run.dt));
  field("scheme", json_string(run.scheme));
  if (run.reports_iterations) {
    const RunResult::Iterations& it = run.iterations;
    std::string i = "{\"nonlinear\": ";
    i += std::to_string(it.nonlinear);
    i += ", \"linear\": " + std::to_string(it.linear);
    i += ", \"solves\": " + std::to_string(it.solves);
    i += ", \"cutbacks\": " + std::to_string(it.cutbacks);
    i += ", \"max_nonlinear\": " + std::to_string(it.max_nonlinear) + "}";
    field("iterations", i);
  }
  field("particles", std::to_string(run.particles));
  field("nodes", std::to_string(run.nodes));
  field("solve_seconds", num(run.solve_seconds));
  field("particle_steps_per_second", num(run.particle_steps_per_second));
  std::string warnings = "[";
  for (std::size_t i = 0; i < run.warnings.size(); ++i)
    warnings += (i ? ", " : "") + json_string(run.warnings[i]);
  field("warnings", warnings + "]");
  field("name", json_string(job_name));
  field("hmpm_version", json_string(version()));
  field("state_bytes", std::to_string(run.state_bytes));
  std::string c = "{\"particles\": " + std::to_string(cost.particles) +
                  ", \"nodes\": " + std::to_string(cost.nodes) +
                  ", \"cells\": " + std::to_string(cost.cells) +
                  ", \"steps\": " + std::to_string(cost.steps) + ", \"dt\": " + num(cost.dt) +
                  ", \"particle_steps\": " + std::to_string(cost.particle_steps) +
                  ", \"memory_bytes\": " + std::to_string(cost.memory_bytes) +
                  ", \"output_bytes\": " + std::to_string(cost.output_bytes) +
                  ", \"series_rows\": " + std::to_string(cost.series_rows) +
                  ", \"snapshots\": " + std::to_string(cost.snapshots) + "}";
  field("cost", c);
  std::string f = "[";
  for (std::size_t i = 0; i < files.size(); ++i) f += (i ? ", " : "") + json_string(files[i]);
  field("files", f + "]", true);
  o += "}\n";
  AtomicFile file(path);
  file.stream() << o;
  file.commit();
}

void write_series_json(const fs::path& path, const Series& s) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"time\": [";
  for (std::size_t r = 0; r < s.time.size(); ++r) {
    if (r) line += ", ";
    append_json_number(line, s.time[r]);
  }
  line += "],\n \"particles\": [";
  out << line;
  const std::size_t rows = series_rows(s);
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    line = p ? ",\n  {" : "\n  {";
    line += "\"index\": " + std::to_string(s.particles[p]) + ", \"initial_position\": [";
    for (int a = 0; a < s.dimension; ++a) {
      if (a) line += ", ";
      append_json_number(line, p < s.initial_positions.size()
                                   ? s.initial_positions[p][static_cast<std::size_t>(a)]
                                   : std::nan(""));
    }
    line += "]";
    out << line;
    for (std::size_t f = 0; f < s.fields.size() && f < s.values.size(); ++f) {
      line = ",\n   ";
      line += json_string(field_name(s.fields[f]));
      line += ": [";
      for (std::size_t r = 0; r < rows; ++r) {
        if (r) line += ", ";
        append_series_value(line, out, s, f, r, p);
      }
      line += "]";
      out << line;
    }
    out << "}";
  }
  out << "\n ]\n}\n";
  file.commit();
}

void write_series_csv(const fs::path& path, const Series& s) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "time";
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    for (std::size_t f = 0; f < s.fields.size(); ++f) {
      const int nc = field_components(s.fields[f], s.dimension);
      for (int c = 0; c < nc; ++c) {
        line += ",p" + std::to_string(s.particles[p]) + "_" + field_name(s.fields[f]);
        // Vectors always carry an axis suffix (also in 1D), scalars none.
        const FieldKind kind = field_info(s.fields[f]).kind;
        if (kind == FieldKind::tensor)
          line += std::string("_") + tensor_suffix[c];
        else if (kind == FieldKind::vector)
          line += std::string("_") + vector_suffix[c];
      }
    }
  }
  out << line << '\n';
  for (std::size_t r = 0; r < series_rows(s); ++r) {
    line.clear();
    append_number(line, s.time[r]);
    for (std::size_t p = 0; p < s.particles.size(); ++p)
      for (std::size_t f = 0; f < s.fields.size() && f < s.values.size(); ++f) {
        const int nc = field_components(s.fields[f], s.dimension);
        for (int c = 0; c < nc; ++c) {
          line += ',';
          append_number(line, series_value(s, f, r, p, nc, c));
        }
      }
    out << line << '\n';
  }
  file.commit();
}

namespace {

// The column names of a field ("pore_pressure", "effective_stress_xx", ...):
// vectors always carry an axis suffix (also in 1D), scalars none.
std::vector<std::string> field_columns(Field field, int dimension) {
  std::vector<std::string> out;
  const FieldKind kind = field_info(field).kind;
  for (int c = 0; c < field_components(field, dimension); ++c) {
    std::string name = field_name(field);
    if (kind == FieldKind::tensor) name += std::string("_") + tensor_suffix[c];
    if (kind == FieldKind::vector) name += std::string("_") + vector_suffix[c];
    out.push_back(std::move(name));
  }
  return out;
}

void append_point(std::string& line, const Vec3& x, int dimension) {
  line += "[";
  for (int a = 0; a < dimension; ++a) {
    if (a) line += ", ";
    append_json_number(line, x[static_cast<std::size_t>(a)]);
  }
  line += "]";
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

void write_profiles_json(const fs::path& path, const std::vector<Series>& profiles,
                         const std::vector<ProfileGeometry>& geometry) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"time\": [";
  const std::vector<double> no_times;
  const std::vector<double>& times = profiles.empty() ? no_times : profiles[0].time;
  for (std::size_t r = 0; r < times.size(); ++r) {
    if (r) line += ", ";
    append_json_number(line, times[r]);
  }
  line += "],\n \"profiles\": [";
  out << line;
  for (std::size_t l = 0; l < profiles.size() && l < geometry.size(); ++l) {
    const Series& s = profiles[l];
    const ProfileGeometry& g = geometry[l];
    line = l ? ",\n  {" : "\n  {";
    line += "\"index\": " + std::to_string(l) + ", \"from\": ";
    append_point(line, g.from, s.dimension);
    line += ", \"to\": ";
    append_point(line, g.to, s.dimension);
    line += ",\n   \"points\": [";
    for (std::size_t k = 0; k < g.points.size(); ++k) {
      if (k) line += ", ";
      append_point(line, g.points[k], s.dimension);
    }
    line += "],\n   \"distance\": [";
    for (std::size_t k = 0; k < g.points.size(); ++k) {
      if (k) line += ", ";
      append_json_number(line, distance(g.points[k], g.from));
    }
    line += "],\n   \"particles\": [";
    for (std::size_t k = 0; k < s.particles.size(); ++k) {
      if (k) line += ", ";
      line += std::to_string(s.particles[k]);
    }
    line += "],\n   \"initial_positions\": [";
    for (std::size_t k = 0; k < s.initial_positions.size(); ++k) {
      if (k) line += ", ";
      append_point(line, s.initial_positions[k], s.dimension);
    }
    line += "]";
    out << line;
    for (std::size_t f = 0; f < s.fields.size() && f < s.values.size(); ++f) {
      line = ",\n   " + json_string(field_name(s.fields[f])) + ": [";
      for (std::size_t r = 0; r < s.time.size(); ++r) {
        line += r ? ",\n    [" : "\n    [";
        for (std::size_t k = 0; k < s.particles.size(); ++k) {
          if (k) line += ", ";
          append_series_value(line, out, s, f, r, k);
        }
        line += "]";
      }
      line += "]";
      out << line;
    }
    out << "}";
  }
  out << "\n ]\n}\n";
  file.commit();
}

namespace {
double average_excess(const RunResult::Consolidation& c, std::size_t k) {
  return k < c.volume.size() && c.volume[k] > 0 ? c.excess[k] / c.volume[k] : std::nan("");
}
}  // namespace

void write_consolidation_json(const fs::path& path, const RunResult::Consolidation& c,
                              double from) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"from\": ";
  append_json_number(line, from);
  line += ", \"t50\": ";
  append_json_number(line, c.t50);
  line += ", \"t90\": ";
  append_json_number(line, c.t90);
  auto column = [&](const char* name, auto value) {
    line += ",\n \"";
    line += name;
    line += "\": [";
    for (std::size_t k = 0; k < c.time.size(); ++k) {
      if (k) line += ", ";
      append_json_number(line, value(k));
    }
    line += "]";
    out << line;
    line.clear();
  };
  column("time", [&](std::size_t k) { return c.time[k]; });
  column("degree", [&](std::size_t k) { return k < c.degree.size() ? c.degree[k] : std::nan(""); });
  column("average_excess_pore_pressure", [&](std::size_t k) { return average_excess(c, k); });
  column("volume", [&](std::size_t k) { return k < c.volume.size() ? c.volume[k] : std::nan(""); });
  out << "\n}\n";
  file.commit();
}

void write_consolidation_csv(const fs::path& path, const RunResult::Consolidation& c) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "time,degree,average_excess_pore_pressure,volume\n";
  std::string line;
  for (std::size_t k = 0; k < c.time.size(); ++k) {
    line.clear();
    append_number(line, c.time[k]);
    line += ',';
    append_number(line, k < c.degree.size() ? c.degree[k] : std::nan(""));
    line += ',';
    append_number(line, average_excess(c, k));
    line += ',';
    append_number(line, k < c.volume.size() ? c.volume[k] : std::nan(""));
    out << line << '\n';
  }
  file.commit();
}

void write_profiles_csv(const fs::path& path, const std::vector<Series>& profiles,
                        const std::vector<ProfileGeometry>& geometry) {
  // One row per time, profile and point; the columns of every field any
  // profile has (empty where a profile does not have it).
  std::vector<Field> fields;
  int dimension = 1;
  for (const Series& s : profiles) {
    dimension = s.dimension;
    for (Field f : s.fields)
      if (std::find(fields.begin(), fields.end(), f) == fields.end()) fields.push_back(f);
  }
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "time,profile,point,distance";
  for (Field f : fields)
    for (const std::string& column : field_columns(f, dimension)) {
      line += ',';
      line += column;
    }
  out << line << '\n';
  const std::size_t rows = profiles.empty() ? 0 : profiles[0].time.size();
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t l = 0; l < profiles.size() && l < geometry.size(); ++l) {
      const Series& s = profiles[l];
      for (std::size_t k = 0; k < s.particles.size() && k < geometry[l].points.size(); ++k) {
        line.clear();
        append_number(line, r < s.time.size() ? s.time[r] : std::nan(""));
        // Piece by piece: GCC 12 warns (-Wstringop-overflow, a false
        // positive) on "literal" + std::string&& here, fatal under -Werror.
        line += ',';
        line += std::to_string(l);
        line += ',';
        line += std::to_string(k);
        line += ',';
        append_number(line, distance(geometry[l].points[k], geometry[l].from));
        for (Field f : fields) {
          const auto at = std::find(s.fields.begin(), s.fields.end(), f);
          const int nc = field_components(f, dimension);
          for (int c = 0; c < nc; ++c) {
            line += ',';
            if (at != s.fields.end())
              append_number(line, series_value(s, static_cast<std::size_t>(at - s.fields.begin()),
                                               r, k, nc, c));
          }
        }
        out << line << '\n';
      }
    }
  file.commit();
}

void write_reactions_json(const fs::path& path, const Reactions& r) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"time\": [";
  for (std::size_t k = 0; k < r.time.size(); ++k) {
    if (k) line += ", ";
    append_json_number(line, r.time[k]);
  }
  line += "],\n \"boundaries\": [";
  out << line;
  const auto d = static_cast<std::size_t>(r.dimension);
  for (std::size_t b = 0; b < r.force.size(); ++b) {
    line = b ? ",\n  {" : "\n  {";
    line += "\"index\": " + std::to_string(b) + ", \"force\": [";
    for (std::size_t k = 0; k < r.time.size(); ++k) {
      line += k ? ", [" : "[";
      for (std::size_t a = 0; a < d; ++a) {
        if (a) line += ", ";
        const std::size_t i = k * d + a;
        append_json_number(line, i < r.force[b].size() ? r.force[b][i] : std::nan(""));
      }
      line += "]";
      if (line.size() > (1u << 16)) {
        out << line;
        line.clear();
      }
    }
    out << line << "]}";
  }
  out << "\n ]\n}\n";
  file.commit();
}

void write_reactions_csv(const fs::path& path, const Reactions& r) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  const auto d = static_cast<std::size_t>(r.dimension);
  std::string line = "time";
  for (std::size_t b = 0; b < r.force.size(); ++b)
    for (std::size_t a = 0; a < d; ++a)
      line += ",b" + std::to_string(b) + "_force_" + vector_suffix[a];
  out << line << '\n';
  for (std::size_t k = 0; k < r.time.size(); ++k) {
    line.clear();
    append_number(line, r.time[k]);
    for (const std::vector<double>& f : r.force)
      for (std::size_t a = 0; a < d; ++a) {
        line += ',';
        const std::size_t i = k * d + a;
        append_number(line, i < f.size() ? f[i] : std::nan(""));
      }
    out << line << '\n';
  }
  file.commit();
}

// ------------------------------------------------------------------- VTU

namespace {

constexpr char base64_digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// Streams base64 of a byte sequence fed in pieces.
class Base64Writer {
 public:
  explicit Base64Writer(std::ostream& out) : out_(out) {}
  void write(const void* data, std::size_t n) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      pending_[count_++] = bytes[i];
      if (count_ == 3) flush_group();
    }
    if (buffer_.size() > (1u << 16)) {
      out_ << buffer_;
      buffer_.clear();
    }
  }
  void finish() {
    if (count_ > 0) {
      const std::size_t n = count_;
      for (std::size_t i = n; i < 3; ++i) pending_[i] = 0;
      flush_group();
      buffer_.resize(buffer_.size() - (3 - n));
      buffer_.append(3 - n, '=');
    }
    out_ << buffer_;
    buffer_.clear();
  }

 private:
  void flush_group() {
    const unsigned v = (unsigned{pending_[0]} << 16) | (unsigned{pending_[1]} << 8) | pending_[2];
    buffer_ += base64_digits[(v >> 18) & 63];
    buffer_ += base64_digits[(v >> 12) & 63];
    buffer_ += base64_digits[(v >> 6) & 63];
    buffer_ += base64_digits[v & 63];
    count_ = 0;
  }
  std::ostream& out_;
  unsigned char pending_[3] = {0, 0, 0};
  std::size_t count_ = 0;
  std::string buffer_;
};

// Text for an XML attribute value.
std::string xml_escaped(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

// One inline binary DataArray: UInt64 byte count then the values, encoded
// together (uncompressed layout of the VTK XML format).
template <typename T, typename Source>
void data_array(std::ostream& out, const char* type, const std::string& name, int components,
                std::size_t count, Source value) {
  out << "        <DataArray type=\"" << type << "\"";
  if (!name.empty()) out << " Name=\"" << name << "\"";
  if (components > 1) out << " NumberOfComponents=\"" << components << "\"";
  // Component names (shown by ParaView in its component menus).
  if (components == 3 || components == 6)
    for (int c = 0; c < components; ++c)
      out << " ComponentName" << c << "=\"" << (components == 3 ? vector_suffix : tensor_suffix)[c]
          << "\"";
  out << " format=\"binary\">\n";
  Base64Writer b64(out);
  const std::uint64_t bytes =
      static_cast<std::uint64_t>(count) * static_cast<std::uint64_t>(components) * sizeof(T);
  b64.write(&bytes, sizeof bytes);
  for (std::size_t i = 0; i < count * static_cast<std::size_t>(components); ++i) {
    const T v = value(i);
    b64.write(&v, sizeof v);
  }
  b64.finish();
  out << "\n        </DataArray>\n";
}

const std::vector<double>* snapshot_array(const Snapshot& s, Field f) {
  switch (f) {
    case Field::position:
      return &s.position;
    case Field::displacement:
      return &s.displacement;
    case Field::velocity:
      return &s.velocity;
    case Field::pore_pressure:
      return &s.pore_pressure;
    case Field::darcy_velocity:
      return &s.darcy_velocity;
    case Field::effective_stress:
      return &s.effective_stress;
    case Field::total_stress:
      return &s.total_stress;
    case Field::strain:
      return &s.strain;
    case Field::porosity:
      return &s.porosity;
    case Field::plastic_strain:
      return &s.plastic_strain;
  }
  return nullptr;
}

}  // namespace

std::string snapshot_file_name(int index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "snapshot_%04d.vtu", index);
  return buf;
}

void write_snapshot_vtu(const fs::path& path, const Snapshot& s,
                        const std::vector<std::string>& material_names) {
  static_assert(sizeof(double) == 8, "Float64 arrays");
  const auto n = static_cast<std::size_t>(std::max<std::int64_t>(s.particles, 0));
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
         "  <UnstructuredGrid>\n"
         "    <FieldData>\n"
         "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
         "format=\"ascii\">";
  std::string t;
  append_number(t, s.time);
  out << t << "</DataArray>\n";
  // Each material's name as the name of a one-value Int32 array holding
  // its index ("material clay" = 0): readable in ParaView's information
  // panel and by meshio, which reads no string arrays.
  for (std::size_t m = 0; m < material_names.size(); ++m)
    out << "      <DataArray type=\"Int32\" Name=\"material " << xml_escaped(material_names[m])
        << "\" NumberOfTuples=\"1\" format=\"ascii\">" << m << "</DataArray>\n";
  out << "    </FieldData>\n";
  out << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n
      << "\">\n      <PointData>\n";
  for (Field f : s.fields) {
    if (f == Field::position) continue;  // the Points
    const std::vector<double>* a = snapshot_array(s, f);
    const int nc = field_components(f, 3);
    if (a == nullptr || a->size() != n * static_cast<std::size_t>(nc)) continue;
    data_array<double>(out, "Float64", field_name(f), nc, n,
                       [&](std::size_t i) { return (*a)[i]; });
  }
  if (s.volume.size() == n)
    data_array<double>(out, "Float64", "volume", 1, n, [&](std::size_t i) { return s.volume[i]; });
  if (s.material.size() == n)
    data_array<std::int32_t>(out, "Int32", "material", 1, n,
                             [&](std::size_t i) { return s.material[i]; });
  out << "      </PointData>\n      <Points>\n";
  const bool have_points = s.position.size() == 3 * n;
  data_array<double>(out, "Float64", "Points", 3, n,
                     [&](std::size_t i) { return have_points ? s.position[i] : 0.0; });
  out << "      </Points>\n      <Cells>\n";
  data_array<std::int64_t>(out, "Int64", "connectivity", 1, n,
                           [](std::size_t i) { return static_cast<std::int64_t>(i); });
  data_array<std::int64_t>(out, "Int64", "offsets", 1, n,
                           [](std::size_t i) { return static_cast<std::int64_t>(i + 1); });
  data_array<std::uint8_t>(out, "UInt8", "types", 1, n,
                           [](std::size_t) { return std::uint8_t{1}; });  // VTK_VERTEX
  out << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  file.commit();
}

void write_pvd(const fs::path& path, const std::vector<std::pair<double, std::string>>& entries) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  for (const auto& [time, name] : entries) {
    std::string t;
    append_number(t, time);
    out << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << name
        << "\"/>\n";
  }
  out << "  </Collection>\n</VTKFile>\n";
  file.commit();
}

}  // namespace hmpm::api

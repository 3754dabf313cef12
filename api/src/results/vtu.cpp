// results/vtu.cpp — snapshots (.vtu) and their collection (.pvd) (results/writers.hpp).
#include "results/writers.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include "hmpm/format.hpp"
#include "results/columns.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;
using results::tensor_suffix;
using results::vector_suffix;

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
    case Field::youngs_modulus:
      return &s.youngs_modulus;
    case Field::cohesion:
      return &s.cohesion;
    case Field::friction_angle:
      return &s.friction_angle;
    case Field::hydraulic_conductivity:
      return &s.hydraulic_conductivity;
    case Field::excess_pore_pressure:
      return &s.excess_pore_pressure;
    case Field::void_ratio:
      return &s.void_ratio;
    case Field::preconsolidation_pressure:
      return &s.preconsolidation_pressure;
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
  if (s.id.size() == n)
    data_array<std::int64_t>(out, "Int64", "particle_id", 1, n,
                             [&](std::size_t i) { return s.id[i]; });
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

// fields.cpp — GET /fields: the output fields with their kinds and units,
// from the solver's table (solver/include/hmpm/fields.hpp). The dashboard
// and the Python client label their plots from it instead of keeping copies.
#include "hmpm/fields.hpp"
#include "handlers.hpp"
#include "problem.hpp"

namespace hmpm::server::http {

void get_fields(Context&, const httplib::Request&, httplib::Response& res) {
  Json fields = Json::array();
  for (const FieldInfo& f : field_table) {
    fields.push_back({{"name", std::string(f.name)},
                      {"kind", std::string(kind_name(f.kind))},
                      {"unit", std::string(f.unit)}});
  }
  send_json(res, 200, Json{{"fields", fields}, {"time_unit", "s"}, {"length_unit", "m"}});
}

}  // namespace hmpm::server::http

// Proof of accuracy in the shop (ISO 20685-1): staff enter the tape measurements
// they took of a scanned customer, and the workstation reports, per measurement,
// how far the scanner's values lie from the tape (pipeline/tape_validation.hpp),
// as JSON and as a PDF for the shop's files.
#include <cmath>
#include <ctime>

#include "core/json_text.hpp"
#include "pipeline/tape_validation.hpp"
#include "server/api/api.hpp"
#include "storage/archive/ids.hpp"
#include "storage/formats/validation_report.hpp"

namespace bodyscan::server {

namespace {

HttpResponse scan_tape(Workstation& ws, const std::string& scan_id) {
  auto r = ws.archive().scan(scan_id);
  if (!r.ok()) return error_response(r.status());
  auto tape = ws.archive().tape_measurements(scan_id);
  if (!tape.ok()) return error_response(tape.status());
  nlohmann::json out = nlohmann::json::array();
  for (const storage::TapeMeasurement& t : *tape) out.push_back(storage::to_json(t));
  return json_response(200, {{"scan_id", scan_id}, {"tape", out}});
}

HttpResponse put_tape(Workstation& ws, const Call& call) {
  HttpResponse error;
  auto body = json_body(call, &error);
  if (!body) return error;
  const auto value = body->find("value_mm");
  if (value == body->end() || !value->is_number() || !std::isfinite(value->get<double>()))
    return error_response(400, "'value_mm' is the tape's reading in millimetres");
  const std::optional<std::string> measured_by = string_field(*body, "measured_by", call.actor());
  if (!measured_by || measured_by->empty() || measured_by->size() > 200)
    return error_response(400, "'measured_by' names who took the measurement (up to 200 characters)");
  storage::TapeMeasurement t;
  t.scan_id = call.params.at("id");
  t.name = call.params.at("name");
  t.value_mm = value->get<double>();
  t.measured_by = *measured_by;
  const Status st = ws.archive().put_tape_measurement(t, call.actor());
  if (!st.ok()) return error_response(st);
  return scan_tape(ws, t.scan_id);
}

}  // namespace

void add_validation_routes(std::vector<Api::Route>* routes, const ApiOptions& options) {
  routes->push_back({"GET", "/api/scans/{id}/tape", kStaff,
                     [](Workstation& ws, const Call& call) { return scan_tape(ws, call.params.at("id")); }});
  routes->push_back({"PUT", "/api/scans/{id}/tape/{name}", kStaff, put_tape});
  routes->push_back({"DELETE", "/api/scans/{id}/tape/{name}", kStaff, [](Workstation& ws, const Call& call) {
                       const Status st = ws.archive().delete_tape_measurement(call.params.at("id"),
                                                                              call.params.at("name"), call.actor());
                       if (!st.ok()) return error_response(st);
                       return no_content();
                     }});
  routes->push_back({"GET", "/api/validation", kStaff, [](Workstation& ws, const Call&) {
                       auto report = pipeline::validate_against_tape(ws.archive());
                       if (!report.ok()) return error_response(report.status());
                       return json_response(200, pipeline::to_json(*report));
                     }});
  routes->push_back(
      {"GET", "/api/validation.pdf", kStaff, [shop = options.shop_name](Workstation& ws, const Call& call) {
         auto report = pipeline::validate_against_tape(ws.archive());
         if (!report.ok()) return error_response(report.status());
         auto pdf =
             storage::validation_report_pdf(pipeline::to_json(*report), shop, storage::iso8601_utc(std::time(nullptr)));
         if (!pdf.ok()) return error_response(pdf.status());
         HttpResponse out = file_response(std::move(*pdf), "application/pdf", "validation-iso-20685-1.pdf");
         ws.archive().log(call.actor(), "export validation report", "archive", "", "pdf");
         return out;
       }});
}

}  // namespace bodyscan::server

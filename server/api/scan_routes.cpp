// Customers and their scans: search, details, the served files (GLB, Draco cloud)
// with ETags, the measurements (automatic and saved), evaluating a measurement the
// browser draws, measurement sheets, avatars for CAD tools, deleting and
// reprocessing.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/json_text.hpp"
#include "pipeline/archive_scan.hpp"
#include "pipeline/cad_avatar.hpp"
#include "pipeline/evaluate_measurement.hpp"
#include "pipeline/repeat_scans.hpp"
#include "recon/io/atomic_file.hpp"
#include "server/api/api.hpp"
#include "server/api/scan_views.hpp"
#include "server/workstation/erasure.hpp"
#include "storage/formats/export_profiles.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::server {

namespace {

nlohmann::json customer_json(const storage::Customer& c) {
  return {{"id", c.id},
          {"name", c.name ? nlohmann::json(*c.name) : nlohmann::json()},
          {"contact", c.contact ? nlohmann::json(*c.contact) : nlohmann::json()},
          {"created_at", c.created_at},
          {"consent", c.consent ? nlohmann::json{{"given_at", c.consent->given_at},
                                                 {"recorded_by", c.consent->recorded_by},
                                                 {"terms", c.consent->terms}}
                                : nlohmann::json()}};
}

nlohmann::json scan_json(const storage::ScanRecord& r) {
  nlohmann::json versions = nlohmann::json::array();
  for (const storage::ScanVersion& v : r.versions) {
    nlohmann::json files = nlohmann::json::array();
    for (const storage::ArchivedFile& f : v.files) files.push_back({{"name", f.name}, {"bytes", f.bytes}});
    versions.push_back({{"version", v.version},
                        {"created_at", v.created_at},
                        {"algorithms", v.algorithms},
                        {"note", v.note},
                        {"files", files}});
  }
  return {{"id", r.id},
          {"customer_id", r.customer_id},
          {"operator", r.operator_name},
          {"calibration_id", r.calibration_id},
          {"status", storage::to_string(r.status)},
          {"status_reason", r.status_reason},
          {"started_at", r.started_at},
          {"finished_at", r.finished_at},
          {"current_version", r.current_version},
          {"versions", versions}};
}

}  // namespace

// A scan's result file, served from the archive. The current version revalidates
// (a reprocess changes it); a named version never changes.
HttpResponse scan_file(Workstation& ws, const std::string& scan_id, const std::string& name,
                       const std::string& version_text, const std::string& if_none_match) {
  int version = 0;
  if (!version_text.empty()) {
    char* end = nullptr;
    const long v = std::strtol(version_text.c_str(), &end, 10);
    if (*end != '\0' || v < 1 || v > 1000000) return error_response(400, "'version' is a version number (1, 2, ...)");
    version = static_cast<int>(v);
  }
  auto r = ws.archive().scan(scan_id);
  if (!r.ok()) return error_response(r.status());
  const int wanted = version == 0 ? r->current_version : version;
  auto path = ws.archive().file_path(scan_id, wanted, name);
  if (!path.ok()) return error_response(path.status());
  std::string etag;
  for (const storage::ScanVersion& v : r->versions)
    if (v.version == wanted)
      for (const storage::ArchivedFile& f : v.files)
        if (f.name == name) etag = "\"" + f.blake2b.substr(0, 32) + "\"";
  HttpResponse out;
  out.set("Content-Type",
          name.size() > 4 && name.substr(name.size() - 4) == ".glb" ? "model/gltf-binary" : "application/octet-stream");
  out.set("ETag", etag);
  out.set("Cache-Control", version ? "private, max-age=31536000, immutable" : "private, no-cache");
  if (!etag.empty() && if_none_match == etag) {
    out.status = 304;
    return out;
  }
  // Read here, on the worker pool, and sent in one piece: the network thread
  // never touches the disk, and a 1 MB model leaves in a few large writes.
  auto bytes = read_whole_file(*path);
  if (!bytes.ok()) return error_response(bytes.status());
  out.body = std::move(*bytes);
  return out;
}

namespace {

// A cached JSON body: 304 on a matching ETag, gzip when the client takes it.
HttpResponse cached_json(const Workstation::CachedText& text, const HttpRequest& request) {
  HttpResponse out;
  out.set("Content-Type", "application/json");
  out.set("Cache-Control", "private, no-cache");
  out.set("ETag", text.etag);
  out.set("Vary", "Accept-Encoding");
  if (request.header("if-none-match") == text.etag) {
    out.status = 304;
    return out;
  }
  if (!text.gzip.empty() && request.header("accept-encoding").find("gzip") != std::string::npos) {
    out.body = text.gzip;
    out.set("Content-Encoding", "gzip");
  } else {
    out.body = text.body;
  }
  return out;
}

HttpResponse sheet(Workstation& ws, const Call& call, const std::string& format) {
  // A CSV's layout is the export profile's (storage/formats/export_profiles.hpp),
  // its unit the profile's own unless one is asked for.
  auto profile = storage::find_export_profile(call.request.param("profile", "sheet"));
  if (!profile.ok()) return error_response(400, profile.status().message());
  if (format != "csv" && profile->id != "sheet")
    return error_response(400, "export profiles lay out the CSV; the " + format + " sheet has one layout");
  auto unit = storage::parse_length_unit(call.request.param("unit", storage::unit_symbol(profile->default_unit)));
  if (!unit.ok()) return error_response(400, unit.status().message());
  const std::string& id = call.params.at("id");
  auto s = pipeline::archived_sheet(ws.archive(), id);
  if (!s.ok()) return error_response(s.status());
  std::string body, type;
  if (format == "csv") {
    body = storage::profile_csv(*s, *profile, *unit), type = "text/csv; charset=utf-8";
  } else if (format == "json") {
    body = storage::sheet_json(*s, *unit).dump(1), type = "application/json";
  } else {
    auto mesh = ws.surface(id);
    const TriangleMesh empty;
    auto pdf = storage::sheet_pdf(*s, mesh.ok() ? **mesh : empty, *unit);
    if (!pdf.ok()) return error_response(pdf.status());
    body = std::move(*pdf), type = "application/pdf";
  }
  const std::string suffix = profile->id == "sheet" ? "measurements" : profile->id;
  HttpResponse out = file_response(std::move(body), type, id + "-" + suffix + "." + format);
  ws.archive().log(call.actor(), "export sheet", "scan", id,
                   profile->id == "sheet" ? format : format + ", " + profile->id);
  return out;
}

// A decimated avatar of the scan's current surface for CAD tools
// (pipeline/cad_avatar.hpp): ?triangles=N (default 70000), ?unit=mm|m (OBJ).
HttpResponse avatar(Workstation& ws, const Call& call, pipeline::AvatarFormat format) {
  pipeline::AvatarOptions options;
  options.format = format;
  const std::string budget = call.request.param("triangles", "70000");
  char* end = nullptr;
  const unsigned long long n = std::strtoull(budget.c_str(), &end, 10);
  if (budget.empty() || *end != '\0' || budget[0] == '-' || n < pipeline::kMinAvatarTriangles ||
      n > pipeline::kMaxAvatarTriangles)
    return error_response(400, "'triangles' is a whole number from " + std::to_string(pipeline::kMinAvatarTriangles) +
                                   " to " + std::to_string(pipeline::kMaxAvatarTriangles));
  options.max_triangles = static_cast<size_t>(n);
  const bool glb = format == pipeline::AvatarFormat::kGlb;
  auto unit = pipeline::parse_model_unit(call.request.param("unit", glb ? "m" : "mm"));
  if (!unit.ok()) return error_response(400, unit.status().message());
  if (glb && *unit != storage::ModelUnit::kMetre)
    return error_response(400, "a glTF avatar is in metres, as glTF defines ('unit' is for OBJ)");
  options.unit = *unit;
  const std::string& id = call.params.at("id");
  auto mesh = ws.surface(id);
  if (!mesh.ok()) return error_response(mesh.status());
  auto a = pipeline::make_avatar(**mesh, options);
  if (!a.ok()) return error_response(a.status());
  const char* ext = format == pipeline::AvatarFormat::kObj ? "obj" : "glb";
  HttpResponse out =
      file_response(std::move(a->bytes), format == pipeline::AvatarFormat::kObj ? "model/obj" : "model/gltf-binary",
                    id + "-avatar." + ext);
  out.set("X-Avatar-Triangles", std::to_string(a->triangles));
  out.set("X-Avatar-Closed", a->closed ? "true" : "false");
  char deviation[32];
  std::snprintf(deviation, sizeof deviation, "%.2f", a->max_deviation_mm);
  out.set("X-Avatar-Deviation-Mm", deviation);
  ws.archive().log(call.actor(), "export avatar", "scan", id,
                   std::string(ext) + ", " + std::to_string(a->triangles) + " triangles");
  return out;
}

}  // namespace

void add_scan_routes(std::vector<Api::Route>* routes) {
  // What a customer agrees to before their first scan, for the station to show.
  routes->push_back({"GET", "/api/consent", kStaff, [](Workstation& ws, const Call&) {
                       return json_response(200, {{"terms", ws.consent_terms()}});
                     }});
  routes->push_back({"GET", "/api/customers", kStaff, [](Workstation& ws, const Call& call) {
                       auto list = ws.archive().customers(call.request.param("q"));
                       if (!list.ok()) return error_response(list.status());
                       nlohmann::json out = nlohmann::json::array();
                       for (const auto& c : *list) out.push_back(customer_json(c));
                       return json_response(200, {{"customers", out}});
                     }});
  routes->push_back({"POST", "/api/customers", kOperator | kAdmin, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       auto text = [&](const char* k) -> std::optional<std::string> {
                         return body->contains(k) && (*body)[k].is_string()
                                    ? std::optional<std::string>((*body)[k].get<std::string>())
                                    : std::nullopt;
                       };
                       auto c = ws.archive().add_customer(text("name"), text("contact"), call.actor());
                       if (!c.ok()) return error_response(c.status());
                       return json_response(201, customer_json(*c));
                     }});
  routes->push_back({"GET", "/api/customers/{id}", kStaff, [](Workstation& ws, const Call& call) {
                       auto c = ws.archive().customer(call.params.at("id"));
                       if (!c.ok()) return error_response(c.status());
                       storage::ScanQuery q;
                       q.customer_id = c->id;
                       auto scans = ws.archive().scans(q);
                       if (!scans.ok()) return error_response(scans.status());
                       nlohmann::json out = customer_json(*c);
                       out["scans"] = nlohmann::json::array();
                       for (const auto& s : *scans) out["scans"].push_back(scan_json(s));
                       return json_response(200, out);
                     }});
  routes->push_back({"DELETE", "/api/customers/{id}", kAdmin, [](Workstation& ws, const Call& call) {
                       const std::string& id = call.params.at("id");
                       if (auto j = ws.current_job(); j && j->customer_id == id)
                         return error_response(409, "a job for customer " + id + " is running (scan " + j->scan_id +
                                                        "); cancel it first");
                       const Status st = erase_customer(ws.archive(), &ws.auth(), id, call.actor());
                       if (!st.ok()) return error_response(st);
                       return no_content();
                     }});
  routes->push_back({"GET", "/api/scans", kStaff, [](Workstation& ws, const Call& call) {
                       storage::ScanQuery q;
                       q.customer_id = call.request.param("customer");
                       q.text = call.request.param("q");
                       q.from = call.request.param("from");
                       q.to = call.request.param("to");
                       const std::string limit = call.request.param("limit", "100");
                       char* end = nullptr;
                       const long n = std::strtol(limit.c_str(), &end, 10);
                       if (*end != '\0' || n < 1 || n > 1000) return error_response(400, "'limit' is 1 to 1000");
                       q.limit = static_cast<int>(n);
                       auto list = ws.archive().scans(q);
                       if (!list.ok()) return error_response(list.status());
                       nlohmann::json out = nlohmann::json::array();
                       for (const auto& s : *list) out.push_back(scan_json(s));
                       return json_response(200, {{"scans", out}});
                     }});
  routes->push_back({"GET", "/api/scans/{id}", kStaff, [](Workstation& ws, const Call& call) {
                       auto r = ws.archive().scan(call.params.at("id"));
                       if (!r.ok()) return error_response(r.status());
                       return json_response(200, scan_json(*r));
                     }});
  routes->push_back({"DELETE", "/api/scans/{id}", kAdmin, [](Workstation& ws, const Call& call) {
                       const std::string& id = call.params.at("id");
                       if (auto j = ws.current_job(); j && j->scan_id == id)
                         return error_response(409, "scan " + id + " is being processed; cancel the job first");
                       const Status st = erase_scan(ws.archive(), &ws.auth(), id, call.actor());
                       if (!st.ok()) return error_response(st);
                       return no_content();
                     }});
  routes->push_back({"POST", "/api/scans/{id}/reprocess", kAdmin, [](Workstation& ws, const Call& call) {
                       auto j = ws.start_reprocess(call.params.at("id"), call.actor());
                       if (!j.ok()) return error_response(j.status());
                       HttpResponse r = json_response(202, {{"job", to_json(*j)}});
                       r.set("Location", "/api/jobs/" + j->id);
                       return r;
                     }});
  for (const char* name : {"mesh.glb", "points.drc"}) {
    routes->push_back(
        {"GET", std::string("/api/scans/{id}/") + name, kStaff, [name](Workstation& ws, const Call& call) {
           return scan_file(ws, call.params.at("id"), name, call.request.param("version"),
                            call.request.header("if-none-match"));
         }});
  }
  routes->push_back(
      {"GET", "/api/scans/{id}/measurements", kStaff, [](Workstation& ws, const Call& call) {
         const std::string& id = call.params.at("id");
         auto text = ws.cached_text("measurements/" + id, [&]() -> StatusOr<std::string> {
           ASSIGN_OR_RETURN(storage::ScanRecord r, ws.archive().scan(id));
           ASSIGN_OR_RETURN(std::vector<storage::MeasurementRecord> ms, ws.archive().measurements(id));
           nlohmann::json out = nlohmann::json::array();
           for (const auto& m : ms) out.push_back(storage::to_json(m));
           // How the customer stood, as the measurements read it (scan.json).
           nlohmann::json posture = nullptr;
           if (auto path = ws.archive().file_path(id, 0, "scan.json"); path.ok())
             if (auto scan = read_whole_file(*path); scan.ok()) {
               const nlohmann::json j = parse_json(*scan);
               if (j.is_object() && j.contains("posture")) posture = j["posture"];
             }
           return nlohmann::json{
               {"scan_id", id}, {"version", r.current_version}, {"measurements", out}, {"posture", posture}}
               .dump();
         });
         if (!text.ok()) return error_response(text.status());
         return cached_json(**text, call.request);
       }});
  // The scan against its customer's earlier scan the same day: the values that
  // differ by more than the shop's repeatability (pipeline/repeat_scans.hpp).
  routes->push_back({"GET", "/api/scans/{id}/repeat", kStaff, [](Workstation& ws, const Call& call) {
                       const double shop_mm = ws.options().repeatability_mm;
                       auto check = pipeline::check_repeat(ws.archive(), call.params.at("id"), shop_mm);
                       if (!check.ok()) return error_response(check.status());
                       nlohmann::json out = {{"earlier", nullptr},
                                             {"repeatability_mm", shop_mm > 0 ? nlohmann::json(shop_mm) : nullptr}};
                       if (*check) {
                         const pipeline::RepeatCheck& c = **check;
                         out["earlier"] = {{"id", c.earlier_scan}, {"started_at", c.earlier_started_at}};
                         out["compared"] = c.compared;
                         nlohmann::json beyond = nlohmann::json::array();
                         for (const pipeline::RepeatDifference& d : c.beyond)
                           beyond.push_back({{"name", d.name},
                                             {"label", d.label},
                                             {"kind", d.kind},
                                             {"value_mm", d.value_mm},
                                             {"earlier_mm", d.earlier_mm},
                                             {"difference_mm", d.difference()},
                                             {"tolerance_mm", d.tolerance_mm}});
                         out["beyond"] = beyond;
                       }
                       return json_response(200, out);
                     }});
  routes->push_back({"POST", "/api/scans/{id}/measure", kStaff, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       auto mesh = ws.surface(call.params.at("id"));
                       if (!mesh.ok()) return error_response(mesh.status());
                       auto m = pipeline::evaluate_measurement(**mesh, *body);
                       if (!m.ok()) return error_response(m.status());
                       return json_response(200, *m);
                     }});
  routes->push_back({"POST", "/api/scans/{id}/measurements", kTailor | kAdmin, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       const std::string& id = call.params.at("id");
                       const std::optional<std::string> name = string_field(*body, "name");
                       if (!name || name->empty() || name->size() > 100)
                         return error_response(400, "give the measurement a 'name' (up to 100 characters)");
                       const std::optional<std::string> label = string_field(*body, "label", *name);
                       if (!label || label->size() > 200)
                         return error_response(400, "'label' is the name shown on the sheet (up to 200 characters)");
                       if (!(*body)["request"].is_object())
                         return error_response(400, "'request' is the measurement to take (as for /measure)");
                       auto r = ws.archive().scan(id);
                       if (!r.ok()) return error_response(r.status());
                       auto mesh = ws.surface(id);
                       if (!mesh.ok()) return error_response(mesh.status());
                       // Evaluated here, on the archived surface: what is saved is what the server measured.
                       auto m = pipeline::evaluate_measurement(**mesh, (*body)["request"]);
                       if (!m.ok()) return error_response(m.status());
                       storage::MeasurementRecord rec;
                       rec.scan_id = id;
                       rec.version = r->current_version;
                       rec.source = "user";
                       rec.name = *name;
                       rec.label = *label;
                       rec.kind = (*m)["kind"];
                       rec.value_mm = (*m)["value_mm"];
                       rec.geometry = *m;
                       rec.geometry["request"] = (*body)["request"];
                       rec.created_by = call.actor();
                       auto saved = ws.archive().save_measurement(rec, call.actor());
                       if (!saved.ok()) return error_response(saved.status());
                       auto all = ws.archive().measurements(id);
                       if (all.ok())
                         for (const auto& x : *all)
                           if (x.id == *saved) return json_response(201, storage::to_json(x));
                       rec.id = *saved;
                       return json_response(201, storage::to_json(rec));
                     }});
  routes->push_back(
      {"DELETE", "/api/scans/{id}/measurements/{mid}", kTailor | kAdmin, [](Workstation& ws, const Call& call) {
         const std::string& mid = call.params.at("mid");
         char* end = nullptr;
         const long long n = std::strtoll(mid.c_str(), &end, 10);
         if (*end != '\0' || n < 1) return error_response(404, "no measurement " + mid);
         const Status st = ws.archive().delete_measurement(call.params.at("id"), n, call.actor());
         if (!st.ok()) return error_response(st);
         return no_content();
       }});
  routes->push_back({"GET", "/api/scans/{id}/avatar.obj", kStaff,
                     [](Workstation& ws, const Call& call) { return avatar(ws, call, pipeline::AvatarFormat::kObj); }});
  routes->push_back({"GET", "/api/scans/{id}/avatar.glb", kStaff,
                     [](Workstation& ws, const Call& call) { return avatar(ws, call, pipeline::AvatarFormat::kGlb); }});
  for (const char* format : {"csv", "json", "pdf"}) {
    routes->push_back({"GET", std::string("/api/scans/{id}/sheet.") + format, kStaff,
                       [format](Workstation& ws, const Call& call) { return sheet(ws, call, format); }});
  }
}

}  // namespace bodyscan::server

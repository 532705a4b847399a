// Customer share links: staff make one per scan (read-only, expiring, revocable,
// with the measurements they choose); the customer's phone reaches that scan's
// model and those measurements through the token alone, and nothing else.
#include <algorithm>
#include <cmath>

#include "pipeline/archive_scan.hpp"
#include "pipeline/share_model.hpp"
#include "server/api/api.hpp"
#include "server/api/scan_views.hpp"
#include "storage/archive/ids.hpp"
#include "storage/formats/customer_sheet.hpp"
#include "storage/formats/draco_files.hpp"

namespace bodyscan::server {

namespace {

constexpr int64_t kDay = 24 * 3600;

nlohmann::json share_json(const ShareLink& s) {
  return {{"id", s.id},
          {"scan_id", s.scan_id},
          {"measurements", s.measurements},
          {"created_by", s.created_by},
          {"created_at", s.created_at},
          {"expires_at", s.expires_at},
          {"revoked", s.revoked},
          {"include_head", s.include_head},
          {"pin", s.pin}};
}

std::string link_base(const ApiOptions& o, const HttpRequest& r) {
  if (!o.public_url.empty()) return o.public_url;
  return std::string(r.secure || o.secure_cookies ? "https://" : "http://") + r.header("host");
}

// ?locale=en|de, else the shop's language.
StatusOr<storage::Locale> asked_locale(const Call& call, const ApiOptions& options) {
  const std::string asked = call.request.param("locale", "");
  return asked.empty() ? StatusOr<storage::Locale>(options.locale) : storage::parse_locale(asked);
}

// The surface a link may show: the whole body, or below the head unless staff
// chose to include it.
StatusOr<TriangleMesh> shared_surface(Workstation& ws, const ShareLink& link) {
  ASSIGN_OR_RETURN(std::shared_ptr<const TriangleMesh> mesh, ws.surface(link.scan_id));
  if (link.include_head) return *mesh;
  ASSIGN_OR_RETURN(std::vector<storage::MeasurementRecord> ms, ws.archive().measurements(link.scan_id));
  ASSIGN_OR_RETURN(const double cut, pipeline::head_cut_height(ms));
  return pipeline::below_height(*mesh, cut);
}

// The customer's sheet for a link (storage/formats/customer_sheet.hpp): the
// measurements it shares, the surface it may show, the customer's name, the shop,
// and the link itself as a QR code; ?unit=mm|cm|in, ?locale=en|de (default: the
// shop's language).
HttpResponse customer_sheet(Workstation& ws, const Call& call, const ApiOptions& options) {
  const ShareLink& link = *call.share;
  auto unit = storage::parse_length_unit(call.request.param("unit", "cm"));
  if (!unit.ok()) return error_response(400, unit.status().message());
  auto tailors = pipeline::archived_sheet(ws.archive(), link.scan_id);
  if (!tailors.ok()) return error_response(tailors.status());
  storage::CustomerSheet sheet;
  auto scan = ws.archive().scan(link.scan_id);
  if (!scan.ok()) return error_response(scan.status());
  auto customer = ws.archive().customer(scan->customer_id);
  if (customer.ok()) sheet.customer_name = customer->name.value_or("");
  sheet.taken_at = tailors->taken_at;
  sheet.shop_name = options.shop_name;
  sheet.shop_logo_png = options.shop_logo_png;
  auto locale = asked_locale(call, options);
  if (!locale.ok()) return error_response(400, locale.status().message());
  sheet.locale = *locale;
  sheet.link_url = link_base(options, call.request) + "/s/" + call.params.at("token");
  sheet.link_expires = storage::iso8601_utc(link.expires_at);
  for (storage::SheetEntry& e : tailors->entries)
    if (std::find(link.measurements.begin(), link.measurements.end(), e.name) != link.measurements.end())
      sheet.entries.push_back(std::move(e));
  auto mesh = shared_surface(ws, link);
  if (!mesh.ok()) return error_response(mesh.status());
  auto pdf = storage::customer_sheet_pdf(sheet, *mesh, *unit);
  if (!pdf.ok()) return error_response(pdf.status());
  HttpResponse out = file_response(std::move(*pdf), "application/pdf", "body-measurements.pdf", "inline");
  out.set("Referrer-Policy", "no-referrer");
  return out;
}

}  // namespace

void add_share_routes(std::vector<Api::Route>* routes, const ApiOptions& options) {
  routes->push_back({"POST", "/api/scans/{id}/shares", kStaff, [options](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       const std::string& id = call.params.at("id");
                       auto r = ws.archive().scan(id);
                       if (!r.ok()) return error_response(r.status());
                       if (r->current_version == 0)
                         return error_response(409, "scan " + id + " has no results to share");
                       const nlohmann::json days = body->value("days", nlohmann::json(7));
                       if (!days.is_number() || !(days.get<double>() > 0) || days.get<double>() > 365)
                         return error_response(400, "'days' is how long the link works: more than 0, at most 365");
                       std::vector<std::string> names;
                       if (body->contains("measurements")) {
                         const nlohmann::json& m = (*body)["measurements"];
                         if (!m.is_array()) return error_response(400, "'measurements' is a list of names");
                         for (const auto& n : m) {
                           if (!n.is_string()) return error_response(400, "'measurements' is a list of names");
                           names.push_back(n);
                         }
                       }
                       const nlohmann::json head = body->value("include_head", nlohmann::json(false));
                       if (!head.is_boolean())
                         return error_response(400, "'include_head' is true to show the head (default: left out)");
                       const nlohmann::json pin = body->value("pin", nlohmann::json(false));
                       if (!pin.is_boolean())
                         return error_response(400, "'pin' is true to protect the link with a PIN staff read out");
                       const int64_t seconds = std::max<int64_t>(1, std::llround(days.get<double>() * kDay));
                       ShareOptions share_options;
                       share_options.include_head = head.get<bool>();
                       share_options.pin = pin.get<bool>();
                       auto made = ws.auth().create_share(id, names, seconds, call.actor(), share_options);
                       if (!made.ok()) return error_response(made.status());
                       ws.archive().log(call.actor(), "share scan", "scan", id, made->link.id);
                       nlohmann::json out = share_json(made->link);
                       out["token"] = made->token;
                       if (share_options.pin) out["pin_code"] = made->pin;  // shown once, like the token
                       out["url"] = link_base(options, call.request) + "/s/" + made->token;
                       return json_response(201, out);
                     }});
  routes->push_back({"GET", "/api/scans/{id}/shares", kStaff, [](Workstation& ws, const Call& call) {
                       auto list = ws.auth().shares(call.params.at("id"));
                       if (!list.ok()) return error_response(list.status());
                       nlohmann::json out = nlohmann::json::array();
                       for (const auto& s : *list) out.push_back(share_json(s));
                       return json_response(200, {{"shares", out}});
                     }});
  routes->push_back({"DELETE", "/api/shares/{id}", kStaff, [](Workstation& ws, const Call& call) {
                       const Status st = ws.auth().revoke_share(call.params.at("id"));
                       if (!st.ok()) return error_response(st);
                       ws.archive().log(call.actor(), "withdraw share", "share", call.params.at("id"), "");
                       HttpResponse out;
                       out.status = 204;
                       return out;
                     }});
  // The customer's side: the token is the only key, and it opens one scan.
  routes->push_back(
      {"GET", "/api/share/{token}", kShareLink, [options](Workstation& ws, const Call& call) {
         const ShareLink& link = *call.share;
         auto locale = asked_locale(call, options);
         if (!locale.ok()) return error_response(400, locale.status().message());
         auto r = ws.archive().scan(link.scan_id);
         if (!r.ok()) return error_response(404, "this link is not valid");
         auto ms = ws.archive().measurements(link.scan_id);
         if (!ms.ok()) return error_response(ms.status());
         nlohmann::json shown = nlohmann::json::array();
         for (const auto& m : *ms)
           if (std::find(link.measurements.begin(), link.measurements.end(), m.name) != link.measurements.end()) {
             nlohmann::json j = storage::to_json(m);
             j.erase("created_by");  // staff names stay in the shop
             j.erase("id");
             const std::string plain = storage::plain_label(m.name, *locale);
             if (!plain.empty()) j["plain_label"] = plain;
             shown.push_back(j);
           }
         HttpResponse out = json_response(200, {{"taken_at", r->started_at},
                                                {"expires_at", link.expires_at},
                                                {"measurements", shown},
                                                {"locale", storage::locale_tag(*locale)},
                                                {"shop", options.shop_name},
                                                {"mesh", "/api/share/" + call.params.at("token") + "/mesh.glb"}});
         out.set("Referrer-Policy", "no-referrer");
         return out;
       }});
  routes->push_back({"GET", "/api/share/{token}/mesh.glb", kShareLink, [](Workstation& ws, const Call& call) {
                       const std::string& scan = call.share->scan_id;
                       HttpResponse out;
                       if (call.share->include_head) {
                         out = scan_file(ws, scan, "mesh.glb", "", call.request.header("if-none-match"));
                       } else {
                         // Made once per change of the archive and kept, as the
                         // measurements are: the cut and the Draco encoding take a second.
                         auto text = ws.cached_text("headless.glb/" + scan, [&]() -> StatusOr<std::string> {
                           ASSIGN_OR_RETURN(const TriangleMesh headless, shared_surface(ws, *call.share));
                           ASSIGN_OR_RETURN(storage::DracoEncoded glb, storage::encode_glb(headless));
                           return std::move(glb.bytes);
                         });
                         if (!text.ok()) return error_response(text.status());
                         out.set("Content-Type", "model/gltf-binary");
                         out.set("Cache-Control", "private, no-cache");
                         out.set("ETag", (*text)->etag);
                         if (call.request.header("if-none-match") == (*text)->etag)
                           out.status = 304;
                         else
                           out.body = (*text)->body;
                       }
                       out.set("Referrer-Policy", "no-referrer");
                       return out;
                     }});
  routes->push_back({"GET", "/api/share/{token}/sheet.pdf", kShareLink,
                     [options](Workstation& ws, const Call& call) { return customer_sheet(ws, call, options); }});
}

}  // namespace bodyscan::server

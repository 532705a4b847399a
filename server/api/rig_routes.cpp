// The rig: its status, calibrating it, checking how the customer stands, starting
// a scan, following the job, answering its prompts and cancelling it. One job at a
// time: a second gets 409 with what the rig is busy with.
#include <optional>

#include "server/api/api.hpp"

namespace bodyscan::server {

namespace {

HttpResponse accepted(const JobInfo& j) {
  HttpResponse r = json_response(202, {{"job", to_json(j)}});
  r.set("Location", "/api/jobs/" + j.id);
  return r;
}

// The fields of POST /api/scans but the new customer's record: `every`, which
// customer (an existing one's id, or a new one's details, exactly one), and the
// consent. An answer when they are malformed.
std::optional<HttpResponse> read_scan_request(const nlohmann::json& body, ScanRequest* req) {
  if (body.contains("every")) {
    const nlohmann::json& every = body["every"];
    if (!every.is_number_integer() || every.get<int64_t>() < 1 || every.get<int64_t>() > 1000)
      return error_response(400, "'every' is a whole number from 1 to 1000");
    req->every = every.get<int>();
  }
  if (body.contains("customer_id") == body.contains("customer"))
    return error_response(400, "give either 'customer_id' or a new 'customer' {name, contact}");
  if (body.contains("consent")) {
    if (!body["consent"].is_boolean())
      return error_response(400, "'consent' is true when the customer has just agreed to the terms (GET /api/consent)");
    req->consent_given = body["consent"].get<bool>();
  }
  if (body.contains("customer_id")) {
    if (!body["customer_id"].is_string()) return error_response(400, "'customer_id' is a string");
    req->customer_id = body["customer_id"];
  }
  return std::nullopt;
}

}  // namespace

void add_rig_routes(std::vector<Api::Route>* routes) {
  routes->push_back(
      {"GET", "/api/rig", kStaff, [](Workstation& ws, const Call&) { return json_response(200, ws.rig_status()); }});
  routes->push_back({"POST", "/api/rig/calibrate", kOperator | kAdmin, [](Workstation& ws, const Call& call) {
                       auto j = ws.start_calibration(call.actor());
                       if (!j.ok()) return error_response(j.status());
                       return accepted(*j);
                     }});
  // A quick coarse sweep before the scan: how the customer stands, in the job's
  // posture_check when it completes. Nothing is stored.
  routes->push_back({"POST", "/api/rig/posture-check", kOperator | kAdmin, [](Workstation& ws, const Call& call) {
                       auto j = ws.start_posture_check(call.actor());
                       if (!j.ok()) return error_response(j.status());
                       return accepted(*j);
                     }});
  routes->push_back({"POST", "/api/scans", kOperator | kAdmin, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       ScanRequest req;
                       req.actor = call.actor();
                       if (std::optional<HttpResponse> bad = read_scan_request(*body, &req)) return *bad;
                       // The rig must be free before a customer record is made for the scan.
                       if (auto running = ws.current_job())
                         return error_response(409, std::string("the rig is busy with a ") + to_string(running->kind) +
                                                        " (job " + running->id + ")");
                       if (body->contains("customer")) {
                         const nlohmann::json& c = (*body)["customer"];
                         if (!c.is_object())
                           return error_response(400, "'customer' is {\"name\": ..., \"contact\": ...}");
                         // No record of a customer who has not agreed to be kept.
                         if (!req.consent_given)
                           return error_response(409,
                                                 "a new customer's consent comes with the scan: 'consent': true "
                                                 "once they agreed to the terms (GET /api/consent)");
                         auto text = [&](const char* k) -> std::optional<std::string> {
                           if (!c.contains(k) || c[k].is_null()) return std::nullopt;
                           return c[k].is_string() ? std::optional<std::string>(c[k].get<std::string>()) : std::nullopt;
                         };
                         auto made = ws.archive().add_customer(text("name"), text("contact"), call.actor());
                         if (!made.ok()) return error_response(made.status());
                         req.customer_id = made->id;
                       }
                       auto j = ws.start_scan(req);
                       if (!j.ok()) return error_response(j.status());
                       return accepted(*j);
                     }});
  routes->push_back({"GET", "/api/jobs/{id}", kStaff, [](Workstation& ws, const Call& call) {
                       auto j = ws.job(call.params.at("id"));
                       if (!j) return error_response(404, "no job " + call.params.at("id"));
                       return json_response(200, {{"job", to_json(*j)}});
                     }});
  // The person has done what the job's prompt asked (held the dot-grid board ...).
  routes->push_back({"POST", "/api/jobs/{id}/prompt", kOperator | kAdmin, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       if (!body->contains("prompt") || !(*body)["prompt"].is_string())
                         return error_response(400, "give the prompt answered: {\"prompt\": \"p1\"}");
                       const Status s = ws.answer_prompt(call.params.at("id"), (*body)["prompt"].get<std::string>());
                       if (!s.ok()) return error_response(s);
                       auto j = ws.job(call.params.at("id"));
                       return json_response(202, {{"job", j ? to_json(*j) : nlohmann::json()}});
                     }});
  routes->push_back({"POST", "/api/jobs/{id}/cancel", kOperator | kAdmin, [](Workstation& ws, const Call& call) {
                       const Status s = ws.cancel(call.params.at("id"), call.actor());
                       if (!s.ok()) return error_response(s);
                       auto j = ws.job(call.params.at("id"));
                       return json_response(202, {{"job", j ? to_json(*j) : nlohmann::json()}});
                     }});
}

}  // namespace bodyscan::server

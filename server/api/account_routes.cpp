// Logging in and out, the session, and the staff accounts (admins).
#include "core/json_text.hpp"
#include "server/api/api.hpp"

namespace bodyscan::server {

namespace {

nlohmann::json account_json(const Account& a) {
  return {{"username", a.username}, {"role", to_string(a.role)}, {"created_at", a.created_at}};
}

std::string cookie(const std::string& value, int64_t max_age, bool secure) {
  // HttpOnly: scripts never see it; SameSite=Strict: no other site's page sends it.
  return std::string(kSessionCookie) + "=" + value +
         "; Path=/; HttpOnly; SameSite=Strict; Max-Age=" + std::to_string(max_age) + (secure ? "; Secure" : "");
}

bool secure(const ApiOptions& o, const HttpRequest& r) { return o.secure_cookies || r.secure; }

}  // namespace

void add_account_routes(std::vector<Api::Route>* routes, const ApiOptions& options) {
  routes->push_back(
      {"POST", "/api/login", kAnyone, [options](Workstation& ws, const Call& call) {
         HttpResponse error;
         auto body = json_body(call, &error);
         if (!body) return error;
         if (!(*body)["username"].is_string() || !(*body)["password"].is_string())
           return error_response(400, "give 'username' and 'password'");
         const LoginResult r = ws.auth().login((*body)["username"], (*body)["password"], call.request.remote_address);
         if (r.outcome == LoginResult::kRateLimited) {
           HttpResponse out =
               error_response(429, "too many failed attempts; try again in " + std::to_string(r.retry_after_s) + " s");
           out.set("Retry-After", std::to_string(r.retry_after_s));
           return out;
         }
         if (r.outcome == LoginResult::kError) return error_response(r.error);
         if (r.outcome != LoginResult::kOk) return error_response(401, "wrong username or password");
         ws.archive().log(r.session.username, "log in", "account", r.session.username, call.request.remote_address);
         HttpResponse out = json_response(200, {{"username", r.session.username},
                                                {"role", to_string(r.session.role)},
                                                {"csrf_token", r.session.csrf_token},
                                                {"expires_at", r.session.expires_at}});
         out.set("Set-Cookie", cookie(r.token, ws.options().auth.session_lifetime_s, secure(options, call.request)));
         return out;
       }});
  routes->push_back({"POST", "/api/logout", kStaff, [options](Workstation& ws, const Call& call) {
                       ws.auth().logout(session_cookie(call.request));
                       HttpResponse out;
                       out.status = 204;
                       out.set("Set-Cookie", cookie("", 0, secure(options, call.request)));
                       return out;
                     }});
  routes->push_back({"GET", "/api/session", kStaff, [](Workstation&, const Call& call) {
                       const Session& s = *call.session;
                       return json_response(200, {{"username", s.username},
                                                  {"role", to_string(s.role)},
                                                  {"csrf_token", s.csrf_token},
                                                  {"expires_at", s.expires_at}});
                     }});
  routes->push_back({"GET", "/api/accounts", kAdmin, [](Workstation& ws, const Call&) {
                       auto list = ws.auth().accounts();
                       if (!list.ok()) return error_response(list.status());
                       nlohmann::json out = nlohmann::json::array();
                       for (const Account& a : *list) out.push_back(account_json(a));
                       return json_response(200, {{"accounts", out}});
                     }});
  routes->push_back({"POST", "/api/accounts", kAdmin, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       const auto role_name = string_field(*body, "role");
                       const auto role = role_name ? role_from_string(*role_name) : std::nullopt;
                       if (!(*body)["username"].is_string() || !(*body)["password"].is_string() || !role)
                         return error_response(400, "give 'username', 'password' and 'role' (operator, tailor, admin)");
                       auto a = ws.auth().add_account((*body)["username"], (*body)["password"], *role);
                       if (!a.ok()) return error_response(a.status());
                       ws.archive().log(call.actor(), "add account", "account", a->username, to_string(a->role));
                       return json_response(201, account_json(*a));
                     }});
  routes->push_back({"PUT", "/api/accounts/{username}", kAdmin, [](Workstation& ws, const Call& call) {
                       HttpResponse error;
                       auto body = json_body(call, &error);
                       if (!body) return error;
                       const std::string& name = call.params.at("username");
                       if (body->contains("role")) {
                         const auto role_name = string_field(*body, "role");
                         const auto role = role_name ? role_from_string(*role_name) : std::nullopt;
                         if (!role) return error_response(400, "'role' is operator, tailor or admin");
                         const Status s = ws.auth().set_role(name, *role);
                         if (!s.ok()) return error_response(s);
                       }
                       if (body->contains("password")) {
                         if (!(*body)["password"].is_string()) return error_response(400, "'password' is a string");
                         const Status s = ws.auth().set_password(name, (*body)["password"]);
                         if (!s.ok()) return error_response(s);
                       }
                       auto a = ws.auth().account(name);
                       if (!a.ok()) return error_response(a.status());
                       ws.archive().log(call.actor(), "change account", "account", a->username, to_string(a->role));
                       return json_response(200, account_json(*a));
                     }});
  routes->push_back({"DELETE", "/api/accounts/{username}", kAdmin, [](Workstation& ws, const Call& call) {
                       const Status s = ws.auth().delete_account(call.params.at("username"));
                       if (!s.ok()) return error_response(s);
                       ws.archive().log(call.actor(), "delete account", "account", call.params.at("username"), "");
                       HttpResponse out;
                       out.status = 204;
                       return out;
                     }});
}

}  // namespace bodyscan::server

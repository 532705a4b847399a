#include "server/api/api.hpp"

#include <sodium.h>

#include <cctype>

#include "core/json_text.hpp"
#include "server/api/static_files.hpp"

namespace bodyscan::server {

namespace {

unsigned role_bit(Role r) {
  switch (r) {
    case Role::kOperator: return kOperator;
    case Role::kTailor: return kTailor;
    case Role::kAdmin: return kAdmin;
  }
  return 0;
}

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> out;
  size_t start = 1;
  while (start <= path.size()) {
    const size_t end = std::min(path.find('/', start), path.size());
    out.push_back(path.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

bool match(const std::vector<std::string>& pattern, const std::vector<std::string>& path,
           std::map<std::string, std::string>* params) {
  if (pattern.size() != path.size()) return false;
  params->clear();
  for (size_t i = 0; i < pattern.size(); ++i) {
    const std::string& p = pattern[i];
    if (p.size() > 2 && p.front() == '{' && p.back() == '}') {
      if (path[i].empty()) return false;
      (*params)[p.substr(1, p.size() - 2)] = path[i];
    } else if (p != path[i]) {
      return false;
    }
  }
  return true;
}

bool constant_time_equal(const std::string& a, const std::string& b) {
  return a.size() == b.size() && !a.empty() && sodium_memcmp(a.data(), b.data(), a.size()) == 0;
}

// A browser sends Origin on cross-site requests; when it names another host
// than the one addressed, the request did not come from our pages. The host a
// proxy says the browser addressed counts only from a trusted proxy: anyone
// else could send it to match their own Origin.
bool foreign_origin(const HttpRequest& r) {
  const std::string origin = r.header("origin");
  if (origin.empty() || origin == "null") return !origin.empty();
  const size_t scheme = origin.find("://");
  const std::string host = scheme == std::string::npos ? origin : origin.substr(scheme + 3);
  const std::string forwarded = r.via_trusted_proxy ? r.header("x-forwarded-host") : std::string();
  return host != r.header("host") && (forwarded.empty() || host != forwarded);
}

// A Host (or forwarded host) as RFC 3986 allows it: a name, an IPv4 address or
// a bracketed IPv6 literal, and a port. It ends up in share links and answers.
bool valid_host(const std::string& host) {
  if (host.size() > 255) return false;
  for (const unsigned char c : host)
    if (!std::isalnum(c) && c != '-' && c != '.' && c != ':' && c != '[' && c != ']' && c != '_') return false;
  return true;
}

}  // namespace

std::string session_cookie(const HttpRequest& request) {
  const std::string cookies = request.header("cookie");
  const std::string key = std::string(kSessionCookie) + "=";
  size_t pos = 0;
  while (pos < cookies.size()) {
    while (pos < cookies.size() && (cookies[pos] == ' ' || cookies[pos] == ';')) ++pos;
    const size_t end = std::min(cookies.find(';', pos), cookies.size());
    if (cookies.compare(pos, key.size(), key) == 0) return cookies.substr(pos + key.size(), end - pos - key.size());
    pos = end;
  }
  return {};
}

std::optional<nlohmann::json> json_body(const Call& call, HttpResponse* error) {
  const std::string type = call.request.header("content-type");
  if (!call.request.body.empty() && type.rfind("application/json", 0) != 0) {
    *error = error_response(415, "send the request body as application/json");
    return std::nullopt;
  }
  nlohmann::json j = call.request.body.empty() ? nlohmann::json::object() : parse_json(call.request.body);
  if (j.is_discarded() || !j.is_object()) {
    *error = error_response(400, "the request body is not a JSON object");
    return std::nullopt;
  }
  return j;
}

Api::Api(Workstation& ws, ApiOptions options) : ws_(ws), options_(std::move(options)) {
  routes_.push_back({"GET", "/api/health", kAnyone, [](Workstation&, const Call&) {
                       return json_response(200, {{"status", "ok"}, {"service", "bodyscan"}});
                     }});
  routes_.push_back({"GET", "/api/openapi.json", kAnyone, [](Workstation&, const Call&) {
                       HttpResponse r;
                       r.body = openapi_document();
                       r.set("Content-Type", "application/json");
                       r.set("Cache-Control", "no-cache");
                       return r;
                     }});
  // The events are a WebSocket (server/net upgrades it before routing); a plain
  // GET is told so.
  routes_.push_back({"GET", "/api/events", kStaff, [](Workstation&, const Call&) {
                       HttpResponse r = error_response(426, "connect to /api/events with a WebSocket");
                       r.set("Upgrade", "websocket");
                       return r;
                     }});
  add_account_routes(&routes_, options_);
  add_rig_routes(&routes_);
  add_scan_routes(&routes_);
  add_share_routes(&routes_, options_);
  add_validation_routes(&routes_, options_);
}

std::optional<HttpResponse> Api::refuse_events(const HttpRequest& request, Session* session) {
  std::optional<Session> s = ws_.auth().session(session_cookie(request));
  if (!s) return error_response(401, "log in to follow the rig's events");
  if (foreign_origin(request)) return error_response(403, "the events are for this workstation's own pages");
  *session = std::move(*s);
  return std::nullopt;
}

HttpResponse Api::handle(const HttpRequest& request) {
  if (!valid_host(request.header("host")) ||
      (request.via_trusted_proxy && !valid_host(request.header("x-forwarded-host"))))
    return error_response(400, "malformed Host header");
  if (request.path.rfind("/api/", 0) != 0 && request.path != "/api") return serve_static(options_.web_root, request);
  const std::vector<std::string> path = split_path(request.path);
  const Route* route = nullptr;
  std::map<std::string, std::string> params;
  std::string allowed;
  for (const Route& r : routes_) {
    std::map<std::string, std::string> p;
    if (!match(split_path(r.pattern), path, &p)) continue;
    const bool head_of_get = request.method == "HEAD" && r.method == "GET";
    if (r.method == request.method || head_of_get) {
      route = &r;
      params = std::move(p);
      break;
    }
    allowed += (allowed.empty() ? "" : ", ") + r.method;
  }
  if (!route) {
    if (allowed.empty()) return error_response(404, "no such endpoint: " + request.method + " " + request.path);
    HttpResponse r = error_response(405, request.method + " is not allowed here");
    r.set("Allow", allowed);
    return r;
  }
  Call call{request, std::move(params), std::nullopt, std::nullopt};
  const bool changes_state = request.method != "GET" && request.method != "HEAD";
  if (route->access & kShareLink) {
    call.share = ws_.auth().share_by_token(call.params["token"]);
    // One answer for unknown, expired and revoked links: nothing to learn by probing.
    if (!call.share) return error_response(404, "this link is not valid (it may have expired or been withdrawn)");
    // A link with a PIN opens only with it (X-Share-PIN); too many wrong tries withdraw it.
    if (call.share->pin) {
      const std::string pin = request.header("x-share-pin");
      if (pin.empty()) return error_response(401, "this link needs the PIN the shop gave you");
      int left = 0;
      auto answer = ws_.auth().check_share_pin(call.params["token"], pin, &left);
      if (!answer.ok() || *answer == PinAnswer::kWithdrawn)
        return error_response(404, "this link is not valid (it may have expired or been withdrawn)");
      if (*answer == PinAnswer::kWrong) {
        HttpResponse wrong =
            error_response(401, "wrong PIN; " + std::to_string(left) + (left == 1 ? " try" : " tries") +
                                    " left before the link is withdrawn");
        // The count as a number too, for the customer's page to say in its language.
        nlohmann::json body = nlohmann::json::parse(wrong.body);
        body["error"]["tries_left"] = left;
        wrong.body = body.dump();
        return wrong;
      }
    }
  } else if (!(route->access & kAnyone)) {
    call.session = ws_.auth().session(session_cookie(request));
    if (!call.session) return error_response(401, "log in first");
    if (!(route->access & role_bit(call.session->role)))
      return error_response(403, std::string("a ") + to_string(call.session->role) + " may not do this");
    if (changes_state && route->csrf) {
      if (!constant_time_equal(request.header("x-csrf-token"), call.session->csrf_token))
        return error_response(403, "missing or wrong X-CSRF-Token (reload the page)");
      if (foreign_origin(request)) return error_response(403, "cross-site request refused");
    }
  } else if (changes_state && foreign_origin(request)) {
    return error_response(403, "cross-site request refused");
  }
  return route->handler(ws_, call);
}

}  // namespace bodyscan::server

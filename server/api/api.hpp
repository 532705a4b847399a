// The REST API (server/api/openapi.json, docs/api.md): routing is a pure function
// of the request and the workstation's state. Each route says who may call it:
// anyone, a customer holding a share link (scoped to its one scan), or staff by
// role. Staff authenticate with a session cookie; state-changing staff requests
// carry the session's CSRF token in X-CSRF-Token.
//
// handle() may block (it decodes meshes, evaluates girths, writes the archive):
// call it from a worker pool, never from a network thread.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "server/api/http_types.hpp"
#include "server/auth/auth_store.hpp"
#include "server/workstation/workstation.hpp"
#include "storage/formats/customer_sheet.hpp"

namespace bodyscan::server {

// Who may call a route.
enum Access : unsigned {
  kAnyone = 1u << 0,
  kShareLink = 1u << 1,  // a customer's token in the path ({token})
  kOperator = 1u << 2,
  kTailor = 1u << 3,
  kAdmin = 1u << 4,
  kStaff = kOperator | kTailor | kAdmin,
};

// What a route's handler knows about its caller.
struct Call {
  const HttpRequest& request;
  std::map<std::string, std::string> params;  // {name} segments of the pattern
  std::optional<Session> session;             // staff
  std::optional<ShareLink> share;             // a customer's link
  std::string actor() const { return session ? session->username : share ? "customer:" + share->id : "anonymous"; }
};

struct ApiOptions {
  std::string web_root;         // the UI's static files
  bool secure_cookies = false;  // Secure on the session cookie (TLS here or at a proxy)
  std::string public_url;       // share links' base, e.g. "https://scanner.shop.example"; "" from Host
  // The shop as the customer's page and sheet name it, in its language.
  std::string shop_name;
  std::string shop_logo_png;  // PNG bytes; "" for none
  storage::Locale locale = storage::Locale::kEnglish;
};

class Api {
 public:
  using Handler = std::function<HttpResponse(Workstation&, const Call&)>;
  struct Route {
    std::string method;   // GET, POST, PUT, DELETE
    std::string pattern;  // "/api/scans/{id}/mesh.glb"
    unsigned access = 0;  // Access bits
    Handler handler;
    bool csrf = true;  // state-changing staff requests must carry the CSRF token
  };

  Api(Workstation& ws, ApiOptions options);

  HttpResponse handle(const HttpRequest& request);
  // The WebSocket upgrade at /api/events: staff only. Nullopt with *session set
  // (the caller's, not refreshed beyond this request), or the error response.
  std::optional<HttpResponse> refuse_events(const HttpRequest& request, Session* session);

  const std::vector<Route>& routes() const { return routes_; }
  const ApiOptions& options() const { return options_; }

 private:
  Workstation& ws_;
  ApiOptions options_;
  std::vector<Route> routes_;
};

// server/api/openapi.json, compiled in.
const char* openapi_document();

// The route groups (one file each).
void add_account_routes(std::vector<Api::Route>* routes, const ApiOptions& options);
void add_rig_routes(std::vector<Api::Route>* routes);
void add_scan_routes(std::vector<Api::Route>* routes);
void add_share_routes(std::vector<Api::Route>* routes, const ApiOptions& options);
void add_validation_routes(std::vector<Api::Route>* routes, const ApiOptions& options);

// Parses a JSON request body (object); nullopt and *error set when it is not one.
std::optional<nlohmann::json> json_body(const Call& call, HttpResponse* error);
// The session cookie's value, if any.
std::string session_cookie(const HttpRequest& request);
inline constexpr const char* kSessionCookie = "bodyscan_session";

}  // namespace bodyscan::server

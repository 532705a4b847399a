// Requests and responses as the API sees them: plain values, no Beast, so that
// the routes compile fast and can be tested as functions (server/net converts).
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/status.hpp"

namespace bodyscan::server {

struct HttpRequest {
  std::string method;                          // "GET", "POST", ...
  std::string target;                          // as sent: "/api/scans?customer=c_1"
  std::string path;                            // the target's path, percent-decoded: "/api/scans"
  std::map<std::string, std::string> query;    // decoded
  std::map<std::string, std::string> headers;  // names in lower case
  std::string body;
  // The client's address: the peer's, or behind a trusted proxy (NetOptions::
  // trusted_proxies) the one it forwarded for in X-Forwarded-For.
  std::string remote_address;
  bool via_trusted_proxy = false;  // its X-Forwarded-* headers may be believed
  bool secure = false;             // arrived over TLS (here, or at the trusted proxy)

  std::string header(const std::string& lower_name) const {
    auto it = headers.find(lower_name);
    return it == headers.end() ? std::string() : it->second;
  }
  std::string param(const std::string& name, const std::string& fallback = "") const {
    auto it = query.find(name);
    return it == query.end() ? fallback : it->second;
  }
};

struct HttpResponse {
  int status = 200;
  std::vector<std::pair<std::string, std::string>> headers;
  std::string body;  // kept for HEAD too: the network layer sends only its length

  HttpResponse& set(const std::string& name, const std::string& value) {
    for (auto& h : headers)
      if (h.first == name) {
        h.second = value;
        return *this;
      }
    headers.emplace_back(name, value);
    return *this;
  }
  std::string get(const std::string& name) const {
    for (const auto& h : headers)
      if (h.first == name) return h.second;
    return {};
  }
};

HttpResponse json_response(int status, const nlohmann::json& body);
// 204, no body.
HttpResponse no_content();
// A file for the browser to save ("attachment") or to show ("inline"): the body,
// its media type, the name it is saved under (quotes and control characters
// dropped), and cached nowhere (every export holds personal data).
HttpResponse file_response(std::string body, const std::string& content_type, const std::string& filename,
                           const char* disposition = "attachment");
// {"error": {"status": 409, "code": "conflict", "message": "..."}}.
HttpResponse error_response(int status, const std::string& message);
// A Status's HTTP status: invalid argument 400, not found 404, failed
// precondition 409, unavailable 503, deadline 504, I/O (a full disk ...) 507, else 500.
int http_status(const Status& s);
HttpResponse error_response(const Status& s);

// "%41b+c" -> "Ab c" (with plus_is_space); nullopt for a malformed escape, a NUL,
// or a result that is not well-formed UTF-8.
std::optional<std::string> percent_decode(std::string_view text, bool plus_is_space);
// Splits a target into its decoded path and query; false when malformed.
bool parse_target(const std::string& target, std::string* path, std::map<std::string, std::string>* query);

}  // namespace bodyscan::server

// A small blocking HTTP/1.1 and WebSocket client for the server tests, on plain
// POSIX sockets (and OpenSSL for TLS): the tests talk to the real server over
// real connections, and a client written apart from Beast cannot share its bugs.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace bodyscan::testing {

struct HttpReply {
  int status = 0;                              // 0: no answer (connection failed or closed)
  std::map<std::string, std::string> headers;  // names in lower case
  std::string body;
  std::string header(const std::string& name) const {
    auto it = headers.find(name);
    return it == headers.end() ? "" : it->second;
  }
};

class Connection {
 public:
  // Connects to 127.0.0.1:port (TLS when `tls`, certificates not checked).
  static std::unique_ptr<Connection> open(int port, bool tls = false);
  ~Connection();
  bool send_all(const std::string& bytes);
  // Up to `max` bytes, waiting at most `timeout`; "" on EOF or timeout.
  std::string receive(size_t max, std::chrono::milliseconds timeout);
  bool read_exact(std::string* out, size_t n, std::chrono::milliseconds timeout);
  // A whole HTTP response (Content-Length or close-delimited).
  // A HEAD request's answer has no body, whatever its Content-Length says.
  HttpReply read_reply(std::chrono::milliseconds timeout = std::chrono::seconds(60), bool head = false);
  void close();

 private:
  Connection() = default;
  int fd_ = -1;
  void* ssl_ = nullptr;  // SSL*
  std::string pending_;
};

// One request on a fresh connection.
HttpReply http(int port, const std::string& method, const std::string& target,
               const std::map<std::string, std::string>& headers = {}, const std::string& body = "", bool tls = false);

// A staff member's session: the cookie and the CSRF token, sent with every request.
struct Client {
  int port = 0;
  bool tls = false;
  std::string cookie;  // "bodyscan_session=..."
  std::string csrf;
  HttpReply get(const std::string& target, std::map<std::string, std::string> headers = {}) const;
  HttpReply post(const std::string& target, const std::string& json_body = "{}") const;
  HttpReply put(const std::string& target, const std::string& json_body) const;
  HttpReply del(const std::string& target) const;
  HttpReply request(const std::string& method, const std::string& target, const std::string& body,
                    std::map<std::string, std::string> headers = {}) const;
};
// No session: what anyone on the network can send.
inline Client anonymous(int port) {
  Client c;
  c.port = port;
  return c;
}
// Logs in; an empty cookie when it failed.
Client login(int port, const std::string& user, const std::string& password, bool tls = false);

// A WebSocket client: text messages from the server, in order.
class EventStream {
 public:
  static std::unique_ptr<EventStream> open(int port, const std::string& cookie, HttpReply* refusal = nullptr);
  // The next text message; nullopt on timeout or close.
  std::optional<std::string> next(std::chrono::milliseconds timeout);
  bool closed() const { return closed_; }

 private:
  std::unique_ptr<Connection> c_;
  bool closed_ = false;
};

}  // namespace bodyscan::testing

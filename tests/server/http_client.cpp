#include "tests/server/http_client.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <openssl/ssl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

namespace bodyscan::testing {

namespace {
SSL_CTX* client_ctx() {
  static SSL_CTX* ctx = [] {
    SSL_CTX* c = SSL_CTX_new(TLS_client_method());
    SSL_CTX_set_verify(c, SSL_VERIFY_NONE, nullptr);
    return c;
  }();
  return ctx;
}
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}
}  // namespace

std::unique_ptr<Connection> Connection::open(int port, bool tls) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return nullptr;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return nullptr;
  }
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  std::unique_ptr<Connection> c(new Connection());
  c->fd_ = fd;
  if (tls) {
    SSL* ssl = SSL_new(client_ctx());
    SSL_set_fd(ssl, fd);
    if (SSL_connect(ssl) != 1) {
      SSL_free(ssl);
      return nullptr;
    }
    c->ssl_ = ssl;
  }
  return c;
}

Connection::~Connection() { close(); }

void Connection::close() {
  if (ssl_) {
    SSL_free(static_cast<SSL*>(ssl_));
    ssl_ = nullptr;
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool Connection::send_all(const std::string& bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n =
        ssl_ ? SSL_write(static_cast<SSL*>(ssl_), bytes.data() + done, static_cast<int>(bytes.size() - done))
             : ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

std::string Connection::receive(size_t max, std::chrono::milliseconds timeout) {
  if (!pending_.empty()) {
    std::string out = pending_.substr(0, max);
    pending_.erase(0, out.size());
    return out;
  }
  if (fd_ < 0) return {};
  if (!(ssl_ && SSL_pending(static_cast<SSL*>(ssl_)) > 0)) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return {};
  }
  std::string buf(std::min<size_t>(max, 65536), '\0');
  const ssize_t n = ssl_ ? SSL_read(static_cast<SSL*>(ssl_), buf.data(), static_cast<int>(buf.size()))
                         : ::recv(fd_, buf.data(), buf.size(), 0);
  if (n <= 0) return {};
  buf.resize(static_cast<size_t>(n));
  return buf;
}

bool Connection::read_exact(std::string* out, size_t n, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  out->clear();
  while (out->size() < n) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    std::string part = receive(n - out->size(), left);
    if (part.empty()) return false;
    *out += part;
  }
  return true;
}

HttpReply Connection::read_reply(std::chrono::milliseconds timeout, bool no_body) {
  HttpReply r;
  std::string head;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  size_t end = std::string::npos;
  while ((end = head.find("\r\n\r\n")) == std::string::npos) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return r;
    std::string part = receive(65536, left);
    if (part.empty()) return r;
    head += part;
  }
  pending_ = head.substr(end + 4) + pending_;
  head.resize(end);
  size_t line_end = head.find("\r\n");
  const std::string status_line = head.substr(0, line_end);
  if (status_line.size() < 12) return r;
  r.status = std::atoi(status_line.c_str() + 9);
  size_t pos = line_end == std::string::npos ? head.size() : line_end + 2;
  while (pos < head.size()) {
    size_t e = head.find("\r\n", pos);
    if (e == std::string::npos) e = head.size();
    const std::string line = head.substr(pos, e - pos);
    const size_t colon = line.find(':');
    if (colon != std::string::npos) {
      std::string v = line.substr(colon + 1);
      while (!v.empty() && v.front() == ' ') v.erase(0, 1);
      r.headers[lower(line.substr(0, colon))] = v;
    }
    pos = e + 2;
  }
  if (no_body || r.status == 101 || r.status == 204 || r.status == 304) return r;
  if (r.headers.count("content-length")) {
    const size_t n = std::stoull(r.headers["content-length"]);
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (!read_exact(&r.body, n, left)) r.status = 0;
  } else {
    for (std::string part; !(part = receive(65536, std::chrono::seconds(5))).empty();) r.body += part;
  }
  return r;
}

HttpReply http(int port, const std::string& method, const std::string& target,
               const std::map<std::string, std::string>& headers, const std::string& body, bool tls) {
  auto c = Connection::open(port, tls);
  if (!c) return {};
  std::string req = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n";
  for (const auto& [k, v] : headers) req += k + ": " + v + "\r\n";
  if (!body.empty() || method == "POST" || method == "PUT")
    req += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  req += "Connection: close\r\n\r\n" + body;
  // A server may answer before the body is all sent (413): read what it said.
  c->send_all(req);
  return c->read_reply(std::chrono::seconds(60), method == "HEAD");
}

HttpReply Client::request(const std::string& method, const std::string& target, const std::string& body,
                          std::map<std::string, std::string> headers) const {
  if (!cookie.empty()) headers.emplace("Cookie", cookie);
  if (!csrf.empty() && method != "GET") headers.emplace("X-CSRF-Token", csrf);
  if (!body.empty()) headers.emplace("Content-Type", "application/json");
  return http(port, method, target, headers, body, tls);
}
HttpReply Client::get(const std::string& target, std::map<std::string, std::string> headers) const {
  return request("GET", target, "", std::move(headers));
}
HttpReply Client::post(const std::string& target, const std::string& json_body) const {
  return request("POST", target, json_body);
}
HttpReply Client::put(const std::string& target, const std::string& json_body) const {
  return request("PUT", target, json_body);
}
HttpReply Client::del(const std::string& target) const { return request("DELETE", target, ""); }

Client login(int port, const std::string& user, const std::string& password, bool tls) {
  Client c;
  c.port = port;
  c.tls = tls;
  const std::string body = "{\"username\":\"" + user + "\",\"password\":\"" + password + "\"}";
  HttpReply r = http(port, "POST", "/api/login", {{"Content-Type", "application/json"}}, body, tls);
  if (r.status != 200) return c;
  const std::string set = r.header("set-cookie");
  c.cookie = set.substr(0, set.find(';'));
  const size_t k = r.body.find("\"csrf_token\":\"");
  if (k != std::string::npos) {
    const size_t start = k + 14;
    c.csrf = r.body.substr(start, r.body.find('"', start) - start);
  }
  return c;
}

std::unique_ptr<EventStream> EventStream::open(int port, const std::string& cookie, HttpReply* refusal) {
  auto c = Connection::open(port);
  if (!c) return nullptr;
  std::string req = "GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                    "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                    "Sec-WebSocket-Version: 13\r\n";
  if (!cookie.empty()) req += "Cookie: " + cookie + "\r\n";
  req += "\r\n";
  if (!c->send_all(req)) return nullptr;
  HttpReply r = c->read_reply(std::chrono::seconds(10));
  if (r.status != 101) {
    if (refusal) *refusal = r;
    return nullptr;
  }
  std::unique_ptr<EventStream> s(new EventStream());
  s->c_ = std::move(c);
  return s;
}

std::optional<std::string> EventStream::next(std::chrono::milliseconds timeout) {
  std::string message;
  for (;;) {
    std::string h;
    if (!c_->read_exact(&h, 2, timeout)) return std::nullopt;
    // `timeout` is for a message to begin; one that has begun gets the time it needs
    // to arrive whole (a short wait must not cut a frame in two).
    timeout = std::max(timeout, std::chrono::milliseconds(5000));
    const bool fin = h[0] & 0x80;
    const int opcode = h[0] & 0x0f;
    uint64_t len = static_cast<unsigned char>(h[1]) & 0x7f;
    std::string ext;
    if (len == 126) {
      if (!c_->read_exact(&ext, 2, timeout)) return std::nullopt;
      len = (static_cast<unsigned char>(ext[0]) << 8) | static_cast<unsigned char>(ext[1]);
    } else if (len == 127) {
      if (!c_->read_exact(&ext, 8, timeout)) return std::nullopt;
      len = 0;
      for (char b : ext) len = (len << 8) | static_cast<unsigned char>(b);
    }
    std::string payload;
    if (!c_->read_exact(&payload, len, timeout)) return std::nullopt;
    if (opcode == 0x8) {
      closed_ = true;
      return std::nullopt;
    }
    if (opcode == 0x9 || opcode == 0xA) continue;  // ping/pong (Beast's idle pings)
    message += payload;
    if (fin) return message;
  }
}

}  // namespace bodyscan::testing

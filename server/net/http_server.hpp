// The network side of `bodyscan serve` (Boost.Beast): HTTP/1.1 and the WebSocket
// at /api/events, plain or TLS. Network threads only read, write and route; every
// request's work runs on a worker pool and its answer is posted back. Each
// WebSocket session has its own write queue, bounded: a slow client loses camera
// previews first and is dropped if it falls further behind, never slowing others.
//
// Running out of descriptors does not spin: an accept that fails waits (10 ms,
// doubling to 1 s) before the next, and says so in the log at most every 10 s.
//
// Only this module's .cpp includes Beast (the heavy headers stay in one place).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"
#include "server/api/api.hpp"
#include "server/workstation/workstation.hpp"

namespace bodyscan::server {

struct NetOptions {
  std::string address = "0.0.0.0";
  uint16_t port = 8080;           // 0: any free port (tests)
  int io_threads = 1;             // network threads
  int workers = 3;                // threads running requests' work
  std::string tls_cert, tls_key;  // PEM files; both or neither
  size_t header_limit = 8 * 1024;
  size_t body_limit = 1 << 20;       // request bodies are JSON; nothing uploads meshes
  std::chrono::seconds timeout{30};  // to read a request, or write a response, or a TLS handshake
  size_t ws_queue_limit = 256;       // queued events before a WebSocket client is dropped
  size_t ws_preview_limit = 8;       // queued events past which camera previews are skipped
  // Open connections (HTTP and WebSocket) at most; one more is answered 503 and
  // closed. 0: the process's descriptor limit (RLIMIT_NOFILE) less
  // kReservedDescriptors for the archive, the rig and the logs.
  size_t max_connections = 0;
  // Peers whose X-Forwarded-For, -Proto and -Host are believed (the reverse
  // proxy in front, e.g. "127.0.0.1"). From anyone else they are ignored: the
  // login limits key on the client's address, and a client must not choose it.
  std::vector<std::string> trusted_proxies;
};

inline constexpr size_t kReservedDescriptors = 128;

// One request's bytes read as a connection reads them (the limits, the target's
// decoding, forwarded headers believed from a trusted `peer`). For tests and
// fuzzing: the server itself reads from sockets.
struct RequestBytes {
  std::optional<HttpRequest> request;  // read whole
  int status = 0;                      // otherwise the answer (400, 413, 431); 0: incomplete or cut short
};
RequestBytes parse_request_bytes(std::string_view bytes, const NetOptions& options, const std::string& peer);

class HttpServer {
 public:
  // Binds and starts serving on its own threads.
  static StatusOr<std::unique_ptr<HttpServer>> start(Api& api, Workstation& ws, const NetOptions& options);
  ~HttpServer();  // stop()
  uint16_t port() const;
  bool tls() const;
  // Stops accepting, closes the WebSocket sessions, finishes the requests being
  // worked on, joins the threads. Idempotent.
  void stop();

 private:
  struct Impl;
  explicit HttpServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyscan::server

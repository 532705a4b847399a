// After Beast's advanced server examples: one class per role in a connection's
// life (listener, HTTP session, WebSocket session), each async step a named
// do_x/on_x pair, one fail() that ignores normal shutdown, a queue in front of
// every WebSocket write.
#include "server/net/http_server.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <deque>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "hw/safety.hpp"

namespace bodyscan::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace ssl = asio::ssl;
using tcp = asio::ip::tcp;

namespace {

// Normal ends of a connection are not worth a line in the log.
void fail(beast::error_code ec, const char* what) {
  if (ec == asio::error::operation_aborted || ec == websocket::error::closed || ec == asio::error::eof ||
      ec == beast::error::timeout || ec == asio::ssl::error::stream_truncated || ec == http::error::end_of_stream ||
      ec == asio::error::connection_reset || ec == asio::error::broken_pipe)
    return;
  std::fprintf(stderr, "bodyscan serve: %s: %s\n", what, ec.message().c_str());
}

}  // namespace

class EventSessionBase {
 public:
  virtual ~EventSessionBase() = default;
  // The server stops.
  virtual void close() = 0;
  // The staff session it was opened with ended or changed (see SessionChange):
  // close with 1008 when it is this socket's.
  virtual void session_changed(const SessionChange& change) = 0;
};

namespace {

bool same_username(const std::string& a, const std::string& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](unsigned char x, unsigned char y) { return std::tolower(x) == std::tolower(y); });
}

}  // namespace

// The threads that run requests' work. Like asio::thread_pool, but each thread
// first takes an alternate signal stack, so that a stack overflow in a request
// still runs the lasers-off stops (hw/safety.hpp).
class WorkerPool {
 public:
  explicit WorkerPool(int n) : guard_(asio::make_work_guard(ctx_)) {
    for (int i = 0; i < n; ++i)
      threads_.emplace_back([this]() {
        hw::ensure_alternate_signal_stack();
        ctx_.run();
      });
  }
  ~WorkerPool() { join(); }
  asio::io_context::executor_type get_executor() { return ctx_.get_executor(); }
  // Runs what was queued, then ends the threads. Idempotent.
  void join() {
    guard_.reset();
    for (std::thread& t : threads_)
      if (t.joinable()) t.join();
  }

 private:
  asio::io_context ctx_;
  asio::executor_work_guard<asio::io_context::executor_type> guard_;
  std::vector<std::thread> threads_;
};

// What every session shares: the API, the pool, the limits, the live WebSockets.
struct Shared {
  Api& api;
  Workstation& ws;
  NetOptions options;
  WorkerPool workers;
  std::mutex mutex;
  std::set<std::weak_ptr<EventSessionBase>, std::owner_less<std::weak_ptr<EventSessionBase>>> event_sessions;
  bool stopping = false;
  std::atomic<size_t> connections{0};
  size_t max_connections = 0;
  int session_watch = 0;  // AuthStore::watch_sessions id
  std::vector<asio::ip::address> trusted_proxies;

  Shared(Api& a, Workstation& w, const NetOptions& o) : api(a), ws(w), options(o), workers(std::max(1, o.workers)) {}
};

// One open connection counted against NetOptions::max_connections, for as long
// as its HTTP session, then its WebSocket session, lives.
class ConnectionSlot {
 public:
  explicit ConnectionSlot(Shared& shared) : shared_(&shared) { shared_->connections.fetch_add(1); }
  ConnectionSlot(ConnectionSlot&& o) noexcept : shared_(std::exchange(o.shared_, nullptr)) {}
  ConnectionSlot& operator=(ConnectionSlot&&) = delete;
  ~ConnectionSlot() {
    if (shared_) shared_->connections.fetch_sub(1);
  }

 private:
  Shared* shared_;
};

namespace {

// IPv4 peers of an IPv6 socket come as ::ffff:a.b.c.d; compared as a.b.c.d.
asio::ip::address plain(const asio::ip::address& a) {
  if (a.is_v6() && a.to_v6().is_v4_mapped()) return asio::ip::make_address_v4(asio::ip::v4_mapped, a.to_v6());
  return a;
}

// NetOptions::trusted_proxies as addresses; an entry that is not one is refused.
StatusOr<std::vector<asio::ip::address>> trusted_addresses(const NetOptions& options) {
  std::vector<asio::ip::address> out;
  for (const std::string& proxy : options.trusted_proxies) {
    beast::error_code ec;
    const auto a = asio::ip::make_address(proxy, ec);
    if (ec) return invalid_argument("trusted proxy '" + proxy + "' is not an IP address");
    out.push_back(plain(a));
  }
  return out;
}

bool is_trusted(const std::vector<asio::ip::address>& trusted, const asio::ip::address& a) {
  return std::find(trusted.begin(), trusted.end(), a) != trusted.end();
}

// The client behind a trusted proxy: the right-most X-Forwarded-For entry that
// is not itself a trusted proxy (entries further left were written by the
// client and prove nothing). Nullopt when there is no usable entry.
std::optional<asio::ip::address> forwarded_client(const http::request<http::string_body>& req,
                                                  const std::vector<asio::ip::address>& trusted) {
  std::vector<std::string> entries;
  const auto [first, last] = req.equal_range("X-Forwarded-For");
  for (auto f = first; f != last; ++f) {
    std::string_view v = f->value();
    while (!v.empty()) {
      const size_t comma = std::min(v.find(','), v.size());
      std::string_view e = v.substr(0, comma);
      while (!e.empty() && (e.front() == ' ' || e.front() == '\t')) e.remove_prefix(1);
      while (!e.empty() && (e.back() == ' ' || e.back() == '\t')) e.remove_suffix(1);
      entries.emplace_back(e);
      v.remove_prefix(std::min(comma + 1, v.size()));
    }
  }
  for (auto it = entries.rbegin(); it != entries.rend(); ++it) {
    beast::error_code ec;
    const auto a = asio::ip::make_address(*it, ec);
    if (ec) return std::nullopt;
    if (!is_trusted(trusted, plain(a))) return plain(a);
  }
  return std::nullopt;
}

HttpRequest to_request(const http::request<http::string_body>& req, const asio::ip::address* peer, bool tls,
                       const std::vector<asio::ip::address>& trusted, bool* ok) {
  HttpRequest r;
  r.method = std::string(req.method_string());
  r.target = std::string(req.target());
  for (const auto& f : req) {
    std::string name(f.name_string());
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
    r.headers[name] = std::string(f.value());
  }
  r.body = req.body();
  r.remote_address = peer ? peer->to_string() : "?";
  r.secure = tls;
  if (peer && is_trusted(trusted, *peer)) {
    r.via_trusted_proxy = true;
    if (const auto client = forwarded_client(req, trusted)) r.remote_address = client->to_string();
    if (r.header("x-forwarded-proto") == "https") r.secure = true;
  }
  *ok = parse_target(r.target, &r.path, &r.query);
  return r;
}

// What a request that could not be read is answered: 413, 431, 400, or nullopt
// for a connection error (nothing to answer).
std::optional<std::pair<int, std::string>> refusal(beast::error_code ec) {
  if (ec == http::error::body_limit) return std::pair{413, std::string("the request body is too large")};
  if (ec == http::error::header_limit) return std::pair{431, std::string("the request headers are too large")};
  if (ec == http::error::bad_method || ec == http::error::bad_target || ec == http::error::bad_version ||
      ec == http::error::bad_field || ec == http::error::bad_value || ec == http::error::bad_chunk ||
      ec == http::error::bad_chunk_extension || ec == http::error::bad_content_length ||
      ec == http::error::bad_line_ending || ec == http::error::bad_obs_fold || ec == http::error::bad_transfer_encoding)
    return std::pair{400, "malformed request: " + ec.message()};
  return std::nullopt;
}

template <class Body>
void apply(const HttpResponse& r, unsigned version, bool keep_alive, http::response<Body>* res) {
  res->version(version);
  res->result(static_cast<unsigned>(r.status));
  res->set(http::field::server, "bodyscan");
  res->set("X-Content-Type-Options", "nosniff");
  res->set("Referrer-Policy", "same-origin");
  res->set("X-Frame-Options", "DENY");
  for (const auto& [k, v] : r.headers) res->set(k, v);
  res->keep_alive(keep_alive);
}

// Every answer is a whole string body. It is held by a shared pointer until
// its write completes (async_write keeps a reference, not a copy).
using Response = http::response<http::string_body>;

std::shared_ptr<Response> make_message(HttpResponse r, unsigned version, bool keep_alive, bool head) {
  auto res = std::make_shared<Response>();
  apply(r, version, keep_alive, res.get());
  const size_t size = r.body.size();
  if (!head) res->body() = std::move(r.body);
  res->prepare_payload();
  if (head) res->content_length(size);
  return res;
}

bool is_preview(const std::string& event) { return event.find("\"type\":\"preview\"") != std::string::npos; }

}  // namespace

template <class Stream>
class EventSession : public EventSessionBase, public std::enable_shared_from_this<EventSession<Stream>> {
 public:
  EventSession(Stream&& stream, Shared& shared, ConnectionSlot slot, std::string token, Session session)
      : ws_(std::move(stream)),
        shared_(shared),
        slot_(std::move(slot)),
        expiry_(ws_.get_executor()),
        token_(std::move(token)),
        session_(std::move(session)) {}
  ~EventSession() override {
    if (sink_) shared_.ws.unsubscribe(sink_);
    std::lock_guard lock(shared_.mutex);
    shared_.event_sessions.erase(this->weak_from_this());
  }

  void run(http::request<http::string_body> req, std::string hello) {
    hello_ = std::move(hello);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, "bodyscan"); }));
    ws_.read_message_max(4096);  // clients only ever send small control messages
    ws_.async_accept(req, beast::bind_front_handler(&EventSession::on_accept, this->shared_from_this()));
  }

  // From any thread: queue an event for this client.
  void send(std::shared_ptr<const std::string> event) {
    asio::post(ws_.get_executor(), [self = this->shared_from_this(), event]() { self->on_send(event); });
  }

  void close() override { close_with({websocket::close_code::going_away, "the workstation is stopping"}); }

  void session_changed(const SessionChange& change) override {
    if ((!change.token.empty() && change.token == token_) ||
        (!change.username.empty() && same_username(change.username, session_.username)))
      close_with({websocket::close_code::policy_error, "the session ended or changed; log in again"});
  }

 private:
  void on_accept(beast::error_code ec) {
    if (ec) return fail(ec, "websocket accept");
    {
      std::lock_guard lock(shared_.mutex);
      if (shared_.stopping) return;
      shared_.event_sessions.insert(this->shared_from_this());
    }
    std::weak_ptr<EventSession> weak = this->shared_from_this();
    sink_ = shared_.ws.subscribe([weak](std::shared_ptr<const std::string> event) {
      if (auto self = weak.lock()) self->send(std::move(event));
    });
    on_send(std::make_shared<const std::string>(std::move(hello_)));
    do_read();
    watch_expiry(session_.expires_at);
  }

  void close_with(websocket::close_reason reason) {
    asio::post(ws_.get_executor(), [self = this->shared_from_this(), reason]() {
      self->expiry_.cancel();
      if (self->closed_) return;
      self->closed_ = true;
      self->ws_.async_close(reason, [self](beast::error_code) {});
    });
  }

  // At the session's expiry (idle or absolute), or every five minutes at the
  // latest, ask the store whether the session still holds; a socket open in a
  // forgotten tab does not count as use.
  void watch_expiry(int64_t expires_at) {
    const int64_t now =
        std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    expiry_.expires_after(std::chrono::seconds(std::clamp<int64_t>(expires_at - now, 1, 300)));
    std::weak_ptr<EventSession> weak = this->shared_from_this();
    expiry_.async_wait([weak](beast::error_code ec) {
      auto self = weak.lock();
      if (ec || !self || self->closed_) return;
      asio::post(self->shared_.workers.get_executor(), [self]() {
        const std::optional<Session> now_valid = self->shared_.ws.auth().session(self->token_, false);
        asio::post(self->ws_.get_executor(), [self, now_valid]() {
          if (self->closed_) return;
          if (!now_valid) return self->close_with({websocket::close_code::policy_error, "the session expired"});
          self->watch_expiry(now_valid->expires_at);
        });
      });
    });
  }

  void do_read() {
    ws_.async_read(buffer_, beast::bind_front_handler(&EventSession::on_read, this->shared_from_this()));
  }
  void on_read(beast::error_code ec, size_t) {
    if (ec) {
      closed_ = true;
      expiry_.cancel();
      return fail(ec, "websocket read");
    }
    buffer_.consume(buffer_.size());  // nothing clients say changes anything
    do_read();
  }

  void on_send(std::shared_ptr<const std::string> event) {
    if (closed_) return;
    if (queue_.size() >= shared_.options.ws_queue_limit) {
      // Too far behind to catch up: drop the client, not the server's pace.
      closed_ = true;
      beast::get_lowest_layer(ws_).cancel();
      return;
    }
    if (queue_.size() >= shared_.options.ws_preview_limit && is_preview(*event)) return;
    queue_.push_back(std::move(event));
    if (queue_.size() > 1) return;  // a write is under way
    do_write();
  }
  void do_write() {
    ws_.text(true);
    ws_.async_write(asio::buffer(*queue_.front()),
                    beast::bind_front_handler(&EventSession::on_write, this->shared_from_this()));
  }
  void on_write(beast::error_code ec, size_t) {
    if (ec) {
      closed_ = true;
      return fail(ec, "websocket write");
    }
    queue_.pop_front();
    if (!queue_.empty() && !closed_) do_write();
  }

  websocket::stream<Stream> ws_;
  Shared& shared_;
  ConnectionSlot slot_;
  asio::steady_timer expiry_;
  const std::string token_;
  const Session session_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  std::string hello_;
  int sink_ = 0;
  bool closed_ = false;
};

template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
  static constexpr bool kTls = !std::is_same_v<Stream, beast::tcp_stream>;

 public:
  template <class... Args>
  HttpSession(Shared& shared, ConnectionSlot slot, std::optional<asio::ip::address> peer, Args&&... args)
      : stream_(std::forward<Args>(args)...), shared_(shared), slot_(std::move(slot)), peer_(std::move(peer)) {}

  void run() {
    asio::dispatch(stream_.get_executor(), beast::bind_front_handler(&HttpSession::on_run, this->shared_from_this()));
  }

 private:
  beast::tcp_stream& tcp() { return beast::get_lowest_layer(stream_); }

  void on_run() {
    if constexpr (kTls) {
      tcp().expires_after(shared_.options.timeout);
      stream_.async_handshake(ssl::stream_base::server,
                              beast::bind_front_handler(&HttpSession::on_handshake, this->shared_from_this()));
    } else {
      do_read();
    }
  }
  void on_handshake(beast::error_code ec) {
    if (ec) return fail(ec, "tls handshake");
    do_read();
  }

  void do_read() {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(shared_.options.header_limit));
    parser_->body_limit(shared_.options.body_limit);
    tcp().expires_after(shared_.options.timeout);
    http::async_read(stream_, buffer_, *parser_,
                     beast::bind_front_handler(&HttpSession::on_read, this->shared_from_this()));
  }

  void on_read(beast::error_code ec, size_t) {
    if (ec == http::error::end_of_stream) return do_close();
    if (const auto refused = refusal(ec)) return reply_and_close(refused->first, refused->second);
    if (ec) return fail(ec, "read");
    http::request<http::string_body> req = parser_->release();
    bool ok = false;
    HttpRequest request = to_request(req, peer_ ? &*peer_ : nullptr, kTls, shared_.trusted_proxies, &ok);
    if (!ok) return reply_and_close(400, "malformed request target");
    if (websocket::is_upgrade(req)) {
      if (request.path != "/api/events") return reply_and_close(404, "WebSockets live at /api/events");
      // The session check reads the accounts database: on the pool, like all work.
      asio::post(shared_.workers.get_executor(), [self = this->shared_from_this(), req = std::move(req),
                                                  request]() mutable {
        Session session;
        std::optional<HttpResponse> refused = self->shared_.api.refuse_events(request, &session);
        std::string hello;
        if (!refused) hello = nlohmann::json{{"type", "hello"}, {"rig", self->shared_.ws.rig_status()}}.dump();
        asio::post(self->stream_.get_executor(), [self, req = std::move(req), refused = std::move(refused),
                                                  hello = std::move(hello), token = session_cookie(request),
                                                  session = std::move(session)]() mutable {
          if (refused) return self->send(make_message(std::move(*refused), req.version(), false, false), false);
          self->tcp().expires_never();
          auto session_socket = std::make_shared<EventSession<Stream>>(
              std::move(self->stream_), self->shared_, std::move(self->slot_), std::move(token), std::move(session));
          session_socket->run(std::move(req), std::move(hello));
        });
      });
      return;
    }
    const unsigned version = req.version();
    const bool keep_alive = req.keep_alive();
    const bool head = req.method() == http::verb::head;
    // The work happens off the network thread; the answer comes back to this
    // session's strand.
    asio::post(shared_.workers.get_executor(),
               [self = this->shared_from_this(), request = std::move(request), version, keep_alive, head]() {
                 HttpResponse response;
                 try {
                   response = self->shared_.api.handle(request);
                 } catch (const std::exception& e) {
                   response = error_response(500, std::string("internal error: ") + e.what());
                 }
                 asio::post(self->stream_.get_executor(),
                            [self, response = std::move(response), version, keep_alive, head]() mutable {
                              self->send(make_message(std::move(response), version, keep_alive, head), keep_alive);
                            });
               });
  }

  // For a request refused before it was read whole: answer, stop sending, and
  // read on (discarding, briefly, boundedly) so that the client - still sending
  // its oversized body - gets to read the answer rather than a reset.
  void reply_and_close(int status, const std::string& message) {
    lingering_ = true;
    send(make_message(error_response(status, message), 11, false, false), false);
  }

  void do_drain() {
    tcp().expires_after(std::chrono::seconds(2));
    stream_.async_read_some(asio::buffer(drain_), [self = this->shared_from_this()](beast::error_code ec, size_t n) {
      self->drained_ += n;
      if (!ec && self->drained_ < (8u << 20)) self->do_drain();
    });
  }

  void send(std::shared_ptr<Response> msg, bool keep_alive) {
    tcp().expires_after(shared_.options.timeout);
    Response& response = *msg;  // taken before the handler takes the pointer
    http::async_write(
        stream_, response,
        beast::bind_front_handler(&HttpSession::on_write, this->shared_from_this(), std::move(msg), keep_alive));
  }

  void on_write(const std::shared_ptr<Response>&, bool keep_alive, beast::error_code ec, size_t) {
    // A client that goes away mid-download ends here; nothing else is held for it.
    if (ec) return fail(ec, "write");
    if (!keep_alive) return do_close();
    do_read();
  }

  void do_close() {
    if (lingering_) {
      beast::error_code ec;
      tcp().socket().shutdown(tcp::socket::shutdown_send, ec);
      return do_drain();
    }
    if constexpr (kTls) {
      tcp().expires_after(std::chrono::seconds(5));
      stream_.async_shutdown([self = this->shared_from_this()](beast::error_code) {});
    } else {
      beast::error_code ec;
      stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
    }
  }

  Stream stream_;
  Shared& shared_;
  ConnectionSlot slot_;
  std::optional<asio::ip::address> peer_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  bool lingering_ = false;
  std::array<char, 16384> drain_;
  size_t drained_ = 0;
};

// What a connection past the cap is told before it is closed; written without
// waiting (a client that does not read it just gets the close).
constexpr std::string_view kBusyReply =
    "HTTP/1.1 503 Service Unavailable\r\nServer: bodyscan\r\nContent-Type: application/json\r\n"
    "Retry-After: 5\r\nConnection: close\r\nContent-Length: 82\r\n\r\n"
    "{\"error\":{\"status\":503,\"message\":\"the workstation has too many open connections\"}}";
static_assert(kBusyReply.size() - kBusyReply.find("\r\n\r\n") - 4 == 82);

struct HttpServer::Impl {
  asio::io_context ioc;
  std::optional<ssl::context> tls;
  tcp::acceptor acceptor{ioc};
  asio::steady_timer accept_retry{ioc};
  std::chrono::milliseconds accept_delay{0};
  std::chrono::steady_clock::time_point accept_error_logged{};
  size_t accept_errors_unlogged = 0;
  std::unique_ptr<Shared> shared;
  std::vector<std::thread> threads;
  uint16_t port = 0;
  bool stopped = false;

  void do_accept() {
    acceptor.async_accept(asio::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
      if (ec) {
        if (!acceptor.is_open() || ec == asio::error::operation_aborted) return;
        return on_accept_error(ec);
      }
      accept_delay = std::chrono::milliseconds(0);
      if (shared->connections.load() >= shared->max_connections) {
        beast::error_code e2;
        socket.non_blocking(true, e2);
        socket.write_some(asio::buffer(kBusyReply.data(), kBusyReply.size()), e2);
        socket.shutdown(tcp::socket::shutdown_both, e2);
        socket.close(e2);
        return do_accept();
      }
      beast::error_code e2;
      // Responses go out in several writes (headers, file chunks): without
      // this, Nagle holds the last one for the client's delayed ACK (40 ms).
      socket.set_option(tcp::no_delay(true), e2);
      const auto ep = socket.remote_endpoint(e2);
      std::optional<asio::ip::address> peer;
      if (!e2) peer = plain(ep.address());
      ConnectionSlot slot(*shared);
      if (tls)
        std::make_shared<HttpSession<beast::ssl_stream<beast::tcp_stream>>>(*shared, std::move(slot), peer,
                                                                            std::move(socket), *tls)
            ->run();
      else
        std::make_shared<HttpSession<beast::tcp_stream>>(*shared, std::move(slot), peer, std::move(socket))->run();
      do_accept();
    });
  }

  // Out of descriptors (or memory) the same accept fails at once, again and
  // again: wait before the next, and keep the log to a line per 10 s.
  void on_accept_error(beast::error_code ec) {
    const auto now = std::chrono::steady_clock::now();
    if (now - accept_error_logged >= std::chrono::seconds(10)) {
      std::fprintf(stderr, "bodyscan serve: accept: %s (%zu more since the last report); %zu connections open\n",
                   ec.message().c_str(), accept_errors_unlogged, shared->connections.load());
      accept_error_logged = now;
      accept_errors_unlogged = 0;
    } else {
      ++accept_errors_unlogged;
    }
    accept_delay = std::clamp(accept_delay * 2, std::chrono::milliseconds(10), std::chrono::milliseconds(1000));
    accept_retry.expires_after(accept_delay);
    accept_retry.async_wait([this](beast::error_code wait_ec) {
      if (!wait_ec && acceptor.is_open()) do_accept();
    });
  }
};

namespace {

size_t connection_cap(size_t configured) {
  if (configured > 0) return configured;
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return 4096;
  const size_t descriptors = static_cast<size_t>(limit.rlim_cur);
  return descriptors > 2 * kReservedDescriptors ? descriptors - kReservedDescriptors : descriptors / 2;
}

}  // namespace

RequestBytes parse_request_bytes(std::string_view bytes, const NetOptions& options, const std::string& peer) {
  RequestBytes out;
  http::request_parser<http::string_body> parser;
  parser.header_limit(static_cast<std::uint32_t>(options.header_limit));
  parser.body_limit(options.body_limit);
  parser.eager(true);
  beast::error_code ec;
  size_t used = 0;
  while (used < bytes.size() && !parser.is_done()) {
    const size_t n = parser.put(asio::buffer(bytes.data() + used, bytes.size() - used), ec);
    if (ec == http::error::need_more) {
      ec = {};
      break;
    }
    if (ec) break;
    used += n;
    if (n == 0) break;
  }
  if (!ec && !parser.is_done()) {
    if (!parser.got_some()) return out;  // nothing but the end: a closed connection
    parser.put_eof(ec);
    if (!ec && !parser.is_done()) ec = http::error::partial_message;
  }
  if (ec) {
    const auto refused = refusal(ec);
    out.status = refused ? refused->first : 0;
    return out;
  }
  const auto parsed = trusted_addresses(options);
  const std::vector<asio::ip::address> trusted = parsed.ok() ? *parsed : std::vector<asio::ip::address>{};
  beast::error_code peer_ec;
  const auto peer_address = asio::ip::make_address(peer, peer_ec);
  const std::optional<asio::ip::address> peer_plain =
      peer_ec ? std::nullopt : std::optional<asio::ip::address>(plain(peer_address));
  bool ok = false;
  out.request = to_request(parser.get(), peer_plain ? &*peer_plain : nullptr, false, trusted, &ok);
  if (!ok) {
    out.request.reset();
    out.status = 400;
  }
  return out;
}

HttpServer::HttpServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HttpServer::~HttpServer() { stop(); }

StatusOr<std::unique_ptr<HttpServer>> HttpServer::start(Api& api, Workstation& ws, const NetOptions& options) {
  auto impl = std::make_unique<Impl>();
  if (options.tls_cert.empty() != options.tls_key.empty())
    return invalid_argument("TLS needs both a certificate and its key");
  if (!options.tls_cert.empty()) {
    impl->tls.emplace(ssl::context::tls_server);
    beast::error_code ec;
    impl->tls->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 |
                               ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 | ssl::context::single_dh_use,
                           ec);
    impl->tls->use_certificate_chain_file(options.tls_cert, ec);
    if (ec) return invalid_argument(options.tls_cert + ": not a usable PEM certificate: " + ec.message());
    impl->tls->use_private_key_file(options.tls_key, ssl::context::pem, ec);
    if (ec) return invalid_argument(options.tls_key + ": not a usable PEM key for the certificate: " + ec.message());
  }
  beast::error_code ec;
  const auto address = asio::ip::make_address(options.address, ec);
  if (ec) return invalid_argument("'" + options.address + "' is not an IP address");
  const tcp::endpoint endpoint(address, options.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl->acceptor.bind(endpoint, ec);
  if (!ec) impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    return unavailable("cannot listen on " + options.address + ":" + std::to_string(options.port) + ": " +
                       ec.message());
  impl->port = impl->acceptor.local_endpoint().port();
  impl->shared = std::make_unique<Shared>(api, ws, options);
  impl->shared->max_connections = connection_cap(options.max_connections);
  ASSIGN_OR_RETURN(impl->shared->trusted_proxies, trusted_addresses(options));
  impl->shared->session_watch = ws.auth().watch_sessions([shared = impl->shared.get()](const SessionChange& change) {
    std::vector<std::shared_ptr<EventSessionBase>> live;
    {
      std::lock_guard lock(shared->mutex);
      for (const auto& w : shared->event_sessions)
        if (auto p = w.lock()) live.push_back(std::move(p));
    }
    for (auto& p : live) p->session_changed(change);
  });
  impl->do_accept();
  for (int i = 0; i < std::max(1, options.io_threads); ++i)
    impl->threads.emplace_back([io = &impl->ioc]() {
      hw::ensure_alternate_signal_stack();
      io->run();
    });
  return std::unique_ptr<HttpServer>(new HttpServer(std::move(impl)));
}

uint16_t HttpServer::port() const { return impl_->port; }
bool HttpServer::tls() const { return impl_->tls.has_value(); }

void HttpServer::stop() {
  Impl& s = *impl_;
  if (s.stopped) return;
  s.stopped = true;
  s.shared->ws.auth().unwatch_sessions(s.shared->session_watch);
  asio::post(s.ioc, [&s]() {
    beast::error_code ec;
    s.acceptor.close(ec);
    s.accept_retry.cancel();
  });
  std::vector<std::shared_ptr<EventSessionBase>> live;
  {
    std::lock_guard lock(s.shared->mutex);
    s.shared->stopping = true;
    for (const auto& w : s.shared->event_sessions)
      if (auto p = w.lock()) live.push_back(p);
    s.shared->event_sessions.clear();
  }
  for (auto& p : live) p->close();
  live.clear();
  s.shared->workers.join();  // the requests being worked on finish
  // Give the last answers and close frames a moment to leave, then stop.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  s.ioc.stop();
  for (std::thread& t : s.threads) t.join();
  s.threads.clear();
}

}  // namespace bodyscan::server

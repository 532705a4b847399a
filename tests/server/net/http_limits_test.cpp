// The server against bad and hostile requests: malformed and oversized requests,
// paths that try to leave the web root, MIME types, a client that goes away
// mid-download, and HTTPS with its Secure cookie.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <thread>

#include "tests/server/server_fixture.hpp"

namespace bodyscan::testing {
namespace {

using namespace std::chrono_literals;

std::string raw(int port, const std::string& bytes) {
  auto c = Connection::open(port);
  if (!c) return {};
  c->send_all(bytes);
  std::string out;
  for (std::string part; !(part = c->receive(65536, 3s)).empty();) out += part;
  return out;
}

int status_of(const std::string& reply) { return reply.size() > 12 ? std::atoi(reply.c_str() + 9) : 0; }

class HttpLimits : public SharedServerTest {};

TEST_F(HttpLimits, MalformedRequestsGetClearErrors) {
  const int port = server_->port;
  EXPECT_EQ(status_of(raw(port, "HELLO\r\n\r\n")), 400);
  EXPECT_EQ(status_of(raw(port, "GET /api/health HTTP/9.9\r\n\r\n")), 400);
  EXPECT_EQ(status_of(raw(port, "GET /api/health HTTP/1.1\r\nHost: x\r\nContent-Length: banana\r\n\r\n")), 400);
  EXPECT_EQ(status_of(raw(port, "GET /api/%zz HTTP/1.1\r\nHost: x\r\n\r\n")), 400);
  EXPECT_EQ(status_of(raw(port, "GET /api/health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")), 200);
  EXPECT_EQ(http(port, "GET", "/api/nothing").status, 404);
  const HttpReply wrong_method = http(port, "PATCH", "/api/health");
  EXPECT_EQ(wrong_method.status, 405);
  EXPECT_EQ(wrong_method.header("allow"), "GET");
  Client t = server_->as("tailor");
  EXPECT_EQ(t.request("POST", "/api/scans/" + server_->scan_id + "/measure", "{\"kind\": ", {}).status, 400);
  EXPECT_EQ(t.request("POST", "/api/scans/" + server_->scan_id + "/measure", "[1, 2]", {}).status, 400);
  const nlohmann::json e = parse(t.request("POST", "/api/scans/" + server_->scan_id + "/measure", "nope", {}));
  EXPECT_EQ(e["error"]["status"], 400);
  EXPECT_FALSE(e["error"]["message"].get<std::string>().empty());
}

TEST_F(HttpLimits, WrongTypesBadEncodingsAndConflictingLengthsAre400) {
  const int port = server_->port;
  // A percent-encoding that decodes to bytes which are not UTF-8.
  EXPECT_EQ(status_of(raw(port, "GET /api/jobs/%ff HTTP/1.1\r\nHost: x\r\n\r\n")), 400);
  EXPECT_EQ(status_of(raw(port, "GET /api/health?x=%c3%28 HTTP/1.1\r\nHost: x\r\n\r\n")), 400);
  EXPECT_EQ(server_->as("op").request("GET", "/api/jobs/%ff", "").status, 400);
  // Two Content-Length headers that disagree: answered, not dropped.
  EXPECT_EQ(status_of(raw(port,
                          "POST /api/login HTTP/1.1\r\nHost: x\r\nContent-Length: 2\r\n"
                          "Content-Length: 3\r\n\r\n{}")),
            400);
  // A Host that is no host name (it would end up in a share link).
  EXPECT_EQ(status_of(raw(port, "GET /api/health HTTP/1.1\r\nHost: \x8f\x8f\r\n\r\n")), 400);
  // Fields of the wrong JSON type.
  Client admin = server_->as("admin");
  EXPECT_EQ(
      admin.request("POST", "/api/accounts", R"({"username": "zed", "password": "long enough pw", "role": 5})").status,
      400);
  EXPECT_EQ(admin.request("PUT", "/api/accounts/op", R"({"role": ["admin"]})").status, 400);
  Client tailor = server_->as("tailor");
  const std::string scan = "/api/scans/" + server_->scan_id;
  EXPECT_EQ(tailor.request("POST", scan + "/measure", R"({"kind": 7})").status, 400);
  EXPECT_EQ(tailor.request("POST", scan + "/measurements", R"({"name": 3, "request": {}})").status, 400);
  EXPECT_EQ(tailor.request("POST", scan + "/measurements", R"({"name": "a", "label": {}, "request": {}})").status, 400);
  EXPECT_EQ(tailor.request("POST", "/api/login", R"({"username": 1, "password": 2})").status, 400);
  EXPECT_EQ(http(port, "GET", "/api/health").status, 200);
}

TEST_F(HttpLimits, OversizedRequestsAreRefused) {
  const int port = server_->port;
  Client t = server_->as("tailor");
  const std::string big(2 << 20, ' ');
  const HttpReply body = t.request("POST", "/api/scans/" + server_->scan_id + "/measure", "{" + big + "}", {});
  EXPECT_EQ(body.status, 413);
  const std::string huge_header =
      "GET /api/health HTTP/1.1\r\nHost: x\r\nX-Junk: " + std::string(20000, 'a') + "\r\n\r\n";
  EXPECT_EQ(status_of(raw(port, huge_header)), 431);
  // The server is still there.
  EXPECT_EQ(http(port, "GET", "/api/health").status, 200);
}

TEST_F(HttpLimits, StaticFilesStayInTheWebRootWithTheirMimeTypes) {
  const std::string& web = server_->web;
  std::filesystem::create_directories(web + "/assets");
  std::filesystem::create_directories(web + "/draco");
  for (auto [name, body] :
       {std::pair{"index.html", "<!doctype html><title>bodyscan</title>"},
        std::pair{"assets/app-1234.mjs", "export {}"}, std::pair{"draco/decoder.wasm", "\0asm"},
        std::pair{"model.glb", "glTF"}, std::pair{"cloud.drc", "DRACO"}, std::pair{".env", "secret"}}) {
    std::ofstream(web + "/" + name) << body;
  }
  const std::string outside = temp_dir() + "/secret.txt";
  std::ofstream(outside) << "do not serve";
  std::filesystem::create_symlink(outside, web + "/link.txt");
  const int port = server_->port;
  auto type = [&](const std::string& path) { return http(port, "GET", path).header("content-type"); };
  EXPECT_EQ(type("/"), "text/html; charset=utf-8");
  EXPECT_EQ(type("/assets/app-1234.mjs"), "text/javascript; charset=utf-8");
  EXPECT_EQ(type("/draco/decoder.wasm"), "application/wasm");
  EXPECT_EQ(type("/model.glb"), "model/gltf-binary");
  EXPECT_EQ(type("/cloud.drc"), "application/octet-stream");
  EXPECT_NE(http(port, "GET", "/assets/app-1234.mjs").header("cache-control").find("immutable"), std::string::npos);
  // The page itself: a content security policy, no framing, no Referer (share
  // links carry their token in the path).
  const HttpReply page = http(port, "GET", "/s/sometoken");
  EXPECT_NE(page.header("content-security-policy").find("default-src 'self'"), std::string::npos);
  EXPECT_NE(page.header("content-security-policy").find("frame-ancestors 'none'"), std::string::npos);
  EXPECT_EQ(page.header("referrer-policy"), "no-referrer");
  EXPECT_EQ(http(port, "GET", "/assets/app-1234.mjs").header("content-security-policy"), "");
  // The UI's own routes are the app's page.
  EXPECT_NE(http(port, "GET", "/s/sometoken").body.find("<title>bodyscan</title>"), std::string::npos);
  EXPECT_EQ(http(port, "GET", "/missing.js").status, 404);
  // Escapes, encoded or not, hidden files, and symlinks out of the root.
  for (const char* evil : {"/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/assets/..%2f..%2fsecret", "/.env",
                           "/%2eenv", "/assets/%00x", "/a\\..\\b", "/link.txt", "//etc/passwd"}) {
    const std::string reply =
        raw(port, std::string("GET ") + evil + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
    const int st = status_of(reply);
    EXPECT_TRUE(st == 400 || st == 404) << evil << ": " << st;
    EXPECT_EQ(reply.find("secret"), std::string::npos) << evil;
    EXPECT_EQ(reply.find("root:"), std::string::npos) << evil;
    EXPECT_EQ(reply.find("do not serve"), std::string::npos) << evil;
  }
  EXPECT_EQ(http(port, "POST", "/index.html").status, 405);
}

// The UI's build leaves .gz twins: a browser that takes gzip gets the twin with
// Content-Encoding, any other client the file itself, and caches keep them apart.
TEST_F(HttpLimits, StaticFilesComeGzippedToBrowsersThatTakeIt) {
  const std::string& web = server_->web;
  std::filesystem::create_directories(web + "/assets");
  const std::string plain(4000, 'x');
  std::ofstream(web + "/assets/big-1.js") << plain;
  std::ofstream(web + "/assets/big-1.js.gz") << "GZIPPED-TWIN";
  std::ofstream(web + "/assets/alone-1.js") << "no twin";
  const int port = server_->port;
  const HttpReply zipped = http(port, "GET", "/assets/big-1.js", {{"Accept-Encoding", "br, gzip;q=0.8"}});
  EXPECT_EQ(zipped.status, 200);
  EXPECT_EQ(zipped.header("content-encoding"), "gzip");
  EXPECT_EQ(zipped.body, "GZIPPED-TWIN");
  EXPECT_EQ(zipped.header("content-type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(zipped.header("vary"), "Accept-Encoding");
  for (const char* ae : {"", "identity", "gzip;q=0", "br"}) {
    const HttpReply r = http(
        port, "GET", "/assets/big-1.js",
        ae[0] ? std::map<std::string, std::string>{{"Accept-Encoding", ae}} : std::map<std::string, std::string>{});
    EXPECT_EQ(r.body, plain) << ae;
    EXPECT_EQ(r.header("content-encoding"), "") << ae;
    EXPECT_NE(r.header("etag"), zipped.header("etag")) << ae;
  }
  const HttpReply alone = http(port, "GET", "/assets/alone-1.js", {{"Accept-Encoding", "gzip"}});
  EXPECT_EQ(alone.body, "no twin");
  EXPECT_EQ(alone.header("content-encoding"), "");
  EXPECT_EQ(
      http(port, "GET", "/assets/big-1.js", {{"Accept-Encoding", "gzip"}, {"If-None-Match", zipped.header("etag")}})
          .status,
      304);
}

// A client that asks for the model and hangs up after the first bytes: the
// server carries on serving everyone else.
TEST_F(HttpLimits, AClientThatDisconnectsMidDownloadHarmsNothing) {
  Client t = server_->as("tailor");
  for (int i = 0; i < 5; ++i) {
    auto c = Connection::open(server_->port);
    ASSERT_NE(c, nullptr);
    ASSERT_TRUE(c->send_all("GET /api/scans/" + server_->scan_id +
                            "/points.drc HTTP/1.1\r\nHost: x\r\nCookie: " + t.cookie + "\r\n\r\n"));
    const std::string first = c->receive(100, 5s);
    EXPECT_EQ(status_of(first), 200);
    c->close();
  }
  const HttpReply whole = t.get("/api/scans/" + server_->scan_id + "/points.drc");
  EXPECT_EQ(whole.status, 200);
  EXPECT_EQ(whole.header("content-length"), std::to_string(whole.body.size()));
  EXPECT_EQ(http(server_->port, "GET", "/api/health").status, 200);
}

// Keep-alive: several requests on one connection.
TEST_F(HttpLimits, KeepAliveServesSeveralRequestsOnOneConnection) {
  auto c = Connection::open(server_->port);
  ASSERT_NE(c, nullptr);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(c->send_all("GET /api/health HTTP/1.1\r\nHost: x\r\n\r\n"));
    EXPECT_EQ(c->read_reply(5s).status, 200) << i;
  }
}

TEST(HttpsServer, ServesTlsWithSecureCookies) {
  const std::string dir = temp_dir();
  const std::string cmd = "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=localhost -keyout " + dir +
                          "/key.pem -out " + dir + "/cert.pem >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  server::NetOptions net;
  net.tls_cert = dir + "/cert.pem";
  net.tls_key = dir + "/key.pem";
  ServerUnderTest s(12, net);
  EXPECT_TRUE(s.http->tls());
  EXPECT_EQ(http(s.port, "GET", "/api/health", {}, "", true).status, 200);
  const HttpReply r = http(s.port, "POST", "/api/login", {{"Content-Type", "application/json"}},
                           R"({"username": "op", "password": "correct horse battery"})", true);
  ASSERT_EQ(r.status, 200);
  EXPECT_NE(r.header("set-cookie").find("; Secure"), std::string::npos) << r.header("set-cookie");
  Client op = login(s.port, "op", kPassword, true);
  EXPECT_EQ(op.get("/api/rig").status, 200);
  // Plain HTTP to the TLS port gets nothing useful.
  EXPECT_NE(http(s.port, "GET", "/api/health").status, 200);
  // A bad certificate is a clear error at start.
  server::NetOptions bad;
  bad.port = 0;
  bad.tls_cert = dir + "/key.pem";
  bad.tls_key = dir + "/key.pem";
  server::ApiOptions ao;
  server::Api api(*s.ws, ao);
  auto refused = server::HttpServer::start(api, *s.ws, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("certificate"), std::string::npos) << refused.status().message();
}

// Past NetOptions::max_connections a new connection is told 503 and closed; a
// slot frees when its connection closes.
TEST(HttpConnectionCap, ConnectionsPastTheCapAre503UntilOneCloses) {
  server::NetOptions net;
  net.max_connections = 3;
  ServerUnderTest s(12, net);
  std::vector<std::unique_ptr<Connection>> held;
  for (int i = 0; i < 3; ++i) {
    held.push_back(Connection::open(s.port));
    ASSERT_TRUE(held.back());
    held.back()->send_all("GET /api/health HTTP/1.1\r\nHost: x\r\n\r\n");
    ASSERT_EQ(held.back()->read_reply(5s).status, 200);  // accepted, and kept alive
  }
  const HttpReply busy = http(s.port, "GET", "/api/health");
  EXPECT_EQ(busy.status, 503);
  EXPECT_EQ(busy.header("retry-after"), "5");
  EXPECT_EQ(parse(busy)["error"]["status"], 503);
  held.front()->send_all("GET /api/health HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(held.front()->read_reply(5s).status, 200) << "the connections already open are served";
  held.pop_back();
  int status = 0;
  for (int attempt = 0; attempt < 50 && status != 200; ++attempt) {
    status = http(s.port, "GET", "/api/health").status;
    if (status != 200) std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(status, 200);
}

}  // namespace
}  // namespace bodyscan::testing

// Who reaches what: the OpenAPI file against the routes the server has, every
// endpoint against every kind of caller, CSRF, login limits, share-link scope.
#include <gtest/gtest.h>

#include <set>
#include <thread>

#include "tests/server/server_fixture.hpp"

namespace bodyscan::testing {
namespace {

using server::Api;

std::set<std::string> access_names(unsigned a) {
  std::set<std::string> out;
  if (a & server::kAnyone) out.insert("anyone");
  if (a & server::kShareLink) out.insert("share");
  if (a & server::kOperator) out.insert("operator");
  if (a & server::kTailor) out.insert("tailor");
  if (a & server::kAdmin) out.insert("admin");
  return out;
}

// The rig asks a person to hold the dot grid (as for staff training), so a
// calibration the matrix starts waits at its first prompt and a cancel ends it at
// once, rather than after a camera's lens fit (minutes under the sanitizers).
class ApiAccess : public SharedServerTest {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerUnderTest(12, {}, [](server::WorkstationOptions& o) { o.operator_dot_grid = true; });
  }
};

// The served description is the file in the repository, and it lists exactly the
// routes the server has, each with the callers it admits.
TEST_F(ApiAccess, OpenApiDescribesEveryRouteAndWhoMayCallIt) {
  const HttpReply r = http(server_->port, "GET", "/api/openapi.json");
  ASSERT_EQ(r.status, 200);
  const nlohmann::json doc = parse(r);
  ASSERT_FALSE(doc.is_discarded());
  EXPECT_EQ(doc["openapi"].get<std::string>().substr(0, 2), "3.");
  std::set<std::string> documented, routed;
  for (const auto& [path, ops] : doc["paths"].items())
    for (const auto& [method, op] : ops.items()) {
      std::string m = method;
      for (char& c : m) c = static_cast<char>(std::toupper(c));
      documented.insert(m + " " + path);
      ASSERT_TRUE(op.contains("x-bodyscan-access")) << m << " " << path;
      ASSERT_TRUE(op.contains("responses")) << m << " " << path;
      std::set<std::string> says(op["x-bodyscan-access"].begin(), op["x-bodyscan-access"].end());
      for (const Api::Route& route : server_->api->routes())
        if (route.method == m && route.pattern == path) {
          EXPECT_EQ(says, access_names(route.access)) << m << " " << path;
          const bool staff_only = !(route.access & (server::kAnyone | server::kShareLink));
          if (staff_only) {
            EXPECT_TRUE(op["responses"].contains("401")) << m << " " << path;
            EXPECT_TRUE(op["responses"].contains("403")) << m << " " << path;
          }
        }
    }
  for (const Api::Route& route : server_->api->routes()) routed.insert(route.method + " " + route.pattern);
  EXPECT_EQ(documented, routed);
  // Every $ref resolves.
  std::function<void(const nlohmann::json&)> walk = [&](const nlohmann::json& j) {
    if (j.is_object()) {
      if (j.contains("$ref")) {
        const std::string ref = j["$ref"];
        ASSERT_EQ(ref.rfind("#/", 0), 0u) << ref;
        EXPECT_FALSE(doc.contains(nlohmann::json::json_pointer(ref.substr(1))) == false) << ref;
      }
      for (const auto& [k, v] : j.items()) walk(v);
    } else if (j.is_array()) {
      for (const auto& v : j) walk(v);
    }
  };
  walk(doc);
}

// Every endpoint x {anonymous, customer with a link, operator, tailor, admin}.
// Allowed callers get past authentication and authorisation (whatever the
// request then gives); the others get 401 (no session) or 403 (role), and a
// customer's link opens its own scan's two endpoints and nothing else.
TEST_F(ApiAccess, AccessMatrixOverEveryEndpoint) {
  ServerUnderTest& s = *server_;
  Client admin = s.as("admin");
  ASSERT_FALSE(admin.cookie.empty());
  const HttpReply made =
      admin.post("/api/scans/" + s.scan_id + "/shares", R"({"days": 1, "measurements": ["waist_girth"]})");
  ASSERT_EQ(made.status, 201) << made.body;
  const std::string token = parse(made)["token"];

  auto concrete = [&](const Api::Route& r) {
    std::string p = r.pattern;
    auto put = [&](const std::string& key, const std::string& value) {
      const size_t at = p.find(key);
      if (at != std::string::npos) p.replace(at, key.size(), value);
    };
    const bool destructive = r.method == "DELETE";
    if (p.rfind("/api/customers/", 0) == 0) put("{id}", destructive ? "c_0000000000000000" : s.customer_id);
    if (p.rfind("/api/scans/", 0) == 0) put("{id}", destructive && p == "/api/scans/{id}" ? "s_none" : s.scan_id);
    put("{id}", "x_none");  // jobs, shares
    put("{mid}", "999999");
    put("{username}", "nobody");
    put("{token}", token);
    return p;
  };
  auto body_for = [&](const Api::Route& r) -> std::string {
    if (r.pattern == "/api/login") return R"({"username": "op", "password": "correct horse battery"})";
    if (r.pattern == "/api/scans" && r.method == "POST") return R"({"customer_id": "c_0000000000000000"})";
    if (r.pattern == "/api/scans/{id}/measure") return R"({"kind": "distance", "from": [0, 0, 0], "to": [0, 100, 0]})";
    if (r.method == "POST" || r.method == "PUT") return "{}";
    return "";
  };

  struct Caller {
    std::string name;
    std::string user;  // "" anonymous / customer
    unsigned bit;
  };
  const std::vector<Caller> callers = {{"anonymous", "", 0},
                                       {"customer", "", server::kShareLink},
                                       {"operator", "op", server::kOperator},
                                       {"tailor", "tailor", server::kTailor},
                                       {"admin", "admin", server::kAdmin}};
  int checked = 0;
  for (const Api::Route& r : s.api->routes()) {
    for (const Caller& c : callers) {
      Client client;
      client.port = s.port;
      if (!c.user.empty()) {
        client = s.as(c.user);  // fresh: /api/logout must not end the next case's session
        ASSERT_FALSE(client.cookie.empty()) << c.user;
      } else if (c.name == "customer") {
        client.cookie = std::string(server::kSessionCookie) + "=" + token;  // the link's token is no session
      }
      const std::string target = concrete(r);
      const HttpReply got = client.request(r.method, target, body_for(r));
      ASSERT_NE(got.status, 0) << r.method << " " << target;
      const bool allowed = (r.access & (server::kAnyone | server::kShareLink)) || (r.access & c.bit);
      SCOPED_TRACE(r.method + " " + target + " as " + c.name + ": " + std::to_string(got.status) + " " + got.body);
      if (allowed) {
        EXPECT_NE(got.status, 401);
        EXPECT_NE(got.status, 403);
        EXPECT_LT(got.status, 500);
      } else if (c.user.empty()) {
        EXPECT_EQ(got.status, 401);
      } else {
        EXPECT_EQ(got.status, 403);
      }
      if ((r.pattern == "/api/rig/calibrate" || r.pattern == "/api/rig/posture-check") && got.status == 202) {
        // Allowed and started: stop it again, lasers off, before the next case.
        const std::string job = parse(got)["job"]["id"];
        EXPECT_EQ(client.post("/api/jobs/" + job + "/cancel").status, 202);
        // Both wait at the dot-grid prompt (the fixture's rig is not calibrated),
        // which a cancel wakes.
        ASSERT_TRUE(s.ws->wait_idle(60));
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, static_cast<int>(s.api->routes().size() * callers.size()));

  // The link is scoped: its own scan only, read-only, and a wrong or withdrawn
  // token gives the same 404 as one that never existed.
  EXPECT_EQ(http(s.port, "GET", "/api/share/" + token).status, 200);
  EXPECT_EQ(http(s.port, "GET", "/api/share/" + token + "/mesh.glb").status, 200);
  EXPECT_EQ(http(s.port, "GET", "/api/share/AAAAAAAAAAAAAAAAAAAAAA").status, 404);
  EXPECT_EQ(http(s.port, "GET", "/api/scans/" + s.scan_id + "/mesh.glb?token=" + token).status, 401);
  EXPECT_EQ(http(s.port, "POST", "/api/share/" + token).status, 405);
}

TEST_F(ApiAccess, LoginSetsAStrictHttpOnlyCookieAndLogoutEndsIt) {
  const int port = server_->port;
  HttpReply r = http(port, "POST", "/api/login", {{"Content-Type", "application/json"}},
                     R"({"username": "tailor", "password": "correct horse battery"})");
  ASSERT_EQ(r.status, 200) << r.body;
  const std::string cookie = r.header("set-cookie");
  EXPECT_NE(cookie.find("HttpOnly"), std::string::npos) << cookie;
  EXPECT_NE(cookie.find("SameSite=Strict"), std::string::npos) << cookie;
  EXPECT_EQ(cookie.find("Secure"), std::string::npos) << "plain HTTP: no Secure flag, " << cookie;
  EXPECT_EQ(parse(r)["role"], "tailor");
  Client c = login(port, "tailor", kPassword);
  EXPECT_EQ(c.get("/api/session").status, 200);
  EXPECT_EQ(parse(c.get("/api/session"))["csrf_token"], c.csrf);
  EXPECT_EQ(c.post("/api/logout").status, 204);
  EXPECT_EQ(c.get("/api/session").status, 401);
  EXPECT_EQ(http(port, "POST", "/api/login", {{"Content-Type", "application/json"}},
                 R"({"username": "tailor", "password": "wrong password!"})")
                .status,
            401);
  EXPECT_EQ(http(port, "POST", "/api/login", {{"Content-Type", "application/json"}}, R"({"username": 3})").status, 400);
  EXPECT_EQ(http(port, "POST", "/api/login", {{"Content-Type", "text/plain"}}, "username=a").status, 415);
}

// A JSON body nested 400,000 deep (800 KB, under the 1 MiB limit) killed the
// server where the value was copied (a share's "days", a saved measurement's
// request): every body is refused at parse time past 64 levels, and the server
// goes on.
TEST_F(ApiAccess, DeeplyNestedJsonIsRefusedAndTheServerGoesOn) {
  Client op = server_->as("op");
  const std::string nest = std::string(400000, '[') + std::string(400000, ']');
  const HttpReply r = op.post("/api/customers", R"({"name": )" + nest + "}");
  EXPECT_EQ(r.status, 400) << r.body;
  const HttpReply share = op.post("/api/scans/" + server_->scan_id + "/shares", R"({"days": )" + nest + "}");
  EXPECT_EQ(share.status, 400) << share.body;
  EXPECT_EQ(op.post("/api/customers", R"({"name": "After"})").status, 201);
  EXPECT_EQ(http(server_->port, "GET", "/api/health").status, 200);
}

TEST_F(ApiAccess, StateChangingRequestsNeedTheCsrfTokenAndOurOrigin) {
  Client op = server_->as("op");
  Client no_token = op;
  no_token.csrf.clear();
  EXPECT_EQ(no_token.post("/api/customers", R"({"name": "X"})").status, 403);
  Client wrong = op;
  // One character changed (to one it is not: the token is random, and began with
  // 'A' once in 64 runs, when this "wrong" token was the right one).
  wrong.csrf = (op.csrf[0] == 'A' ? "B" : "A") + op.csrf.substr(1);
  EXPECT_EQ(wrong.post("/api/customers", R"({"name": "X"})").status, 403);
  EXPECT_EQ(op.request("POST", "/api/customers", R"({"name": "X"})", {{"Origin", "https://evil.example"}}).status, 403);
  EXPECT_EQ(op.request("POST", "/api/customers", R"({"name": "X"})",
                       {{"Origin", "http://127.0.0.1:" + std::to_string(server_->port)}})
                .status,
            201);
  EXPECT_EQ(op.post("/api/customers", R"({"name": "Y"})").status, 201);
  // Reading needs no token.
  EXPECT_EQ(no_token.get("/api/customers").status, 200);
}

TEST_F(ApiAccess, RepeatedFailedLoginsAreRefusedForAWhile) {
  const int port = server_->port;
  auto attempt = [&](const std::string& password) {
    return http(port, "POST", "/api/login", {{"Content-Type", "application/json"}},
                R"({"username": "admin", "password": ")" + password + R"("})");
  };
  int refused = 0;
  HttpReply last;
  for (int i = 0; i < 8; ++i) {
    last = attempt("guess number " + std::to_string(i));
    if (last.status == 429) ++refused;
  }
  EXPECT_GE(refused, 3);
  EXPECT_EQ(last.status, 429);
  EXPECT_GT(std::atoi(last.header("retry-after").c_str()), 0);
  // Even the right password waits out the window.
  EXPECT_EQ(attempt(kPassword).status, 429);
}

TEST_F(ApiAccess, EventsNeedAStaffSession) {
  HttpReply refusal;
  EXPECT_EQ(EventStream::open(server_->port, "", &refusal), nullptr);
  EXPECT_EQ(refusal.status, 401);
  Client t = server_->as("tailor");
  auto events = EventStream::open(server_->port, t.cookie);
  ASSERT_NE(events, nullptr);
  auto hello = events->next(std::chrono::seconds(10));
  ASSERT_TRUE(hello);
  const nlohmann::json j = nlohmann::json::parse(*hello);
  EXPECT_EQ(j["type"], "hello");
  EXPECT_EQ(j["rig"]["cameras"].size(), 3u);
  EXPECT_EQ(anonymous(server_->port).get("/api/events").status, 401);
  EXPECT_EQ(t.get("/api/events").status, 426);
}

using namespace std::chrono_literals;

HttpReply login_from(int port, const std::string& password, std::map<std::string, std::string> headers) {
  headers.emplace("Content-Type", "application/json");
  return http(port, "POST", "/api/login", headers, R"({"username": "op", "password": ")" + password + R"("})");
}

// Behind the documented proxy every client reaches the server from 127.0.0.1;
// the client's own address comes from X-Forwarded-For, believed only from the
// configured proxy, and the login limits key on it.
TEST(ProxiedClients, LoginLimitsKeyOnTheAddressTheTrustedProxyForwarded) {
  server::NetOptions net;
  net.trusted_proxies = {"127.0.0.1"};
  ServerUnderTest s(12, net);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(login_from(s.port, "wrong guess " + std::to_string(i), {{"X-Forwarded-For", "10.0.0.1"}}).status, 401);
  EXPECT_EQ(login_from(s.port, kPassword, {{"X-Forwarded-For", "10.0.0.1"}}).status, 429);
  // What the guesser writes to the left of the proxy's entry changes nothing.
  EXPECT_EQ(login_from(s.port, kPassword, {{"X-Forwarded-For", "10.0.0.2, 10.0.0.1"}}).status, 429);
  // The right password from another client gets in.
  const HttpReply ok = login_from(s.port, kPassword, {{"X-Forwarded-For", "10.0.0.2"}, {"X-Forwarded-Proto", "https"}});
  EXPECT_EQ(ok.status, 200);
  EXPECT_NE(ok.header("set-cookie").find("; Secure"), std::string::npos) << "TLS ended at the proxy";
  // The host the proxy says the browser addressed satisfies the Origin check.
  Client op = s.as("op");
  EXPECT_EQ(op.request("POST", "/api/customers", R"({"name": "P"})",
                       {{"Origin", "https://scanner.shop.example"}, {"X-Forwarded-Host", "scanner.shop.example"}})
                .status,
            201);
}

// Without a trusted proxy the X-Forwarded-* headers are the client's own words.
TEST(ProxiedClients, ForwardedHeadersFromAnyoneElseAreIgnored) {
  ServerUnderTest s;
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(
        login_from(s.port, "wrong guess " + std::to_string(i), {{"X-Forwarded-For", "10.0.1." + std::to_string(i)}})
            .status,
        401);
  EXPECT_EQ(login_from(s.port, kPassword, {{"X-Forwarded-For", "10.0.1.99"}}).status, 429);
  Client admin = s.as("admin");
  EXPECT_EQ(admin
                .request("POST", "/api/customers", R"({"name": "Q"})",
                         {{"Origin", "https://evil.example"}, {"X-Forwarded-Host", "evil.example"}})
                .status,
            403);
  const HttpReply plain =
      http(s.port, "POST", "/api/login", {{"Content-Type", "application/json"}, {"X-Forwarded-Proto", "https"}},
           std::string(R"({"username": "tailor", "password": ")") + kPassword + R"("})");
  ASSERT_EQ(plain.status, 200);
  EXPECT_EQ(plain.header("set-cookie").find("; Secure"), std::string::npos) << "plain HTTP all the way";
}

// True once the server has closed the socket (within `wait`); false while it is
// open. Messages that arrive meanwhile (events, previews) are skipped.
bool closed_within(EventStream& events, std::chrono::milliseconds wait) {
  const auto until = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < until) {
    events.next(std::chrono::milliseconds(200));
    if (events.closed()) return true;
  }
  return events.closed();
}

std::unique_ptr<EventStream> open_events(int port, const Client& c) {
  auto events = EventStream::open(port, c.cookie);
  if (events && !events->next(std::chrono::seconds(10))) return nullptr;  // the hello
  return events;
}

// A socket carries job events and camera pictures of the person in the rig: it
// lives no longer than the session it was opened with, whatever ends that.
TEST(EventSockets, CloseWhenTheirSessionEndsOrChanges) {
  ServerUnderTest s;
  Client admin = s.as("admin");
  for (const char* name : {"anna", "ben", "carl"})
    ASSERT_EQ(admin
                  .post("/api/accounts", std::string(R"({"username": ")") + name +
                                             R"(", "password": "a long password", "role": "operator"})")
                  .status,
              201);
  const Client anna1 = login(s.port, "anna", "a long password"), anna2 = login(s.port, "anna", "a long password");
  const Client ben = login(s.port, "ben", "a long password"), carl = login(s.port, "carl", "a long password");
  auto e_anna1 = open_events(s.port, anna1), e_anna2 = open_events(s.port, anna2);
  auto e_ben = open_events(s.port, ben), e_carl = open_events(s.port, carl);
  auto e_admin = open_events(s.port, admin);
  ASSERT_TRUE(e_anna1 && e_anna2 && e_ben && e_carl && e_admin);

  // Logout ends that session's socket only.
  EXPECT_EQ(anna1.post("/api/logout").status, 204);
  EXPECT_TRUE(closed_within(*e_anna1, 5s));
  EXPECT_FALSE(closed_within(*e_anna2, 500ms));
  // A new password ends every session of the account.
  EXPECT_EQ(admin.put("/api/accounts/ANNA", R"({"password": "another long password"})").status, 200);
  EXPECT_TRUE(closed_within(*e_anna2, 5s));
  // So does a new role, and deleting the account.
  EXPECT_EQ(admin.put("/api/accounts/ben", R"({"role": "tailor"})").status, 200);
  EXPECT_TRUE(closed_within(*e_ben, 5s));
  EXPECT_EQ(admin.del("/api/accounts/carl").status, 204);
  EXPECT_TRUE(closed_within(*e_carl, 5s));
  // Nobody else's socket is touched.
  EXPECT_FALSE(closed_within(*e_admin, 500ms));
  // A closed socket cannot be reopened with the ended session.
  HttpReply refusal;
  EXPECT_EQ(EventStream::open(s.port, anna1.cookie, &refusal), nullptr);
  EXPECT_EQ(refusal.status, 401);
}

TEST(EventSockets, CloseWhenTheirSessionExpires) {
  ServerUnderTest s(12, {}, [](server::WorkstationOptions& wo) { wo.auth.session_idle_s = 2; });
  const Client op = s.as("op");
  auto events = open_events(s.port, op);
  ASSERT_TRUE(events);
  EXPECT_TRUE(closed_within(*events, 6s)) << "idle for longer than the idle limit";
}

}  // namespace
}  // namespace bodyscan::testing

namespace bodyscan::testing {
namespace {

// An admin manages the staff: add, change role and password (which ends the
// account's sessions), delete; never the last admin.
TEST(ApiAccounts, AdminManagesStaffAccounts) {
  ServerUnderTest s;
  Client admin = s.as("admin");
  const HttpReply made =
      admin.post("/api/accounts", R"({"username": "fitter", "password": "measure twice cut once", "role": "tailor"})");
  ASSERT_EQ(made.status, 201) << made.body;
  EXPECT_EQ(parse(made)["role"], "tailor");
  EXPECT_EQ(
      admin.post("/api/accounts", R"({"username": "fitter", "password": "measure twice cut once", "role": "tailor"})")
          .status,
      409);
  EXPECT_EQ(
      admin.post("/api/accounts", R"({"username": "x y", "password": "measure twice cut once", "role": "tailor"})")
          .status,
      400);
  EXPECT_EQ(admin.post("/api/accounts", R"({"username": "shorty", "password": "short", "role": "tailor"})").status,
            400);
  EXPECT_EQ(admin.post("/api/accounts", R"({"username": "boss", "password": "measure twice cut once", "role": "king"})")
                .status,
            400);
  const nlohmann::json list = parse(admin.get("/api/accounts"));
  EXPECT_EQ(list["accounts"].size(), 4u);
  Client fitter = login(s.port, "fitter", "measure twice cut once");
  ASSERT_FALSE(fitter.cookie.empty());
  EXPECT_EQ(fitter.post("/api/rig/calibrate").status, 403);
  ASSERT_EQ(admin.put("/api/accounts/fitter", R"({"role": "operator"})").status, 200);
  EXPECT_EQ(parse(fitter.get("/api/session"))["role"], "operator") << "a role change applies to live sessions";
  ASSERT_EQ(admin.put("/api/accounts/fitter", R"({"password": "a brand new password"})").status, 200);
  EXPECT_EQ(fitter.get("/api/session").status, 401) << "a new password ends the account's sessions";
  EXPECT_FALSE(login(s.port, "fitter", "a brand new password").cookie.empty());
  EXPECT_EQ(admin.put("/api/accounts/nobody", R"({"role": "operator"})").status, 404);
  EXPECT_EQ(admin.put("/api/accounts/admin", R"({"role": "tailor"})").status, 409) << "the last admin";
  EXPECT_EQ(admin.del("/api/accounts/admin").status, 409) << "the last admin";
  EXPECT_EQ(admin.del("/api/accounts/fitter").status, 204);
  EXPECT_TRUE(login(s.port, "fitter", "a brand new password").cookie.empty());
  EXPECT_EQ(admin.del("/api/accounts/fitter").status, 404);
  // Every change is in the audit log, by whom.
  auto audit = s.ws->archive().audit("fitter");
  ASSERT_TRUE(audit.ok());
  EXPECT_GE(audit->size(), 3u);
  for (const auto& e : *audit) EXPECT_TRUE(e.actor == "admin" || e.actor == "fitter") << e.actor;
}

}  // namespace
}  // namespace bodyscan::testing

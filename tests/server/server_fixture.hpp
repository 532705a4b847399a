// A running workstation for the server tests: the simulated rig, a fresh archive,
// three staff accounts (one per role), a finished scan of the demo body (its true
// mesh as the surface, measured), and the HTTP server on a free port.
#pragma once

#include <gtest/gtest.h>
#include <sodium.h>

#include <functional>
#include <memory>
#include <string>

#include "pipeline/archive_scan.hpp"
#include "recon/io/ply.hpp"
#include "server/api/api.hpp"
#include "server/net/http_server.hpp"
#include "server/workstation/workstation.hpp"
#include "tests/half_resolution.hpp"
#include "tests/server/http_client.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::testing {

inline constexpr const char* kPassword = "correct horse battery";

inline std::string demo_body_path() { return std::string(BODYSCAN_SOURCE_DIR) + "/hw/sim/bodies/male_average.ply"; }

// A ServerUnderTest tweak for tests of a job's course rather than its figures
// (cancelling, a failing camera, prompts): the thesis rig at half resolution,
// whose calibration renders four times fewer pixels.
inline void on_half_resolution_rig(server::WorkstationOptions& o) { o.rig = half_resolution_rig_file(); }

struct ServerUnderTest {
  std::string data, web;
  std::unique_ptr<server::Workstation> ws;
  std::unique_ptr<server::Api> api;
  std::unique_ptr<server::HttpServer> http;
  int port = 0;
  std::string scan_id, customer_id;  // the finished demo scan
  TriangleMesh body;                 // its surface (the true body)

  // `every`: the scans the tests run use every Nth laser step (fast). `tweak`
  // changes the workstation's options before it opens.
  explicit ServerUnderTest(int every = 12, server::NetOptions net = {},
                           const std::function<void(server::WorkstationOptions&)>& tweak = {}) {
    data = temp_dir();
    web = temp_dir();
    server::WorkstationOptions wo;
    wo.data_dir = data;
    wo.default_every = every;
    wo.auth.opslimit = crypto_pwhash_OPSLIMIT_MIN;
    wo.auth.memlimit = crypto_pwhash_MEMLIMIT_MIN;
    wo.preview_interval_s = 0.2;
    if (tweak) tweak(wo);
    auto opened = server::Workstation::open(wo);
    if (!opened.ok()) throw std::runtime_error(opened.status().message());
    ws = std::move(*opened);
    for (auto [name, role] : {std::pair{"op", server::Role::kOperator}, std::pair{"tailor", server::Role::kTailor},
                              std::pair{"admin", server::Role::kAdmin}}) {
      auto a = ws->auth().add_account(name, kPassword, role);
      if (!a.ok()) throw std::runtime_error(a.status().message());
    }
    seed_scan();
    server::ApiOptions ao;
    ao.web_root = web;
    api = std::make_unique<server::Api>(*ws, ao);
    net.port = 0;
    net.address = "127.0.0.1";
    auto started = server::HttpServer::start(*api, *ws, net);
    if (!started.ok()) throw std::runtime_error(started.status().message());
    http = std::move(*started);
    port = http->port();
  }
  ~ServerUnderTest() {
    ws->shutdown("the test ended");
    http->stop();
  }

  Client as(const std::string& user) const { return login(port, user, kPassword); }

 private:
  void seed_scan() {
    auto mesh = read_ply_mesh(demo_body_path());
    if (!mesh.ok()) throw std::runtime_error(mesh.status().message());
    body = *mesh;
    pipeline::ScanJobResult r;
    r.mesh = body;
    r.cloud.positions = body.vertices;
    auto measured = measure_body(body);
    if (measured.ok()) r.body = std::move(*measured);
    auto c = ws->archive().add_customer(std::string("Demo Customer"), std::nullopt, "test");
    if (!c.ok()) throw std::runtime_error(c.status().message());
    customer_id = c->id;
    auto consented = ws->archive().record_consent(customer_id, ws->consent_terms(), "test");
    if (!consented.ok()) throw std::runtime_error(consented.status().message());
    auto id = ws->archive().begin_scan(customer_id, "test", nlohmann::json::object(), "");
    if (!id.ok()) throw std::runtime_error(id.status().message());
    scan_id = *id;
    const Status s = pipeline::archive_scan(ws->archive(), scan_id, r, {});
    if (!s.ok()) throw std::runtime_error(s.message());
  }
};

// A suite whose tests share one server (ctest runs each test in a process of its
// own; run by hand, the suite's tests see each other's changes).
class SharedServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new ServerUnderTest(); }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  inline static ServerUnderTest* server_ = nullptr;
};

inline nlohmann::json parse(const HttpReply& r) { return nlohmann::json::parse(r.body, nullptr, false); }

}  // namespace bodyscan::testing

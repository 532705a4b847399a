// HTTP requests as a connection reads them (Beast's parser under the server's
// limits, the target's decoding, forwarded headers from a trusted proxy), then
// routed through the API of a workstation on the simulated rig with one
// archived scan. An input whose last byte is odd (bytes after the request are
// ignored, so a mutation can flip it) is sent with a tailor's session and CSRF
// token added, so that the staff routes are reached too (a tailor cannot start
// rig jobs, which would run on in the background). "@scan" and "@customer" in
// the path stand for the archived scan's and its customer's ids, which are made
// up anew in every run.
#include <sodium.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "pipeline/archive_scan.hpp"
#include "recon/io/ply.hpp"
#include "server/api/api.hpp"
#include "server/net/http_server.hpp"
#include "server/workstation/workstation.hpp"

namespace {

using namespace bodyscan;

struct Fixture {
  std::unique_ptr<server::Workstation> ws;
  std::unique_ptr<server::Api> api;
  server::NetOptions net;
  std::string cookie, csrf, scan_id, customer_id;

  Fixture() {
    const std::string dir =
        (std::filesystem::temp_directory_path() / ("bodyscan-http-fuzz-" + std::to_string(::getpid()))).string();
    std::filesystem::remove_all(dir);
    server::WorkstationOptions wo;
    wo.data_dir = dir + "/data";
    wo.default_every = 12;
    wo.auth.opslimit = crypto_pwhash_OPSLIMIT_MIN;
    wo.auth.memlimit = crypto_pwhash_MEMLIMIT_MIN;
    wo.auth.max_failures = 0;  // the fuzzer guesses passwords all day
    auto opened = server::Workstation::open(wo);
    if (!opened.ok()) std::abort();
    ws = std::move(*opened);
    if (!ws->auth().add_account("tailor", "tailor password", server::Role::kTailor).ok()) std::abort();
    auto mesh = read_ply_mesh(std::string(BODYSCAN_SOURCE_DIR) + "/hw/sim/bodies/male_average.ply");
    auto customer = ws->archive().add_customer(std::string("Fuzz"), std::nullopt, "fuzz");
    if (!mesh.ok() || !customer.ok()) std::abort();
    auto scan = ws->archive().begin_scan(customer->id, "fuzz", nlohmann::json::object(), "");
    if (!scan.ok()) std::abort();
    pipeline::ScanJobResult r;
    r.mesh = *mesh;
    r.cloud.positions = mesh->vertices;
    if (!pipeline::archive_scan(ws->archive(), *scan, r, {}).ok()) std::abort();
    scan_id = *scan;
    customer_id = customer->id;
    server::ApiOptions ao;
    ao.web_root = dir + "/web";
    std::filesystem::create_directories(ao.web_root);
    api = std::make_unique<server::Api>(*ws, ao);
    const server::LoginResult login = ws->auth().login("tailor", "tailor password", "127.0.0.1");
    if (login.outcome != server::LoginResult::kOk) std::abort();
    cookie = std::string(server::kSessionCookie) + "=" + login.token;
    csrf = login.session.csrf_token;
    net.trusted_proxies = {"127.0.0.1"};
  }
};

void replace_all(std::string* s, std::string_view from, const std::string& to) {
  for (size_t at = s->find(from); at != std::string::npos; at = s->find(from, at + to.size()))
    s->replace(at, from.size(), to);
}

}  // namespace

namespace {
Fixture* f = nullptr;  // lives for the process: the workstation's threads run on
}  // namespace

// Opening the workstation takes seconds under the sanitizers: done once, before
// the first input, outside the per-input timeout.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  f = new Fixture();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  server::RequestBytes read = server::parse_request_bytes(bytes, f->net, "127.0.0.1");
  if (!read.request) return 0;
  replace_all(&read.request->path, "@scan", f->scan_id);
  replace_all(&read.request->path, "@customer", f->customer_id);
  if (size > 0 && (data[size - 1] & 1)) {
    read.request->headers["cookie"] = f->cookie;
    read.request->headers["x-csrf-token"] = f->csrf;
  }
  const server::HttpResponse response = f->api->handle(*read.request);
  if (response.status < 200 || response.status > 599) __builtin_trap();
  return 0;
}

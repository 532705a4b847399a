// `bodyscan serve`: the workstation. Opens the archive, the accounts and the rig,
// serves the API and the browser UI, and on SIGINT, SIGTERM, SIGHUP, SIGQUIT or
// SIGUSR1 cancels the running job (marked as such in the archive), turns the
// lasers off and closes cleanly.
#include <signal.h>
#include <sodium.h>
#include <strings.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "app/cli_subject.hpp"
#include "core/command_line.hpp"
#include "recon/io/atomic_file.hpp"
#include "server/api/api.hpp"
#include "server/net/http_server.hpp"
#include "server/workstation/workstation.hpp"

namespace bodyscan::cli {

namespace {

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1};

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGQUIT: return "SIGQUIT";
    case SIGUSR1: return "SIGUSR1";
    default: return "signal";
  }
}

std::string usage() {
  return std::string(
             "usage: bodyscan serve [options]\n"
             "\n"
             "Runs the workstation: the rig (calibration, scans, reconstruction), the\n"
             "archive, the REST API and WebSocket events (docs/api.md), and the browser UI.\n"
             "On embedded defaults: the simulated rig with the demo body, the archive in\n"
             "./bodyscan-data, port 8080.\n"
             "\n"
             "  --address A        the address to listen on (default 0.0.0.0)\n"
             "  --port N           (default 8080; 0 picks a free port)\n"
             "  --data DIR         the archive and accounts (default ./bodyscan-data)\n"
             "  --rig RIG          sim (default), thesis, square, tiered or a rig description file\n") +
         kSubjectOptionsHelp +
         "  --every N          scans use every Nth laser step unless asked otherwise\n"
         "                     (default 1)\n"
         "  --repeatability MM two scans of one customer on one day may differ by MM\n"
         "                     before the station suggests another (default: each\n"
         "                     value's ISO 20685-1 allowance, 4-9 mm)\n"
         "  --retention-days N erase scans that started more than N days ago, at start\n"
         "                     and hourly (logged in the audit); default: keep them\n"
         "  --operator-dot-grid\n"
         "                     calibration asks a person to hold the lens board before\n"
         "                     the simulated cameras too, as it does before real ones\n"
         "                     (staff training)\n"
         "  --web DIR          the browser UI's files (default: the UI this build made, BUILD/web)\n"
         "  --tls-cert PEM --tls-key PEM\n"
         "                     serve HTTPS (session cookies become Secure)\n"
         "  --behind-tls-proxy a TLS proxy in front forwards to us: cookies Secure\n"
         "  --trusted-proxy A  believe X-Forwarded-For/-Proto/-Host from this address\n"
         "                     (the reverse proxy's; repeatable)\n"
         "  --public-url URL   the address customers' share links start with\n"
         "  --admin NAME       the first admin account, made when there is none; its\n"
         "                     password comes from BODYSCAN_ADMIN_PASSWORD, or one is made\n"
         "                     up, printed once and kept in DATA/first-admin-password\n"
         "                     (mode 0600) until changed\n"
         "  --workers N        threads for requests' work (default 3)\n"
         "  --max-connections N\n"
         "                     open HTTP and WebSocket connections at most; more are\n"
         "                     answered 503 (default: the descriptor limit less 128)\n";
}

constexpr size_t kMaxLogoBytes = 2 << 20;

std::string random_password() {
  unsigned char b[12];
  randombytes_buf(b, sizeof b);
  std::string out(sodium_base64_encoded_len(sizeof b, sodium_base64_VARIANT_URLSAFE_NO_PADDING), '\0');
  sodium_bin2base64(out.data(), out.size(), b, sizeof b, sodium_base64_VARIANT_URLSAFE_NO_PADDING);
  out.pop_back();
  return out;
}

}  // namespace

int run_serve(int argc, char** argv) {
  server::WorkstationOptions wo;
  server::NetOptions no;
  server::ApiOptions ao;
  ao.web_root = BODYSCAN_WEB_ROOT;
  std::string admin = "admin";
  CommandLine cl("bodyscan serve", usage());
  cl.option("--address", &no.address);
  cl.option("--port", integer_between(0, 65535, [&no](long long n) { no.port = static_cast<uint16_t>(n); }));
  cl.option("--data", &wo.data_dir);
  cl.option("--rig", &wo.rig);
  add_subject_options(&cl, &wo.subject);
  cl.option("--every", integer_between(1, 1000, [&wo](long long n) { wo.default_every = static_cast<int>(n); }));
  cl.option("--repeatability", [&wo](const std::string& v) -> std::string {
    const auto mm = parse_double(v);
    if (!mm || *mm <= 0 || *mm > 100) return "expects millimetres, more than 0 and at most 100, got '" + v + "'";
    wo.repeatability_mm = *mm;
    return "";
  });
  cl.option("--retention-days",
            integer_between(1, 36500, [&wo](long long n) { wo.retention_days = static_cast<int>(n); }));
  cl.flag("--operator-dot-grid", &wo.operator_dot_grid);
  cl.option("--web", &ao.web_root);
  cl.option("--tls-cert", &no.tls_cert);
  cl.option("--tls-key", &no.tls_key);
  cl.flag("--behind-tls-proxy", &ao.secure_cookies);
  cl.option("--trusted-proxy", &no.trusted_proxies);
  cl.option("--public-url", &ao.public_url);
  cl.option("--shop-name", &ao.shop_name);
  std::string logo_path;
  cl.option("--shop-logo", &logo_path);
  cl.option("--locale", [&ao](const std::string& v) -> std::string {
    auto locale = storage::parse_locale(v);
    if (!locale.ok()) return "expects en or de (the languages shipped), got '" + v + "'";
    ao.locale = *locale;
    return "";
  });
  cl.option("--admin", &admin);
  cl.option("--workers", integer_between(1, 64, [&no](long long n) { no.workers = static_cast<int>(n); }));
  cl.option("--max-connections",
            integer_between(1, 1000000, [&no](long long n) { no.max_connections = static_cast<size_t>(n); }));
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (!logo_path.empty()) {
    // Read once and tried on a sheet now, so that a wrong file stops the start
    // rather than every customer's sheet.
    auto logo = read_whole_file(logo_path);
    if (!logo.ok()) return cl.fail("--shop-logo: " + logo.status().message());
    if (logo->size() > kMaxLogoBytes) return cl.fail("--shop-logo: the PNG is over 2 MB");
    storage::CustomerSheet trial;
    trial.shop_logo_png = *logo;
    if (auto tried = storage::customer_sheet_pdf(trial, TriangleMesh(), storage::LengthUnit::kCentimetre); !tried.ok())
      return cl.fail("--shop-logo " + logo_path + ": " + tried.status().message());
    ao.shop_logo_png = std::move(*logo);
  }
  if (!no.tls_cert.empty()) ao.secure_cookies = true;

  // The signals that end a process by default and that a person or the system
  // sends to stop it (Ctrl-C, kill, a closed terminal or ssh session, Ctrl-\,
  // a stray SIGUSR1) are taken by this thread alone (sigwait below) and stop the
  // workstation in order, lasers off: every thread started from here on inherits
  // the block.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  for (int stop : kStopSignals) sigaddset(&stop_signals, stop);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  // Everything the workstation writes (the archive, accounts, logs of people's
  // scans) is for its own user only, however it was started.
  umask(0077);

  auto ws = server::Workstation::open(wo);
  if (!ws.ok()) {
    std::fprintf(stderr, "bodyscan serve: %s\n", ws.status().message().c_str());
    return 1;
  }
  const auto& recovered = (*ws)->archive().recovery();
  for (const std::string& id : recovered.scans_failed)
    std::fprintf(stderr, "bodyscan serve: scan %s was interrupted by the last stop; marked failed\n", id.c_str());
  if (!(*ws)->auth().has_admin()) {
    const char* env = std::getenv("BODYSCAN_ADMIN_PASSWORD");
    const std::string password = env && *env ? env : random_password();
    auto made = (*ws)->auth().add_account(admin, password, server::Role::kAdmin);
    if (!made.ok()) {
      std::fprintf(stderr, "bodyscan serve: cannot make the first admin '%s': %s\n", admin.c_str(),
                   made.status().message().c_str());
      return 1;
    }
    if (!(env && *env)) {
      const std::string file = wo.data_dir + "/first-admin-password";
      const Status w = write_file_atomically(file, password + "\n", FileAccess::kPrivate);
      if (!w.ok()) std::fprintf(stderr, "bodyscan serve: %s\n", w.message().c_str());
      std::printf("first admin account: %s, password %s (also in %s; change it after logging in)\n", admin.c_str(),
                  password.c_str(), file.c_str());
    } else {
      std::printf("first admin account: %s (password from BODYSCAN_ADMIN_PASSWORD)\n", admin.c_str());
    }
  }
  // The made-up first password is kept on disk only until it stops working.
  const std::string first_password_file = wo.data_dir + "/first-admin-password";
  (*ws)->auth().watch_sessions([first_password_file, admin](const server::SessionChange& change) {
    if (change.reason != server::SessionChange::kPassword && change.reason != server::SessionChange::kDeleted) return;
    if (strcasecmp(change.username.c_str(), admin.c_str()) != 0) return;
    if (std::remove(first_password_file.c_str()) == 0)
      std::fprintf(stderr, "bodyscan serve: %s removed: the password in it no longer works\n",
                   first_password_file.c_str());
  });
  server::Api api(**ws, ao);
  auto http = server::HttpServer::start(api, **ws, no);
  if (!http.ok()) {
    std::fprintf(stderr, "bodyscan serve: %s\n", http.status().message().c_str());
    return 1;
  }
  const std::string host = no.address == "0.0.0.0" || no.address == "::" ? "localhost" : no.address;
  std::printf("bodyscan workstation on %s rig, archive in %s\nopen %s://%s:%u/\n",
              (*ws)->rig_status()["rig"].get<std::string>().c_str(), wo.data_dir.c_str(),
              (*http)->tls() ? "https" : "http", host.c_str(), (*http)->port());
  std::fflush(stdout);

  int sig = 0;
  sigwait(&stop_signals, &sig);
  std::printf("bodyscan serve: %s: stopping (lasers off, the running job cancelled)\n", signal_name(sig));
  std::fflush(stdout);
  // The job first, so that browsers still hear it was cancelled; then the network.
  (*ws)->shutdown("the workstation stopped");
  (*http)->stop();
  ws->reset();
  std::printf("bodyscan serve: stopped cleanly\n");
  return 0;
}

}  // namespace bodyscan::cli

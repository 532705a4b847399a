// `bodyscan serve` as a shop runs it: the real binary, stopped with SIGTERM in
// the middle of a scan. It must exit cleanly and leave the scan marked
// cancelled with the reason, and the next start must find the archive whole.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <thread>
#include <utility>
#include <vector>

#include "storage/archive/archive.hpp"
#include "tests/server/http_client.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::testing {
namespace {

using namespace std::chrono_literals;

struct Child {
  pid_t pid = -1;
  FILE* out = nullptr;
};

// How the child starts besides its data folder and admin password.
struct ServeStart {
  std::vector<std::string> extra_args;
  rlim_t descriptor_limit = 0;  // RLIMIT_NOFILE for the child; 0: inherited
  bool stderr_to_log = false;   // its stderr into the same pipe as its stdout
};

Child start_serve(const std::string& data, const std::string& password, const ServeStart& how = {}) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  std::vector<std::string> args = {BODYSCAN_BIN, "serve",     "--data",    data,      "--port",
                                   "0",          "--address", "127.0.0.1", "--every", "4"};
  args.insert(args.end(), how.extra_args.begin(), how.extra_args.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // a test killed on its timeout takes its server with it
    dup2(fds[1], STDOUT_FILENO);
    if (how.stderr_to_log) dup2(fds[1], STDERR_FILENO);
    close(fds[0]);
    if (how.descriptor_limit > 0) {
      const rlimit limit{how.descriptor_limit, how.descriptor_limit};
      if (setrlimit(RLIMIT_NOFILE, &limit) != 0) _exit(126);
    }
    setenv("BODYSCAN_ADMIN_PASSWORD", password.c_str(), 1);
    execv(BODYSCAN_BIN, argv.data());
    _exit(127);
  }
  close(fds[1]);
  return {pid, fdopen(fds[0], "r")};
}

// The port from the "open http://HOST:PORT/" line.
int read_port(FILE* out, std::string* log) {
  char line[512];
  while (std::fgets(line, sizeof line, out)) {
    *log += line;
    const std::string s = line;
    const size_t at = s.find("open http://");
    if (at != std::string::npos) return std::atoi(s.c_str() + s.rfind(':') + 1);
  }
  return 0;
}

// Sends `sig` to the child, reads the rest of its output into *log and waits for
// it to end: its wait status.
int signal_and_wait(Child& child, int sig, std::string* log) {
  if (kill(child.pid, sig) != 0) return -1;
  char line[512];
  while (std::fgets(line, sizeof line, child.out)) *log += line;
  int status = 0;
  if (waitpid(child.pid, &status, 0) != child.pid) return -1;
  fclose(child.out);
  return status;
}

TEST(ServeCli, SigtermMidScanCancelsTheScanAndStopsCleanly) {
  const std::string data = temp_dir();
  const std::string password = "a long test password";
  Child child = start_serve(data, password);
  ASSERT_GT(child.pid, 0);
  std::string log;
  const int port = read_port(child.out, &log);
  ASSERT_GT(port, 0) << log;
  Client admin = login(port, "admin", password);
  ASSERT_FALSE(admin.cookie.empty());
  const HttpReply started = admin.post("/api/scans", R"({"customer": {"name": "Interrupted"}, "consent": true})");
  ASSERT_EQ(started.status, 202) << started.body;
  const nlohmann::json job = nlohmann::json::parse(started.body)["job"];
  const std::string scan_id = job["scan_id"];
  const auto until = std::chrono::steady_clock::now() + 240s;
  for (;;) {
    const nlohmann::json j = nlohmann::json::parse(admin.get("/api/jobs/" + job["id"].get<std::string>()).body)["job"];
    if (j["stage"] == "scan" && j["frames"].get<int64_t>() > 10) break;
    ASSERT_EQ(j["state"], "running");
    ASSERT_LT(std::chrono::steady_clock::now(), until);
    std::this_thread::sleep_for(100ms);
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int status = signal_and_wait(child, SIGTERM, &log);
  ASSERT_NE(status, -1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 0) << log;
  EXPECT_NE(log.find("stopped cleanly"), std::string::npos) << log;
  EXPECT_LT(seconds, 20.0) << "the scan stops at the next frame";
  auto archive = storage::Archive::open(data);
  ASSERT_TRUE(archive.ok()) << archive.status().message();
  EXPECT_TRUE((*archive)->recovery().scans_failed.empty()) << "the scan was closed, not left running";
  auto scan = (*archive)->scan(scan_id);
  ASSERT_TRUE(scan.ok());
  EXPECT_EQ(scan->status, storage::ScanStatus::kCancelled);
  EXPECT_EQ(scan->status_reason, "cancelled: the workstation stopped");
  EXPECT_TRUE((*archive)->verify().ok());
}

// A closed terminal or ssh session (SIGHUP), Ctrl-\ (SIGQUIT) and a stray SIGUSR1
// end a process at once by default; the workstation stops in order instead, as on
// SIGTERM (the path that cancels a running scan above).
TEST(ServeCli, HangupQuitAndUsr1StopInOrderLikeSigterm) {
  for (const auto& [sig, name] : {std::pair{SIGHUP, "SIGHUP"}, {SIGQUIT, "SIGQUIT"}, {SIGUSR1, "SIGUSR1"}}) {
    const std::string data = temp_dir();
    Child child = start_serve(data, "a long test password");
    ASSERT_GT(child.pid, 0);
    std::string log;
    ASSERT_GT(read_port(child.out, &log), 0) << log;
    const int status = signal_and_wait(child, sig, &log);
    ASSERT_NE(status, -1) << name;
    ASSERT_TRUE(WIFEXITED(status)) << name << ": " << log;
    EXPECT_EQ(WEXITSTATUS(status), 0) << name << ": " << log;
    EXPECT_NE(log.find(std::string(name) + ": stopping"), std::string::npos) << log;
    EXPECT_NE(log.find("stopped cleanly"), std::string::npos) << log;
  }
}

// A made-up first password is written where only the service's user can read
// it, and removed as soon as it stops working.
TEST(ServeCli, TheFirstAdminPasswordFileIsPrivateAndGoesWhenThePasswordChanges) {
  const std::string data = temp_dir();
  Child child = start_serve(data, "");  // no BODYSCAN_ADMIN_PASSWORD: one is made up
  ASSERT_GT(child.pid, 0);
  std::string log;
  const int port = read_port(child.out, &log);
  ASSERT_GT(port, 0) << log;
  const std::string file = data + "/first-admin-password";
  struct stat st {};
  ASSERT_EQ(stat(file.c_str(), &st), 0) << log;
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(stat(data.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0077, 0u) << "the data folder is the service's alone";
  std::string password;
  {
    std::ifstream in(file);
    std::getline(in, password);
  }
  Client admin = login(port, "admin", password);
  ASSERT_FALSE(admin.cookie.empty()) << "the file holds the working password";
  // Another account changing its password leaves the file alone.
  ASSERT_EQ(
      admin.post("/api/accounts", R"({"username": "zoe", "password": "zoes long password", "role": "tailor"})").status,
      201);
  ASSERT_EQ(admin.put("/api/accounts/zoe", R"({"password": "zoes new long password"})").status, 200);
  EXPECT_EQ(stat(file.c_str(), &st), 0);
  ASSERT_EQ(admin.put("/api/accounts/admin", R"({"password": "the admin's own password"})").status, 200);
  EXPECT_NE(stat(file.c_str(), &st), 0) << "the old password no longer works; its file is gone";
  signal_and_wait(child, SIGTERM, &log);
}

// A server out of descriptors (clients hold every one the process may open)
// waits before accepting again rather than spinning, keeps its log short, and
// serves again once the clients go.
TEST(ServeCli, RunningOutOfDescriptorsBacksOffAndRecovers) {
  const std::string data = temp_dir();
  ServeStart how;
  how.extra_args = {"--max-connections", "100000"};  // past the limit: the accept itself fails
  how.descriptor_limit = 96;
  how.stderr_to_log = true;
  Child child = start_serve(data, "a long test password", how);
  ASSERT_GT(child.pid, 0);
  std::string log;
  const int port = read_port(child.out, &log);
  ASSERT_GT(port, 0) << log;
  std::vector<std::unique_ptr<Connection>> flood;
  for (int i = 0; i < 200; ++i) {
    auto c = Connection::open(port);
    if (c) flood.push_back(std::move(c));
  }
  ASSERT_GT(flood.size(), 96u) << "the kernel queues connections the server cannot take";
  std::this_thread::sleep_for(3s);
  flood.clear();
  // Served again: the backoff is at most a second.
  int status = 0;
  for (int attempt = 0; attempt < 50 && status != 200; ++attempt) {
    status = http(port, "GET", "/api/health").status;
    if (status != 200) std::this_thread::sleep_for(200ms);
  }
  EXPECT_EQ(status, 200);
  const int exit_status = signal_and_wait(child, SIGTERM, &log);
  ASSERT_TRUE(WIFEXITED(exit_status)) << log;
  size_t accept_lines = 0;
  for (size_t at = log.find("accept:"); at != std::string::npos; at = log.find("accept:", at + 1)) ++accept_lines;
  EXPECT_GE(accept_lines, 1u) << log;
  EXPECT_LE(accept_lines, 2u) << "at most a line per 10 s: " << log.substr(0, 4000);
}

}  // namespace
}  // namespace bodyscan::testing

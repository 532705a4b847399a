// `bodyscan serve` as a shop runs it: the real binary, stopped with SIGTERM in
// the middle of a scan. It must exit cleanly and leave the scan marked
// cancelled with the reason, and the next start must find the archive whole.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <thread>
#include <utility>

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

Child start_serve(const std::string& data, const std::string& password) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    setenv("BODYSCAN_ADMIN_PASSWORD", password.c_str(), 1);
    execl(BODYSCAN_BIN, BODYSCAN_BIN, "serve", "--data", data.c_str(), "--port", "0", "--address", "127.0.0.1",
          "--every", "4", static_cast<char*>(nullptr));
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
  const HttpReply started = admin.post("/api/scans", R"({"customer": {"name": "Interrupted"}})");
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

}  // namespace
}  // namespace bodyscan::testing

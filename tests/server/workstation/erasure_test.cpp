// Erasure by the command line, beside a workstation's data: the customer's share
// links in accounts.db go with their scans, and neither database's files keep
// the erased ids.
#include <gtest/gtest.h>
#include <sodium.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "server/auth/auth_store.hpp"
#include "storage/archive/archive.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::testing {
namespace {

std::string everything_in(const std::string& dir) {
  std::string out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file()) {
      std::ifstream in(e.path(), std::ios::binary);
      out.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
  return out;
}

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

server::AuthOptions cheap() {
  server::AuthOptions o;
  o.opslimit = crypto_pwhash_OPSLIMIT_MIN;
  o.memlimit = crypto_pwhash_MEMLIMIT_MIN;
  return o;
}

TEST(ArchiveErasure, TheCommandLineErasesShareLinksToo) {
  const std::string data = temp_dir();
  std::string customer, scan, other_scan;
  {
    auto archive = storage::Archive::open(data);
    ASSERT_TRUE(archive.ok()) << archive.status().message();
    auto c = (*archive)->add_customer(std::string("Wilhelmina Erasable"), std::nullopt, "test");
    auto keep = (*archive)->add_customer(std::string("Kept Customer"), std::nullopt, "test");
    ASSERT_TRUE(c.ok() && keep.ok());
    customer = c->id;
    auto s = (*archive)->begin_scan(customer, "test", nlohmann::json::object(), "");
    auto o = (*archive)->begin_scan(keep->id, "test", nlohmann::json::object(), "");
    ASSERT_TRUE(s.ok() && o.ok());
    scan = *s;
    other_scan = *o;
    auto accounts = server::AuthStore::open(data + "/accounts.db", cheap());
    ASSERT_TRUE(accounts.ok()) << accounts.status().message();
    ASSERT_TRUE((*accounts)->create_share(scan, {"waist_girth"}, 3600, "anna").ok());
    ASSERT_TRUE((*accounts)->create_share(other_scan, {}, 3600, "anna").ok());
  }
  ASSERT_NE(everything_in(data).find(scan), std::string::npos) << "the test sees what it looks for";
  EXPECT_EQ(run(std::string(BODYSCAN_BIN) + " archive " + data + " erase " + customer + " --yes --actor admin"), 0);
  auto accounts = server::AuthStore::open(data + "/accounts.db", cheap());
  ASSERT_TRUE(accounts.ok());
  EXPECT_TRUE((*accounts)->shares(scan)->empty());
  EXPECT_EQ((*accounts)->shares(other_scan)->size(), 1u) << "other customers' links stay";
  accounts->reset();
  const std::string files = everything_in(data);
  for (const std::string& gone : {scan, customer, std::string("Wilhelmina Erasable")})
    EXPECT_EQ(files.find(gone), std::string::npos) << gone << " is still in the data folder";
  EXPECT_NE(files.find(other_scan), std::string::npos);
}

}  // namespace
}  // namespace bodyscan::testing

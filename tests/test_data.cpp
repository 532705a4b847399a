#include "tests/test_data.hpp"

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <random>
#include <vector>

namespace bodyscan::testing {

std::string data_path(const std::string& name) { return std::string(BODYSCAN_TEST_DATA_DIR) + "/" + name; }

namespace {
std::vector<std::filesystem::path>& dirs() {
  static std::vector<std::filesystem::path> d;
  return d;
}
void remove_dirs() {
  for (const auto& d : dirs()) {
    std::error_code ec;
    std::filesystem::remove_all(d, ec);
  }
}
}  // namespace

std::string temp_dir() {
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  if (dirs().empty()) std::atexit(remove_dirs);
  std::random_device rd;
  auto p = std::filesystem::temp_directory_path() /
           ("bodyscan-test-" + std::to_string(rd()) + "-" + std::to_string(dirs().size()));
  std::filesystem::create_directories(p);
  dirs().push_back(p);
  return p.string();
}

}  // namespace bodyscan::testing

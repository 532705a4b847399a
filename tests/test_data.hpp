// Where tests find their fixtures.
#pragma once

#include <string>

namespace bodyscan::testing {

// tests/data/<name> inside the repository.
std::string data_path(const std::string& name);

// A fresh empty directory under the system temp folder, removed at process exit.
std::string temp_dir();

}  // namespace bodyscan::testing

// Running the built `bodyscan` executable from tests, as a user would.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

// tests/CMakeLists.txt passes the executable's path ($<TARGET_FILE:bodyscan>).
#ifndef BODYSCAN_BIN
#define BODYSCAN_BIN BODYSCAN_SOURCE_DIR "/build-tests/app/bodyscan"
#endif

namespace bodyscan {

struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Single-quoted for /bin/sh (temp paths contain no quotes, but be safe).
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `bodyscan <args>` with stdout and stderr captured in files under `dir`,
// and `input` on its standard input (from a file of its own, empty by default:
// the test does not depend on the machine's /dev/null).
inline CliResult bodyscan(const std::string& args, const std::string& dir, const std::string& input = "") {
  const std::string out = dir + "/stdout.txt", err = dir + "/stderr.txt", in = dir + "/stdin.txt";
  std::ofstream(in, std::ios::binary | std::ios::trunc) << input;
  const std::string cmd = quote(BODYSCAN_BIN) + " " + args + " >" + quote(out) + " 2>" + quote(err) + " <" + quote(in);
  const int status = std::system(cmd.c_str());
  CliResult r;
  if (status != -1 && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace bodyscan

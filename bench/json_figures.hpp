// What a benchmark writes with --json: {"run": ..., "records": [...]}, the records
// being the benchmark's own, "run" saying where they come from (the command, the
// source tree's commit, the date, the machine). bench/tables.py renders the tables
// of docs/benchmarks.md from such files (docs/figures/), so that every figure there
// carries its provenance and cannot drift from what the benchmark printed.
#pragma once

#include <array>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

namespace bodyscan::bench {

// The output of a shell command's first line, without its newline ("" on failure).
inline std::string first_line_of(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return "";
  std::array<char, 256> buf{};
  if (!std::fgets(buf.data(), buf.size(), pipe.get())) return "";
  std::string line(buf.data());
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  return line;
}

// The run's provenance: the command, the commit of the source tree the
// benchmark runs in ("-dirty" when files outside docs/ had uncommitted changes;
// "unknown" outside a checkout), the UTC date, the processor and cores, and the
// build type where the benchmark's build says it. Take it as the run starts: the
// tree is then nearest to the one the benchmark was built from, and edits made
// while a long run goes on do not mark its figures.
inline nlohmann::json run_record(const std::string& command) {
  std::string commit = first_line_of("git -C '" BODYSCAN_SOURCE_DIR "' describe --always --abbrev=7 2>/dev/null");
  if (commit.empty()) commit = "unknown";
  // Changes to docs/ (where the figures go) do not make a run's tree dirty.
  else if (!first_line_of("git -C '" BODYSCAN_SOURCE_DIR
                          "' status --porcelain --untracked-files=no -- . ':(exclude)docs' 2>/dev/null")
                .empty())
    commit += "-dirty";
  std::array<char, 32> date{};
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(date.data(), date.size(), "%Y-%m-%d", &utc);
  std::string cpu = first_line_of("sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null");
  if (cpu.empty()) cpu = "unknown processor";
  nlohmann::json run = {{"command", command},
                        {"commit", commit},
                        {"date", date.data()},
                        {"machine", {{"cpu", cpu}, {"cores", std::thread::hardware_concurrency()}}}};
#ifdef BODYSCAN_BUILD_TYPE
  run["build"] = BODYSCAN_BUILD_TYPE;  // CMake's build type: the optimisation and whether asserts are on
#endif
  return run;
}

// The same, the command being this process's arguments (the program's path relative
// to the source tree where it lies in it).
inline nlohmann::json run_record(int argc, char** argv) {
  std::string command;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    if (i == 0 && arg.rfind(BODYSCAN_SOURCE_DIR "/", 0) == 0) arg.erase(0, std::strlen(BODYSCAN_SOURCE_DIR "/"));
    command += (i ? " " : "") + arg;
  }
  return run_record(command);
}

// Writes {"run": run, "records": records} to path (replacing it); false, with a
// message on stderr, when it cannot.
inline bool write_figures(const std::string& path, const nlohmann::json& run, const nlohmann::json& records) {
  std::ofstream out(path);
  out << nlohmann::json{{"run", run}, {"records", records}}.dump(1) << "\n";
  out.close();
  if (!out) std::fprintf(stderr, "--json: cannot write %s\n", path.c_str());
  return static_cast<bool>(out);
}

}  // namespace bodyscan::bench

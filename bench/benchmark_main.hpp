// main() for the Google Benchmark binaries, with --json as the other benchmarks have.
#pragma once

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include "bench/json_figures.hpp"

namespace bodyscan::bench {

// main() of a Google Benchmark binary that also takes --json OUT: the library's own
// JSON report, its "benchmarks" array as the records, with the run's provenance
// (json_figures.hpp).
// Runs the benchmarks as BENCHMARK_MAIN does; returns main's exit code.
inline int run_benchmarks(int argc, char** argv) {
  const nlohmann::json run = run_record(argc, argv);
  std::string json_out;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
      json_out = argv[++i];
      continue;
    }
    args.push_back(argv[i]);
  }
  const std::string report = json_out + ".benchmark";
  std::string out_flag = "--benchmark_out=" + report, format_flag = "--benchmark_out_format=json";
  if (!json_out.empty()) args.insert(args.end(), {out_flag.data(), format_flag.data()});
  int n = static_cast<int>(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (json_out.empty()) return 0;
  std::ifstream in(report);
  nlohmann::json library = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  in.close();
  std::remove(report.c_str());
  if (library.is_discarded() || !library.contains("benchmarks")) {
    std::fprintf(stderr, "--json: no report from the benchmark library in %s\n", report.c_str());
    return 1;
  }
  return write_figures(json_out, run, library["benchmarks"]) ? 0 : 1;
}

}  // namespace bodyscan::bench

// bodyscan: the command-line entry point. Each subcommand lives in its own file.
#include <cstdio>
#include <cstring>
#include <string>

#include "hw/safety.hpp"

namespace bodyscan::cli {
int run_reconstruct(int argc, char** argv);
int run_sim(int argc, char** argv);
int run_scan(int argc, char** argv);
int run_measure(int argc, char** argv);
int run_sheet(int argc, char** argv);
int run_reprocess(int argc, char** argv);
int run_archive(int argc, char** argv);
int run_serve(int argc, char** argv);
int run_devices(int argc, char** argv);
}  // namespace bodyscan::cli

namespace {
void print_usage(FILE* out) {
  std::fputs(
      "usage: bodyscan <command> [options]\n"
      "\n"
      "commands:\n"
      "  reconstruct IN.ply -o OUT.ply   points (PLY, optional normals) to a watertight mesh\n"
      "  scan --rig sim --out DIR        calibrate, scan and reconstruct on the simulated rig\n"
      "  sim render --rig RIG --out DIR  what the simulated rig's cameras see (PNG + index)\n"
      "  measure FILE.ply --girth-y Y    a girth (or --plane, --distance) as JSON\n"
      "  sheet MESH.ply -o OUT.pdf       the measurement sheet (PDF, CSV or JSON)\n"
      "  reprocess SCAN_DIR --out DIR    a scan again from its raw record\n"
      "  archive DIR list|show|verify|export|erase|reprocess|sheet ...  the scan archive\n"
      "  serve [--port 8080] [--data DIR]  the workstation: rig, archive, API and browser UI\n"
      "  devices [--json]                the cameras and controller boards this machine reaches\n"
      "\n"
      "Run 'bodyscan <command> --help' for a command's options.\n",
      out);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  const std::string cmd = argv[1];
  if (cmd == "-h" || cmd == "--help" || cmd == "help") {
    print_usage(stdout);
    return 0;
  }
  // Lasers off on a crash, and on Ctrl-C or kill in every command but `serve`, which
  // takes the stopping signals itself and stops in order.
  bodyscan::hw::install_laser_safety_handlers(cmd != "serve");
  if (cmd == "reconstruct") return bodyscan::cli::run_reconstruct(argc - 1, argv + 1);
  if (cmd == "scan") return bodyscan::cli::run_scan(argc - 1, argv + 1);
  if (cmd == "sim") return bodyscan::cli::run_sim(argc - 1, argv + 1);
  if (cmd == "measure") return bodyscan::cli::run_measure(argc - 1, argv + 1);
  if (cmd == "sheet") return bodyscan::cli::run_sheet(argc - 1, argv + 1);
  if (cmd == "reprocess") return bodyscan::cli::run_reprocess(argc - 1, argv + 1);
  if (cmd == "archive") return bodyscan::cli::run_archive(argc - 1, argv + 1);
  if (cmd == "serve") return bodyscan::cli::run_serve(argc - 1, argv + 1);
  if (cmd == "devices") return bodyscan::cli::run_devices(argc - 1, argv + 1);
  std::fprintf(stderr, "bodyscan: unknown command '%s'\n", cmd.c_str());
  print_usage(stderr);
  return 2;
}

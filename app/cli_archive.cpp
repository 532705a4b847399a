// bodyscan archive: what shop IT needs without the browser — list and search
// scans, check the archive, export or erase a customer's data, reprocess a scan,
// print its measurement sheet.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/command_line.hpp"
#include "pipeline/archive_scan.hpp"
#include "recon/io/atomic_file.hpp"
#include "recon/io/ply.hpp"
#include "server/workstation/erasure.hpp"
#include "storage/archive/archive.hpp"
#include "storage/formats/draco_files.hpp"
#include "storage/formats/export_profiles.hpp"
#include "storage/formats/measurement_sheet.hpp"
#include "storage/formats/mesh_files.hpp"

namespace bodyscan::cli {

namespace {

constexpr const char* kUsage =
    "usage: bodyscan archive DIR COMMAND [args] [--actor NAME]\n"
    "\n"
    "  list [TEXT]              scans, newest first (TEXT: part of an id, a customer's\n"
    "                           name, an operator)\n"
    "  customers [TEXT]         customers\n"
    "  show SCAN                a scan's record, versions, files and measurements (JSON)\n"
    "  verify                   repairs what a crash left (on open), then checks the\n"
    "                           database and every file against its checksum\n"
    "  export CUSTOMER DEST     everything held about a customer, into DEST\n"
    "  erase CUSTOMER --yes     deletes a customer, everything derived from them and\n"
    "                           their scans' share links\n"
    "  delete-scan SCAN --yes   deletes one scan\n"
    "  reprocess SCAN           the scan again from its raw record, as a new version\n"
    "  mesh SCAN -o OUT         the scan's surface as .ply, .obj, .stl (mm) or .glb\n"
    "  sheet SCAN -o OUT [--unit mm|cm|in] [--profile sheet|iso8559|mtm-order]\n"
    "                           the measurement sheet (.pdf, .csv or .json); a\n"
    "                           CSV laid out for its target (docs/archive.md)\n"
    "\n"
    "--actor names who does it in the audit log (default: cli).\n"
    "Exit status: 0 done, 1 failed (the message says why), 2 bad arguments.\n";

int fail(const Status& s) {
  std::fprintf(stderr, "bodyscan archive: %s\n", s.message().c_str());
  return 1;
}

nlohmann::json files_json(const std::vector<storage::ArchivedFile>& files) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& f : files) a.push_back({{"name", f.name}, {"bytes", f.bytes}, {"blake2b", f.blake2b}});
  return a;
}

}  // namespace

int run_archive(int argc, char** argv) {
  std::vector<std::string> args;
  std::string actor = "cli", out, unit_text, profile_text = "sheet";
  bool yes = false;
  CommandLine cl("bodyscan archive", kUsage);
  cl.option("--actor", &actor);
  cl.option("-o|--output", &out);
  cl.option("--unit", &unit_text);
  cl.option("--profile", &profile_text);
  cl.flag("--yes", &yes);
  cl.rest("DIR COMMAND [args]", &args);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (args.size() < 2) return cl.fail("give the archive's DIR and a COMMAND");
  const std::string cmd = args[1];
  auto need = [&](size_t n) {
    if (args.size() == n) return true;
    std::fprintf(stderr, "bodyscan archive %s: expected %zu argument(s)\n", cmd.c_str(), n - 2);
    return false;
  };
  static const std::vector<std::string> known = {"list",  "customers",   "show",      "verify", "export",
                                                 "erase", "delete-scan", "reprocess", "mesh",   "sheet"};
  if (std::find(known.begin(), known.end(), cmd) == known.end()) return cl.fail("unknown command '" + cmd + "'");
  auto opened = storage::Archive::open(args[0]);
  if (!opened.ok()) return fail(opened.status());
  storage::Archive& ar = **opened;
  const storage::RecoveryReport& rep = ar.recovery();
  for (const std::string& s : rep.scans_failed)
    std::fprintf(stderr, "bodyscan archive: scan %s was interrupted by a stop; marked failed\n", s.c_str());

  if (cmd == "list" || cmd == "customers") {
    const std::string text = args.size() > 2 ? args[2] : "";
    if (cmd == "customers") {
      auto cs = ar.customers(text);
      if (!cs.ok()) return fail(cs.status());
      for (const auto& c : *cs)
        std::printf("%s  %s  %s  %s\n", c.id.c_str(), c.created_at.c_str(), c.name.value_or("-").c_str(),
                    c.contact.value_or("-").c_str());
      return 0;
    }
    storage::ScanQuery q;
    q.text = text;
    auto scans = ar.scans(q);
    if (!scans.ok()) return fail(scans.status());
    for (const auto& r : *scans)
      std::printf("%s  %-9s  %s  customer %s  operator %s  version %d%s%s\n", r.id.c_str(), to_string(r.status),
                  r.started_at.c_str(), r.customer_id.c_str(), r.operator_name.c_str(), r.current_version,
                  r.status_reason.empty() ? "" : "  ", r.status_reason.c_str());
    return 0;
  }
  if (cmd == "show") {
    if (!need(3)) return 2;
    auto r = ar.scan(args[2]);
    if (!r.ok()) return fail(r.status());
    nlohmann::json j = {{"id", r->id},
                        {"customer", r->customer_id},
                        {"operator", r->operator_name},
                        {"calibration", r->calibration_id},
                        {"rig", r->rig},
                        {"status", to_string(r->status)},
                        {"status_reason", r->status_reason},
                        {"started_at", r->started_at},
                        {"finished_at", r->finished_at},
                        {"current_version", r->current_version},
                        {"raw", files_json(r->raw)},
                        {"versions", nlohmann::json::array()},
                        {"measurements", nlohmann::json::array()}};
    for (const auto& v : r->versions)
      j["versions"].push_back({{"version", v.version},
                               {"created_at", v.created_at},
                               {"algorithms", v.algorithms},
                               {"note", v.note},
                               {"files", files_json(v.files)}});
    if (r->status == storage::ScanStatus::kComplete) {
      auto ms = ar.measurements(r->id);
      if (!ms.ok()) return fail(ms.status());
      for (const auto& m : *ms)
        j["measurements"].push_back({{"id", m.id},
                                     {"source", m.source},
                                     {"name", m.name},
                                     {"iso_clause", m.iso_clause},
                                     {"value_mm", m.value_mm},
                                     {"version", m.version}});
    }
    std::printf("%s\n", j.dump(1).c_str());
    return 0;
  }
  if (cmd == "verify") {
    if (!need(2)) return 2;
    std::printf(
        "recovered on open: %zu interrupted scan(s) marked failed, %zu stray version(s), %zu orphan folder(s), "
        "%zu temporary file(s) removed\n",
        rep.scans_failed.size(), rep.versions_removed, rep.orphans_removed, rep.temp_files_removed);
    const Status v = ar.verify();
    if (!v.ok()) return fail(v);
    std::printf("archive %s: consistent, every file matches its checksum\n", ar.dir().c_str());
    return 0;
  }
  if (cmd == "export") {
    if (!need(4)) return 2;
    const Status s = ar.export_customer(args[2], args[3], actor);
    if (!s.ok()) return fail(s);
    std::printf("exported customer %s to %s\n", args[2].c_str(), args[3].c_str());
    return 0;
  }
  if (cmd == "erase" || cmd == "delete-scan") {
    if (!need(3)) return 2;
    if (!yes) {
      std::fprintf(stderr, "bodyscan archive %s: this cannot be undone; add --yes\n", cmd.c_str());
      return 2;
    }
    // The workstation keeps its share links beside the archive; they go too.
    std::unique_ptr<server::AuthStore> accounts;
    const std::string accounts_path = args[0] + "/accounts.db";
    if (std::filesystem::exists(accounts_path)) {
      auto opened_accounts = server::AuthStore::open(accounts_path);
      if (!opened_accounts.ok()) return fail(opened_accounts.status());
      accounts = std::move(*opened_accounts);
    }
    const Status s = cmd == "erase" ? server::erase_customer(ar, accounts.get(), args[2], actor)
                                    : server::erase_scan(ar, accounts.get(), args[2], actor);
    if (!s.ok()) return fail(s);
    std::printf("%s %s\n", cmd == "erase" ? "erased customer" : "deleted scan", args[2].c_str());
    return 0;
  }
  if (cmd == "reprocess") {
    if (!need(3)) return 2;
    auto v = pipeline::reprocess_archived_scan(ar, args[2], {}, actor);
    if (!v.ok()) return fail(v.status());
    std::printf("scan %s: version %d\n", args[2].c_str(), *v);
    return 0;
  }
  auto ends = [&](const char* suffix) {
    return out.size() >= std::strlen(suffix) &&
           out.compare(out.size() - std::strlen(suffix), std::string::npos, suffix) == 0;
  };
  auto surface = [&](const std::string& scan) { return pipeline::archived_surface(ar, scan); };
  if (cmd == "mesh") {
    if (!need(3)) return 2;
    if (!ends(".ply") && !ends(".obj") && !ends(".stl") && !ends(".glb")) {
      std::fprintf(stderr, "bodyscan archive mesh: -o OUT must end in .ply, .obj, .stl or .glb\n");
      return 2;
    }
    auto mesh = surface(args[2]);
    if (!mesh.ok()) return fail(mesh.status());
    Status w;
    if (ends(".ply"))
      w = write_ply(out, *mesh);
    else if (ends(".obj"))
      w = storage::write_obj(out, *mesh);
    else if (ends(".stl"))
      w = storage::write_stl(out, *mesh);
    else
      w = storage::write_glb(out, *mesh).status();
    if (!w.ok()) return fail(w);
    ar.log(actor, "export mesh", "scan", args[2], out);
    std::printf("wrote %s: %zu triangles\n", out.c_str(), mesh->num_triangles());
    return 0;
  }
  // sheet
  if (!need(3)) return 2;
  auto profile = storage::find_export_profile(profile_text);
  if (!profile.ok()) {
    std::fprintf(stderr, "bodyscan archive: %s\n", profile.status().message().c_str());
    return 2;
  }
  if (profile->id != "sheet" && !ends(".csv")) {
    std::fprintf(stderr, "bodyscan archive sheet: --profile lays out a CSV (OUT.csv)\n");
    return 2;
  }
  // The tailor's sheet in cm unless asked; another profile in its target's unit.
  auto unit = storage::parse_length_unit(!unit_text.empty()       ? unit_text
                                         : profile->id == "sheet" ? "cm"
                                                                  : storage::unit_symbol(profile->default_unit));
  if (!unit.ok()) {
    std::fprintf(stderr, "bodyscan archive: %s\n", unit.status().message().c_str());
    return 2;
  }
  if (out.empty()) {
    std::fprintf(stderr, "bodyscan archive sheet: -o OUT.pdf|.csv|.json is required\n");
    return 2;
  }
  auto sheet = pipeline::archived_sheet(ar, args[2]);
  if (!sheet.ok()) return fail(sheet.status());
  std::string bytes;
  if (ends(".csv")) {
    bytes = storage::profile_csv(*sheet, *profile, *unit);
  } else if (ends(".json")) {
    bytes = storage::sheet_json(*sheet, *unit).dump(1);
  } else if (ends(".pdf")) {
    TriangleMesh mesh;
    auto m = surface(args[2]);
    if (m.ok()) mesh = std::move(*m);
    auto pdf = storage::sheet_pdf(*sheet, mesh, *unit);
    if (!pdf.ok()) return fail(pdf.status());
    bytes = std::move(*pdf);
  } else {
    std::fprintf(stderr, "bodyscan archive sheet: OUT must end in .pdf, .csv or .json\n");
    return 2;
  }
  const Status w = write_file_atomically(out, bytes);
  if (!w.ok()) return fail(w);
  std::printf("wrote %s: %zu measurements\n", out.c_str(), sheet->entries.size());
  return 0;
}

}  // namespace bodyscan::cli

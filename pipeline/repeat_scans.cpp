#include "pipeline/repeat_scans.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>

#include "recon/measure/body_measurements.hpp"

namespace bodyscan::pipeline {

double repeat_tolerance_mm(const storage::MeasurementRecord& m, double shop_mm) {
  if (shop_mm > 0) return shop_mm;
  BodyMeasurement b;
  b.name = m.name, b.kind = m.kind;
  return iso20685_allowance_mm(b);
}

namespace {

// "2026-11-29T10:15:00Z" or "2026-11-29T10:15:00.123Z" (the archive's) as unix
// seconds; nullopt if it is neither form.
std::optional<std::time_t> parse_utc(std::string_view iso) {
  std::tm t{};
  int used = 0;
  const std::string text(iso);
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%n", &t.tm_year, &t.tm_mon, &t.tm_mday, &t.tm_hour, &t.tm_min,
                  &t.tm_sec, &used) != 6)
    return std::nullopt;
  std::string_view rest = iso.substr(static_cast<size_t>(used));
  if (!rest.empty() && rest.front() == '.') {
    rest.remove_prefix(1);
    while (!rest.empty() && rest.front() >= '0' && rest.front() <= '9') rest.remove_prefix(1);
  }
  if (rest != "Z") return std::nullopt;
  t.tm_year -= 1900;
  t.tm_mon -= 1;
  return timegm(&t);
}

}  // namespace

bool same_local_day(std::string_view a_iso, std::string_view b_iso) {
  const auto a = parse_utc(a_iso), b = parse_utc(b_iso);
  if (!a || !b) return false;
  std::tm la{}, lb{};
  localtime_r(&*a, &la);
  localtime_r(&*b, &lb);
  return la.tm_year == lb.tm_year && la.tm_yday == lb.tm_yday;
}

StatusOr<std::optional<RepeatCheck>> check_repeat(const storage::Archive& archive, const std::string& scan_id,
                                                  double shop_mm) {
  ASSIGN_OR_RETURN(const storage::ScanRecord scan, archive.scan(scan_id));
  storage::ScanQuery q;
  q.customer_id = scan.customer_id;
  ASSIGN_OR_RETURN(const std::vector<storage::ScanRecord> scans, archive.scans(q));
  // Newest first: the first complete one that started before this one.
  const storage::ScanRecord* earlier = nullptr;
  for (const storage::ScanRecord& s : scans)
    if (s.id != scan_id && s.status == storage::ScanStatus::kComplete && s.current_version > 0 &&
        s.started_at <= scan.started_at) {
      earlier = &s;
      break;
    }
  if (!earlier || !same_local_day(earlier->started_at, scan.started_at)) return std::optional<RepeatCheck>();
  ASSIGN_OR_RETURN(const std::vector<storage::MeasurementRecord> now, archive.measurements(scan_id));
  ASSIGN_OR_RETURN(const std::vector<storage::MeasurementRecord> before, archive.measurements(earlier->id));
  std::map<std::string, const storage::MeasurementRecord*> by_name;
  for (const storage::MeasurementRecord& m : before)
    if (m.source == "automatic") by_name[m.name] = &m;
  RepeatCheck check;
  check.earlier_scan = earlier->id;
  check.earlier_started_at = earlier->started_at;
  for (const storage::MeasurementRecord& m : now) {
    if (m.source != "automatic") continue;
    const auto other = by_name.find(m.name);
    if (other == by_name.end()) continue;
    ++check.compared;
    RepeatDifference d{m.name, m.label, m.kind, m.value_mm, other->second->value_mm, repeat_tolerance_mm(m, shop_mm)};
    if (std::abs(d.difference()) > d.tolerance_mm) check.beyond.push_back(std::move(d));
  }
  return std::optional<RepeatCheck>(std::move(check));
}

}  // namespace bodyscan::pipeline

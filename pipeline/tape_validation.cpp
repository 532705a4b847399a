#include "pipeline/tape_validation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/student_t.hpp"
#include "recon/measure/body_measurements.hpp"

namespace bodyscan::pipeline {

namespace {

// The half width of the 95 % interval of a mean of n values with standard deviation sd.
double half_width(size_t n, double sd) {
  return student_t_quantile(0.975, static_cast<double>(n - 1)) * sd / std::sqrt(static_cast<double>(n));
}

}  // namespace

DifferenceStats difference_stats(const std::vector<double>& d) {
  DifferenceStats s;
  s.n = d.size();
  if (d.empty()) return s;
  double sum = 0;
  for (double x : d) sum += x;
  s.mean = sum / static_cast<double>(s.n);
  s.ci_low = s.ci_high = s.mean;
  if (s.n < 2) return s;
  double squares = 0;
  for (double x : d) squares += (x - s.mean) * (x - s.mean);
  s.sd = std::sqrt(squares / static_cast<double>(s.n - 1));
  const double h = half_width(s.n, s.sd);
  s.ci_low = s.mean - h;
  s.ci_high = s.mean + h;
  return s;
}

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::kTooFew: return "too_few";
    case Verdict::kWithin: return "within";
    case Verdict::kMoreSubjects: return "more_subjects";
    case Verdict::kOutsideAllowance: return "outside";
  }
  return "?";
}

Judgement judge(const DifferenceStats& s, double allowance_mm) {
  if (s.n < 2) return {Verdict::kTooFew, 2 - s.n};
  if (s.ci_low >= -allowance_mm && s.ci_high <= allowance_mm) return {Verdict::kWithin, 0};
  const double margin = allowance_mm - std::abs(s.mean);
  if (!(margin > 0)) return {Verdict::kOutsideAllowance, 0};
  // |mean| + half_width(N) <= allowance: the half width falls with N, so double
  // N past the answer, then bisect.
  auto fits = [&](size_t n) { return half_width(n, s.sd) <= margin; };
  size_t hi = s.n + 1;
  while (!fits(hi)) hi *= 2;
  size_t lo = std::max(s.n, hi / 2);  // does not fit
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    (fits(mid) ? hi : lo) = mid;
  }
  return {Verdict::kMoreSubjects, hi - s.n};
}

StatusOr<ValidationReport> validate_against_tape(const storage::Archive& archive) {
  ASSIGN_OR_RETURN(const std::vector<storage::TapeMeasurement> tape, archive.tape_measurements());
  // Per customer and measurement, the tape value of the newest scan.
  struct Chosen {
    const storage::TapeMeasurement* tape = nullptr;
    std::string started_at;
  };
  std::map<std::string, storage::ScanRecord> scans;
  std::map<std::pair<std::string, std::string>, Chosen> chosen;
  for (const storage::TapeMeasurement& t : tape) {
    auto it = scans.find(t.scan_id);
    if (it == scans.end()) {
      ASSIGN_OR_RETURN(storage::ScanRecord r, archive.scan(t.scan_id));
      it = scans.emplace(t.scan_id, std::move(r)).first;
    }
    Chosen& c = chosen[{t.customer_id, t.name}];
    if (!c.tape || it->second.started_at > c.started_at) c = {&t, it->second.started_at};
  }
  // The scans' current automatic values, by scan and name.
  std::map<std::string, std::vector<storage::MeasurementRecord>> values;
  for (const auto& [id, record] : scans) {
    ASSIGN_OR_RETURN(std::vector<storage::MeasurementRecord> ms, archive.measurements(id));
    values[id] = std::move(ms);
  }
  struct Gathered {
    const storage::MeasurementRecord* first = nullptr;  // label, kind and clause
    size_t order = 0;                                   // index in its scan's automatic set
    std::vector<double> differences;
    std::set<std::string> measured_by;
  };
  std::map<std::string, Gathered> by_name;
  std::set<std::string> customers;
  ValidationReport report;
  for (const auto& [key, c] : chosen) {
    const std::vector<storage::MeasurementRecord>& ms = values[c.tape->scan_id];
    const std::string& name = c.tape->name;  // a lambda may not capture a structured binding
    const auto m = std::find_if(ms.begin(), ms.end(), [&name](const storage::MeasurementRecord& r) {
      return r.source == "automatic" && r.name == name;
    });
    if (m == ms.end()) continue;  // a reprocessed scan without that measurement
    Gathered& g = by_name[c.tape->name];
    if (!g.first) g.first = &*m, g.order = static_cast<size_t>(m - ms.begin());
    g.differences.push_back(m->value_mm - c.tape->value_mm);
    g.measured_by.insert(c.tape->measured_by);
    customers.insert(key.first);
    ++report.tape_values;
  }
  report.customers = customers.size();
  for (auto& [name, g] : by_name) {
    MeasurementValidation v;
    v.name = name, v.label = g.first->label, v.kind = g.first->kind, v.iso_clause = g.first->iso_clause;
    BodyMeasurement b;
    b.name = name, b.kind = g.first->kind;
    v.allowance_mm = iso20685_allowance_mm(b);
    v.stats = difference_stats(g.differences);
    v.judgement = judge(v.stats, v.allowance_mm);
    v.measured_by.assign(g.measured_by.begin(), g.measured_by.end());
    report.measurements.push_back(std::move(v));
  }
  std::stable_sort(report.measurements.begin(), report.measurements.end(),
                   [&](const MeasurementValidation& a, const MeasurementValidation& b) {
                     return by_name[a.name].order < by_name[b.name].order;
                   });
  return report;
}

nlohmann::json to_json(const ValidationReport& report) {
  nlohmann::json rows = nlohmann::json::array();
  for (const MeasurementValidation& v : report.measurements) {
    const bool interval = v.stats.n >= 2;
    rows.push_back({{"name", v.name},
                    {"label", v.label},
                    {"kind", v.kind},
                    {"iso_clause", v.iso_clause},
                    {"allowance_mm", v.allowance_mm},
                    {"subjects", v.stats.n},
                    {"mean_difference_mm", v.stats.mean},
                    {"sd_mm", interval ? nlohmann::json(v.stats.sd) : nlohmann::json()},
                    {"ci_low_mm", interval ? nlohmann::json(v.stats.ci_low) : nlohmann::json()},
                    {"ci_high_mm", interval ? nlohmann::json(v.stats.ci_high) : nlohmann::json()},
                    {"verdict", to_string(v.judgement.verdict)},
                    {"more_subjects", v.judgement.more_subjects},
                    {"measured_by", v.measured_by}});
  }
  return {{"customers", report.customers},
          {"tape_values", report.tape_values},
          {"confidence", 0.95},
          {"measurements", rows}};
}

}  // namespace bodyscan::pipeline

#include "storage/formats/measurement_sheet.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "recon/io/ply.hpp"
#include "storage/formats/export_profiles.hpp"
#include "tests/storage/pdf_text.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::storage {
namespace {

struct Fixture {
  TriangleMesh mesh;
  MeasurementSheet sheet;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    auto mesh = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
    EXPECT_TRUE(mesh.ok());
    x.mesh = *mesh;
    auto body = measure_body(x.mesh);
    EXPECT_TRUE(body.ok());
    x.sheet.customer_ref = "C-0042";
    x.sheet.scan_id = "s-20261122-001";
    x.sheet.taken_at = "2026-11-22T10:15:00Z";
    x.sheet.operator_name = "Ana";
    x.sheet.entries = sheet_entries(*body);
    return x;
  }();
  return f;
}

// RFC 4180 rows (quoted fields may hold commas, quotes and line breaks).
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1);
  std::string field;
  bool quoted = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"')
        field += '"', ++i;
      else if (c == '"')
        quoted = false;
      else
        field += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      rows.back().push_back(field), field.clear();
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      rows.back().push_back(field), field.clear(), rows.emplace_back(), ++i;
    } else {
      field += c;
    }
  }
  if (rows.back().empty()) rows.pop_back();
  return rows;
}

SheetEntry saved(const std::string& name, const std::string& label, double mm) {
  SheetEntry e;
  e.name = name, e.label = label, e.kind = "girth", e.value_mm = mm, e.source = "saved by Ana";
  return e;
}

TEST(MeasurementSheet, UnitsConvertAndRound) {
  EXPECT_EQ(format_length(812.345, LengthUnit::kMillimetre), "812.3");
  EXPECT_EQ(format_length(812.345, LengthUnit::kCentimetre), "81.23");
  EXPECT_EQ(format_length(254.0, LengthUnit::kInch), "10.00");
  EXPECT_EQ(*parse_length_unit("inch"), LengthUnit::kInch);
  EXPECT_EQ(*parse_length_unit("cm"), LengthUnit::kCentimetre);
  EXPECT_FALSE(parse_length_unit("furlong").ok());
}

TEST(MeasurementSheet, CsvHasOneRowPerMeasurementKeyedByClauseAndName) {
  const Fixture& f = fixture();
  const auto rows = parse_csv(sheet_csv(f.sheet, LengthUnit::kCentimetre));
  ASSERT_EQ(rows.size(), f.sheet.entries.size() + 1);
  EXPECT_EQ(rows[0][0], "iso_clause");
  EXPECT_EQ(rows[0][1], "name");
  for (size_t i = 0; i < f.sheet.entries.size(); ++i) {
    const SheetEntry& e = f.sheet.entries[i];
    ASSERT_EQ(rows[i + 1].size(), 10u);
    EXPECT_EQ(rows[i + 1][0], e.iso_clause);
    EXPECT_EQ(rows[i + 1][1], e.name);
    EXPECT_NEAR(std::stod(rows[i + 1][3]), e.value_mm / 10, 0.005 + 1e-9);
    EXPECT_EQ(rows[i + 1][4], "cm");
    EXPECT_EQ(rows[i + 1][7], "C-0042");
  }
}

TEST(ExportProfiles, TheIsoProfileKeysEveryClausedValueByClauseAndSide) {
  const Fixture& f = fixture();
  auto iso = find_export_profile("iso8559");
  ASSERT_TRUE(iso.ok());
  const auto rows = parse_csv(profile_csv(f.sheet, *iso));
  ASSERT_GE(rows.size(), 2u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"iso_clause", "side", "measurement", "value", "unit", "flagged"}));
  size_t claused = 0;
  std::set<std::pair<std::string, std::string>> keys;
  for (const SheetEntry& e : f.sheet.entries) claused += e.iso_clause.empty() ? 0 : 1;
  ASSERT_EQ(rows.size(), claused + 1) << "a row per measurement with a clause, none without";
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_TRUE(keys.insert({rows[i][0], rows[i][1]}).second) << "clause and side are a key: " << rows[i][0];
    EXPECT_EQ(rows[i][4], "mm");
    const std::string name = rows[i][2] + (rows[i][1].empty() ? "" : "_" + rows[i][1]);
    bool found = false;
    for (const SheetEntry& e : f.sheet.entries)
      if (e.name == name) {
        found = true;
        EXPECT_EQ(e.iso_clause, rows[i][0]);
        EXPECT_NEAR(std::stod(rows[i][3]), e.value_mm, 0.05 + 1e-9);
      }
    EXPECT_TRUE(found) << name;
  }
  EXPECT_EQ(parse_csv(profile_csv(f.sheet, *iso, LengthUnit::kInch))[1][4], "in");
}

TEST(ExportProfiles, TheOrderIsOneRowUnderTheFormsNamesInCentimetres) {
  const Fixture& f = fixture();
  auto order = find_export_profile("mtm-order");
  ASSERT_TRUE(order.ok());
  const auto rows = parse_csv(profile_csv(f.sheet, *order));
  ASSERT_EQ(rows.size(), 2u);
  ASSERT_EQ(rows[0].size(), rows[1].size());
  ASSERT_EQ(rows[0].size(), 4 + mtm_order_columns().size());
  EXPECT_EQ(rows[1][0], "C-0042");
  EXPECT_EQ(rows[1][2], "2026-11-22");
  EXPECT_EQ(rows[1][3], "cm");
  for (size_t c = 0; c < mtm_order_columns().size(); ++c) {
    EXPECT_EQ(rows[0][4 + c], mtm_order_columns()[c].column);
    const SheetEntry* e = nullptr;
    for (const SheetEntry& x : f.sheet.entries)
      if (x.name == mtm_order_columns()[c].measurement) e = &x;
    ASSERT_NE(e, nullptr) << "every column maps to a measurement of the automatic set: "
                          << mtm_order_columns()[c].measurement;
    EXPECT_NEAR(std::stod(rows[1][4 + c]), e->value_mm / 10, 0.005 + 1e-9) << rows[0][4 + c];
  }
  // A sheet without a measurement leaves its cell empty.
  MeasurementSheet partial = f.sheet;
  partial.entries.erase(partial.entries.begin());
  const auto short_rows = parse_csv(profile_csv(partial, *order));
  EXPECT_EQ(short_rows[1][4], "") << "height, from the missing stature";
  EXPECT_FALSE(find_export_profile("excel").ok());
  EXPECT_EQ(profile_csv(f.sheet, *find_export_profile("sheet"), LengthUnit::kCentimetre),
            sheet_csv(f.sheet, LengthUnit::kCentimetre));
}

TEST(MeasurementSheet, CsvQuotesAndDefusesWhatPeopleType) {
  MeasurementSheet s;
  s.customer_ref = "=HYPERLINK(\"http://evil\")";
  s.entries.push_back(saved("user_1", "Sleeve, \"left\"\nto cuff", 612.0));
  const auto rows = parse_csv(sheet_csv(s, LengthUnit::kMillimetre));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1][2], "Sleeve, \"left\"\nto cuff");
  EXPECT_EQ(rows[1][7], "'=HYPERLINK(\"http://evil\")");  // never a live formula
}

TEST(MeasurementSheet, JsonCarriesTheSameValues) {
  const Fixture& f = fixture();
  const nlohmann::json j = sheet_json(f.sheet, LengthUnit::kInch);
  EXPECT_EQ(j["schema"], "bodyscan.sheet/1");
  EXPECT_EQ(j["unit"], "in");
  ASSERT_EQ(j["measurements"].size(), f.sheet.entries.size());
  for (size_t i = 0; i < f.sheet.entries.size(); ++i)
    EXPECT_NEAR(j["measurements"][i]["value"].get<double>(), f.sheet.entries[i].value_mm / 25.4, 0.005 + 1e-9);
  EXPECT_EQ(j["by_clause"]["5.3.10"], "waist_girth");
  EXPECT_EQ(j["by_clause"]["5.1.1"], "stature");
}

std::string pdf_text(const std::string& pdf) { return testing::pdf_text(pdf, true); }

TEST(MeasurementSheet, PdfShowsTheCustomerTheTableAndTheSilhouettes) {
  const Fixture& f = fixture();
  auto pdf = sheet_pdf(f.sheet, f.mesh, LengthUnit::kCentimetre);
  ASSERT_TRUE(pdf.ok()) << pdf.status().message();
  ASSERT_EQ(pdf->rfind("%PDF-", 0), 0u);
  const std::string text = pdf_text(*pdf);
  EXPECT_NE(text.find("C-0042"), std::string::npos) << text;
  EXPECT_NE(text.find("2026-11-22"), std::string::npos);
  for (const SheetEntry& e : f.sheet.entries) {
    EXPECT_NE(text.find(e.label), std::string::npos) << e.label;
    EXPECT_NE(text.find(format_length(e.value_mm, LengthUnit::kCentimetre)), std::string::npos) << e.label;
  }
  // One page, and the silhouettes are images on it: a sheet without the mesh is smaller.
  auto bare = sheet_pdf(f.sheet, TriangleMesh{}, LengthUnit::kCentimetre);
  ASSERT_TRUE(bare.ok());
  EXPECT_GT(pdf->size(), bare->size() + 5000);
  EXPECT_EQ(text.find("page 2"), std::string::npos);
}

TEST(MeasurementSheet, ALongListRunsOnToMorePages) {
  const Fixture& f = fixture();
  MeasurementSheet s = f.sheet;
  for (int i = 0; i < 60; ++i)
    s.entries.push_back(saved("user_" + std::to_string(i), "Saved line " + std::to_string(i), 500.0 + i));
  auto pdf = sheet_pdf(s, f.mesh, LengthUnit::kMillimetre);
  ASSERT_TRUE(pdf.ok());
  const std::string text = pdf_text(*pdf);
  EXPECT_NE(text.find("page 2"), std::string::npos);
  EXPECT_NE(text.find("Saved line 59"), std::string::npos);
  EXPECT_NE(text.find("559.0"), std::string::npos);
}

}  // namespace
}  // namespace bodyscan::storage

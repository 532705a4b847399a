#include "storage/formats/customer_sheet.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "recon/io/ply.hpp"
#include "recon/io/png_image.hpp"
#include "tests/storage/pdf_text.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::storage {
namespace {

struct Fixture {
  TriangleMesh mesh;
  std::vector<SheetEntry> entries;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    auto mesh = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
    EXPECT_TRUE(mesh.ok());
    x.mesh = *mesh;
    auto body = measure_body(x.mesh);
    EXPECT_TRUE(body.ok());
    x.entries = sheet_entries(*body);
    return x;
  }();
  return f;
}

using testing::pdf_text;

const SheetEntry& entry(const std::vector<SheetEntry>& entries, const std::string& name) {
  for (const SheetEntry& e : entries)
    if (e.name == name) return e;
  ADD_FAILURE() << "no " << name;
  return entries.front();
}

// A 2 x 1 grey PNG, as a shop's logo.
std::string tiny_png() {
  GrayImage image;
  image.width = 2, image.height = 1;
  image.pixels = {40, 200};
  auto png = encode_png(image);
  EXPECT_TRUE(png.ok());
  return *png;
}

TEST(CustomerSheet, PlainWordsTheCustomersNameAndTheShopInEnglish) {
  const Fixture& f = fixture();
  CustomerSheet s;
  s.customer_name = "Zora Quintrell";
  s.taken_at = "2026-11-29T10:15:00Z";
  s.shop_name = "Schneiderei Lindner";
  s.shop_logo_png = tiny_png();
  s.link_url = "https://scanner.shop.example/s/abcdefghijklmnopqrstuvwxyz0123456789ABCDEFG";
  s.link_expires = "2026-12-06T10:15:00Z";
  for (const char* name : {"chest_girth", "waist_girth", "hip_girth", "thigh_girth_left", "crotch_height"})
    s.entries.push_back(entry(f.entries, name));
  s.entries[1].flagged = true;
  auto pdf = customer_sheet_pdf(s, f.mesh, LengthUnit::kCentimetre);
  ASSERT_TRUE(pdf.ok()) << pdf.status().message();
  const std::string text = pdf_text(*pdf);
  for (const char* want : {"Your body measurements", "Zora Quintrell", "Scanned on 29 November 2026",
                           "Schneiderei Lindner", "Chest", "Waist *", "Hips", "Thigh (left)", "Inside leg",
                           "* Estimated", "Your 3-D model: scan with your phone", "Link valid until 6 December 2026"})
    EXPECT_NE(text.find(want), std::string::npos) << want << "\n" << text;
  // The values in cm with one decimal, as the entries hold them.
  char waist[32];
  std::snprintf(waist, sizeof waist, "%.1f cm", s.entries[1].value_mm / 10);
  EXPECT_NE(text.find(waist), std::string::npos) << waist << "\n" << text;
  // No ISO clause numbers or snake_case ids: those are the tailor's.
  EXPECT_EQ(text.find("5.3."), std::string::npos) << text;
  EXPECT_EQ(text.find("girth"), std::string::npos) << text;
}

TEST(CustomerSheet, GermanWordsDatesAndDecimalCommas) {
  const Fixture& f = fixture();
  CustomerSheet s;
  s.customer_name = "Jürgen Maß";
  s.taken_at = "2026-03-05T08:00:00Z";
  s.locale = Locale::kGerman;
  s.link_url = "https://scanner.shop.example/s/token";
  s.link_expires = "2026-03-12T08:00:00Z";
  for (const char* name : {"waist_girth", "outer_arm_length_right"}) s.entries.push_back(entry(f.entries, name));
  s.entries[0].flagged = true;
  auto pdf = customer_sheet_pdf(s, f.mesh, LengthUnit::kCentimetre);
  ASSERT_TRUE(pdf.ok()) << pdf.status().message();
  const std::string text = pdf_text(*pdf);
  for (const char* want : {"Ihre Körpermaße", "Jürgen Maß", "Gescannt am 5. März 2026", "Taillenumfang *",
                           "Armlänge (rechts)", "* Geschätzt", "Link gültig bis 12. März 2026"})
    EXPECT_NE(text.find(want), std::string::npos) << want << "\n" << text;
  std::string waist = format_number(s.entries[0].value_mm / 10, 1, Locale::kGerman) + " cm";
  EXPECT_NE(waist.find(','), std::string::npos);
  EXPECT_NE(text.find(waist), std::string::npos) << waist << "\n" << text;
}

TEST(CustomerSheet, NothingChosenSaysSoAndStaffMeasurementsKeepTheirLabel) {
  CustomerSheet s;
  s.taken_at = "2026-11-29";
  auto empty = customer_sheet_pdf(s, TriangleMesh(), LengthUnit::kMillimetre);
  ASSERT_TRUE(empty.ok());
  EXPECT_NE(pdf_text(*empty).find("No measurements were chosen"), std::string::npos);
  SheetEntry own;
  own.name = "user_7";
  own.label = "Sleeve to cuff";
  own.value_mm = 612.4;
  s.entries = {own};
  auto pdf = customer_sheet_pdf(s, TriangleMesh(), LengthUnit::kMillimetre);
  ASSERT_TRUE(pdf.ok());
  const std::string text = pdf_text(*pdf);
  EXPECT_NE(text.find("Sleeve to cuff"), std::string::npos) << text;
  EXPECT_NE(text.find("612 mm"), std::string::npos) << text;
}

TEST(CustomerSheet, ABadLogoOrALinkTooLongForAQrCodeIsAnError) {
  CustomerSheet s;
  s.shop_logo_png = "not a png";
  auto bad_logo = customer_sheet_pdf(s, TriangleMesh(), LengthUnit::kCentimetre);
  ASSERT_FALSE(bad_logo.ok());
  EXPECT_NE(bad_logo.status().message().find("logo"), std::string::npos);
  s.shop_logo_png.clear();
  s.link_url = std::string(4000, 'x');  // past a version-40 code's 2,331 bytes at level M
  auto too_long = customer_sheet_pdf(s, TriangleMesh(), LengthUnit::kCentimetre);
  ASSERT_FALSE(too_long.ok());
  EXPECT_NE(too_long.status().message().find("QR"), std::string::npos);
}

TEST(CustomerSheet, LocalesAndLabels) {
  EXPECT_EQ(*parse_locale("de-AT"), Locale::kGerman);
  EXPECT_EQ(*parse_locale("en"), Locale::kEnglish);
  EXPECT_FALSE(parse_locale("fr").ok());
  EXPECT_EQ(plain_label("calf_girth_left", Locale::kGerman), "Wadenumfang (links)");
  EXPECT_EQ(plain_label("user_3", Locale::kEnglish), "");
  EXPECT_EQ(format_number(1234.56, 1, Locale::kGerman), "1234,6");
  EXPECT_EQ(format_date("not a date", Locale::kEnglish), "not a date");
  // Every automatic measurement has a plain name in both languages.
  for (const SheetEntry& e : fixture().entries) {
    EXPECT_NE(plain_label(e.name, Locale::kEnglish), "") << e.name;
    EXPECT_NE(plain_label(e.name, Locale::kGerman), "") << e.name;
  }
}

}  // namespace
}  // namespace bodyscan::storage

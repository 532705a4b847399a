// The sheet a customer takes home: one A4 page for the shop's printer with their
// name, the date in the shop's language, the measurements staff chose under plain
// names ("Chest", "Waist"; no ISO clauses), the silhouette with the lines, the
// shop's name and logo, and the share link as a QR code. The tailor's sheet is
// measurement_sheet.hpp.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::storage {

// The languages the customer's side is shipped in.
enum class Locale { kEnglish, kGerman };

// "en" or "de" (a region, "de-AT", is accepted and ignored).
StatusOr<Locale> parse_locale(std::string_view text);
const char* locale_tag(Locale locale);  // "en", "de"

// The measurement's plain name in `locale` ("Chest", "Brust"), or "" when the
// automatic set has no such name (a measurement staff took: its own label is used).
std::string plain_label(std::string_view name, Locale locale);

// `value` with `decimals` digits after the locale's decimal mark (a comma in German).
std::string format_number(double value, int decimals, Locale locale);
// An ISO 8601 date or date-time ("2026-11-29T10:15:00Z") as the locale writes a
// day: "29 November 2026", "29. November 2026"; the text itself if it is no date.
std::string format_date(std::string_view iso, Locale locale);

struct CustomerSheet {
  std::string customer_name;  // "" prints no name
  std::string taken_at;       // ISO 8601
  std::string shop_name;      // "" prints none
  std::string shop_logo_png;  // PNG bytes; "" prints none
  std::string link_url;       // the share link, printed as a QR code; "" prints none
  std::string link_expires;   // ISO 8601; printed under the code
  Locale locale = Locale::kEnglish;
  std::vector<SheetEntry> entries;  // label: the plain name, else the entry's own
};

// One A4 page. `mesh` gives the silhouette (an empty mesh leaves it out). An error
// if the logo is not a PNG or the link does not fit a QR code.
StatusOr<std::string> customer_sheet_pdf(const CustomerSheet& sheet, const TriangleMesh& mesh, LengthUnit unit);

}  // namespace bodyscan::storage

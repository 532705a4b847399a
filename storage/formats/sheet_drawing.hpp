// Drawing on a sheet's PDF page with Cairo: text, the body's silhouettes with the
// measured lines, a PNG (a shop's logo) and a QR code. Shared by the tailor's sheet
// (measurement_sheet) and the customer's (customer_sheet).
#pragma once

#include <cairo.h>

#include <string>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::storage::drawing {

constexpr double kPageW = 595.276, kPageH = 841.89, kMargin = 40;  // A4 in points

// A cairo write function that appends the PDF to the std::string `closure`.
cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length);

// Ends a PDF drawn with `cr` on `surface` (both destroyed): Ok, or Cairo's
// error, named with `what` ("sheet", "validation report").
Status finish_pdf(cairo_t* cr, cairo_surface_t* surface, const char* what);

class Page {
 public:
  explicit Page(cairo_t* cr) : cr_(cr) {}
  // UTF-8 text in DejaVu Sans at baseline (x, y); `right`: x is where it ends.
  void text(double x, double y, const std::string& s, double size, bool bold = false, bool right = false);
  // The width `s` takes at `size`.
  double text_width(const std::string& s, double size, bool bold = false);
  cairo_t* cr() { return cr_; }

 private:
  cairo_t* cr_;
};

enum BodySide { kFront, kLeftSide };

// The body's silhouette seen from `side`, top left at (x, y), `pt_per_mm`, with each
// entry's path drawn (heights left out) and, if `numbers`, numbered 1.. in order.
void draw_body(Page& page, const TriangleMesh& mesh, BodySide side, const std::vector<SheetEntry>& entries, double x,
               double y, double pt_per_mm, bool numbers);

// A PNG image fitted into the box (w, h) at (x, y), keeping its aspect, drawn
// from its top left. An error if the bytes are not a PNG Cairo reads.
Status draw_png(Page& page, const std::string& png, double x, double y, double w, double h);

// `text` as a QR code (error correction M) of side `size` points, top left at
// (x, y), with its quiet zone inside that side.
Status draw_qr(Page& page, const std::string& text, double x, double y, double size);

}  // namespace bodyscan::storage::drawing

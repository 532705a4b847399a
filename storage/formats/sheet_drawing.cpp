#include "storage/formats/sheet_drawing.hpp"

#include <qrencode.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace bodyscan::storage::drawing {

namespace {

// The body seen from the front (X to the right, Y up) or from its left side (-Z to
// the right, Y up): which pixels of a raster it covers.
struct View {
  int axis_x = 0;     // 0: X, 2: Z
  double sign_x = 1;  // +1 or -1
  Eigen::Vector2d project(const Eigen::Vector3d& p) const { return {sign_x * p[axis_x], p.y()}; }
};

struct Silhouette {
  int width = 0, height = 0;
  double lo_x = 0, hi_y = 0, mm_per_px = 1;
  std::vector<unsigned char> mask;  // width * height, 255 where the body is
  Eigen::Vector2d to_px(const Eigen::Vector2d& p) const {
    return {(p.x() - lo_x) / mm_per_px, (hi_y - p.y()) / mm_per_px};
  }
};

Silhouette rasterise(const TriangleMesh& mesh, const View& view, double mm_per_px) {
  Silhouette s;
  double lo_x = std::numeric_limits<double>::max(), hi_x = -lo_x, lo_y = lo_x, hi_y = -lo_x;
  for (const Vec3f& v : mesh.vertices) {
    const Eigen::Vector2d p = view.project(v.cast<double>());
    lo_x = std::min(lo_x, p.x()), hi_x = std::max(hi_x, p.x()), lo_y = std::min(lo_y, p.y()),
    hi_y = std::max(hi_y, p.y());
  }
  s.lo_x = lo_x, s.hi_y = hi_y, s.mm_per_px = mm_per_px;
  s.width = static_cast<int>(std::ceil((hi_x - lo_x) / mm_per_px)) + 1;
  s.height = static_cast<int>(std::ceil((hi_y - lo_y) / mm_per_px)) + 1;
  s.mask.assign(static_cast<size_t>(s.width) * static_cast<size_t>(s.height), 0);
  for (const Triangle& t : mesh.triangles) {
    Eigen::Vector2d q[3];
    for (int k = 0; k < 3; ++k) q[k] = s.to_px(view.project(mesh.vertices[t[k]].cast<double>()));
    const double area = (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
    if (area == 0) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int x1 = std::min(s.width - 1, static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int y1 = std::min(s.height - 1, static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Eigen::Vector2d c(x + 0.5, y + 0.5);
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Eigen::Vector2d a = q[k], b = q[(k + 1) % 3];
          const double e = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
          inside = area > 0 ? e >= 0 : e <= 0;
        }
        if (inside) s.mask[static_cast<size_t>(y) * static_cast<size_t>(s.width) + static_cast<size_t>(x)] = 255;
      }
  }
  return s;
}

// Reads a PNG held in memory for cairo_image_surface_create_from_png_stream.
struct PngReader {
  const std::string* bytes;
  size_t at = 0;
};

cairo_status_t read_png(void* closure, unsigned char* data, unsigned int length) {
  auto* r = static_cast<PngReader*>(closure);
  if (r->bytes->size() - r->at < length) return CAIRO_STATUS_READ_ERROR;
  std::copy_n(r->bytes->data() + r->at, length, data);
  r->at += length;
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

Status finish_pdf(cairo_t* cr, cairo_surface_t* surface, const char* what) {
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS)
    return internal_error(std::string(what) + ": Cairo failed: " + cairo_status_to_string(status));
  return Status::Ok();
}

void Page::text(double x, double y, const std::string& s, double size, bool bold, bool right) {
  cairo_select_font_face(cr_, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr_, size);
  if (right) x -= text_width(s, size, bold);
  cairo_move_to(cr_, x, y);
  cairo_show_text(cr_, s.c_str());
}

double Page::text_width(const std::string& s, double size, bool bold) {
  cairo_select_font_face(cr_, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr_, size);
  cairo_text_extents_t ext;
  cairo_text_extents(cr_, s.c_str(), &ext);
  return ext.x_advance;
}

// The silhouette at (x, y) (top left), `pt_per_mm`, with each entry's path drawn
// and, on the front view, numbered.
void draw_body(Page& page, const TriangleMesh& mesh, BodySide side, const std::vector<SheetEntry>& entries, double x,
               double y, double pt_per_mm, bool numbers) {
  const View view = side == kFront ? View{0, 1} : View{2, -1};
  constexpr double kPxPerPt = 3;
  const Silhouette s = rasterise(mesh, view, 1 / (pt_per_mm * kPxPerPt));
  cairo_t* cr = page.cr();
  const int stride = cairo_format_stride_for_width(CAIRO_FORMAT_A8, s.width);
  std::vector<unsigned char> rows(static_cast<size_t>(stride) * static_cast<size_t>(s.height), 0);
  for (int r = 0; r < s.height; ++r)
    std::copy_n(s.mask.begin() + static_cast<long>(r) * s.width, s.width, rows.begin() + static_cast<long>(r) * stride);
  cairo_surface_t* mask = cairo_image_surface_create_for_data(rows.data(), CAIRO_FORMAT_A8, s.width, s.height, stride);
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_scale(cr, 1 / kPxPerPt, 1 / kPxPerPt);
  cairo_set_source_rgb(cr, 0.78, 0.82, 0.88);
  cairo_mask_surface(cr, mask, 0, 0);
  cairo_restore(cr);
  cairo_surface_finish(mask);
  cairo_surface_destroy(mask);

  auto at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = s.to_px(view.project(p)) / kPxPerPt;
    return Eigen::Vector2d(x + q.x(), y + q.y());
  };
  cairo_set_line_width(cr, 0.6);
  for (size_t i = 0; i < entries.size(); ++i) {
    const SheetEntry& e = entries[i];
    if (e.path.size() < 2 || e.kind == "height") continue;
    cairo_set_source_rgb(cr, e.flagged ? 0.75 : 0.1, 0.2, e.flagged ? 0.1 : 0.55);
    Eigen::Vector2d right_most = at(e.path.front());
    for (size_t k = 0; k < e.path.size(); ++k) {
      const Eigen::Vector2d p = at(e.path[k]);
      (k == 0 ? cairo_move_to : cairo_line_to)(cr, p.x(), p.y());
      if (p.x() > right_most.x()) right_most = p;
    }
    if (e.closed) cairo_close_path(cr);
    cairo_stroke(cr);
    if (numbers) page.text(right_most.x() + 2, right_most.y() + 2, std::to_string(i + 1), 5);
  }
}

Status draw_png(Page& page, const std::string& png, double x, double y, double w, double h) {
  PngReader reader{&png};
  cairo_surface_t* image = cairo_image_surface_create_from_png_stream(read_png, &reader);
  const std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> owned(image, cairo_surface_destroy);
  if (cairo_surface_status(image) != CAIRO_STATUS_SUCCESS)
    return invalid_argument(std::string("logo: not a PNG Cairo reads (") +
                            cairo_status_to_string(cairo_surface_status(image)) + ")");
  const int iw = cairo_image_surface_get_width(image), ih = cairo_image_surface_get_height(image);
  if (iw <= 0 || ih <= 0) return invalid_argument("logo: the PNG is empty");
  const double scale = std::min(w / iw, h / ih);
  cairo_t* cr = page.cr();
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_scale(cr, scale, scale);
  cairo_set_source_surface(cr, image, 0, 0);
  cairo_paint(cr);
  cairo_restore(cr);
  return Status();
}

Status draw_qr(Page& page, const std::string& text, double x, double y, double size) {
  QRcode* code = QRcode_encodeString8bit(text.c_str(), 0, QR_ECLEVEL_M);
  if (!code) return invalid_argument("QR code: the text does not fit one (" + std::to_string(text.size()) + " bytes)");
  const std::unique_ptr<QRcode, void (*)(QRcode*)> owned(code, QRcode_free);
  constexpr int kQuiet = 4;  // modules of white around the code, as the standard asks
  const int n = code->width;
  const double module = size / (n + 2 * kQuiet);
  cairo_t* cr = page.cr();
  cairo_save(cr);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_rectangle(cr, x, y, size, size);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      if (code->data[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)] & 1)
        cairo_rectangle(cr, x + (c + kQuiet) * module, y + (r + kQuiet) * module, module, module);
  cairo_fill(cr);
  cairo_restore(cr);
  return Status();
}

}  // namespace bodyscan::storage::drawing

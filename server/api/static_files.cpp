#include "server/api/static_files.hpp"

#include "recon/io/atomic_file.hpp"

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string_view>
#include <system_error>

namespace bodyscan::server {

namespace fs = std::filesystem;

std::string mime_type(const std::string& name) {
  static const std::map<std::string, std::string> kTypes = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".wasm", "application/wasm"},
      {".glb", "model/gltf-binary"},
      {".gltf", "model/gltf+json"},
      {".drc", "application/octet-stream"},  // Draco has no registered type
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".woff2", "font/woff2"},
      {".txt", "text/plain; charset=utf-8"},
      {".pdf", "application/pdf"},
      {".csv", "text/csv; charset=utf-8"},
      {".webmanifest", "application/manifest+json"},
  };
  const size_t dot = name.rfind('.');
  if (dot == std::string::npos) return "application/octet-stream";
  std::string ext = name.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  auto it = kTypes.find(ext);
  return it == kTypes.end() ? "application/octet-stream" : it->second;
}

namespace {

bool safe_segments(const std::string& path) {
  if (path.empty() || path[0] != '/') return false;
  size_t start = 1;
  while (start <= path.size()) {
    const size_t end = std::min(path.find('/', start), path.size());
    const std::string seg = path.substr(start, end - start);
    if (seg.empty() && end != path.size()) return false;  // "//"
    if (seg == "." || seg == ".." || (!seg.empty() && seg[0] == '.')) return false;
    for (char c : seg)
      if (c == '\\' || c == '\0' || static_cast<unsigned char>(c) < 0x20) return false;
    start = end + 1;
  }
  return true;
}

// `p` lies under `root` (both canonical).
bool under(const fs::path& root, const fs::path& p) {
  auto r = root.begin(), q = p.begin();
  for (; r != root.end(); ++r, ++q)
    if (q == p.end() || *r != *q) return false;
  return true;
}

constexpr const char* kPageCsp =
    "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; worker-src 'self' blob:; "
    "img-src 'self' data: blob:; style-src 'self'; connect-src 'self'; object-src 'none'; "
    "base-uri 'none'; form-action 'self'; frame-ancestors 'none'";

// Accept-Encoding names gzip without q=0.
bool accepts_gzip(std::string_view header) {
  size_t at = 0;
  while (at < header.size()) {
    size_t end = header.find(',', at);
    if (end == std::string_view::npos) end = header.size();
    std::string_view item = header.substr(at, end - at);
    at = end + 1;
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    const size_t semi = item.find(';');
    std::string_view coding = item.substr(0, semi);
    while (!coding.empty() && coding.back() == ' ') coding.remove_suffix(1);
    if (coding != "gzip" && coding != "*") continue;
    if (semi == std::string_view::npos) return true;
    std::string_view params = item.substr(semi + 1);
    const size_t q = params.find("q=");
    if (q == std::string_view::npos) return true;
    return std::strtod(std::string(params.substr(q + 2)).c_str(), nullptr) > 0;
  }
  return false;
}

}  // namespace

HttpResponse serve_static(const std::string& web_root, const HttpRequest& request) {
  if (request.method != "GET" && request.method != "HEAD") {
    HttpResponse r = error_response(405, "only GET and HEAD reach static files");
    r.set("Allow", "GET, HEAD");
    return r;
  }
  if (!safe_segments(request.path)) return error_response(400, "bad path");
  std::error_code ec;
  const fs::path root = fs::canonical(web_root, ec);
  if (ec) return error_response(404, "the web UI is not installed (" + web_root + ")");
  std::string rel = request.path.substr(1);
  if (rel.empty() || rel.back() == '/') rel += "index.html";
  fs::path file = root / rel;
  if (!fs::is_regular_file(file, ec)) {
    // The UI's own routes (no extension) are pages of the single-page app.
    const std::string last = rel.substr(rel.rfind('/') == std::string::npos ? 0 : rel.rfind('/') + 1);
    if (last.find('.') != std::string::npos) return error_response(404, "no such file: " + request.path);
    file = root / "index.html";
  }
  const fs::path real = fs::canonical(file, ec);
  if (ec || !under(root, real) || !fs::is_regular_file(real, ec))
    return error_response(404, "no such file: " + request.path);
  // The UI's build leaves a .gz twin beside each large text or wasm file; a
  // browser that takes gzip gets it, the rest the file itself.
  const fs::path twin = real.string() + ".gz";
  const bool has_twin = fs::is_regular_file(twin, ec) && under(root, fs::canonical(twin, ec)) && !ec;
  const bool gzip = has_twin && accepts_gzip(request.header("accept-encoding"));
  const fs::path& sent = gzip ? twin : real;
  const auto size = fs::file_size(sent, ec);
  const auto mtime = fs::last_write_time(sent, ec).time_since_epoch().count();
  char etag[64];
  std::snprintf(etag, sizeof etag, "\"%llx-%llx%s\"", static_cast<unsigned long long>(size),
                static_cast<unsigned long long>(mtime), gzip ? "-gz" : "");
  HttpResponse r;
  r.set("Content-Type", mime_type(real.filename().string()));
  r.set("ETag", etag);
  r.set("X-Content-Type-Options", "nosniff");
  if (has_twin) r.set("Vary", "Accept-Encoding");
  if (gzip) r.set("Content-Encoding", "gzip");
  if (rel.rfind("assets/", 0) == 0)
    r.set("Cache-Control", "public, max-age=31536000, immutable");
  else
    r.set("Cache-Control", "no-cache");
  if (real.extension() == ".html") {
    // The UI's page: its own scripts only (and the Draco decoder's wasm and
    // worker), no framing, and no Referer: a share link's token never leaves in one.
    r.set("Content-Security-Policy", kPageCsp);
    r.set("Referrer-Policy", "no-referrer");
    r.set("X-Frame-Options", "DENY");
  }
  if (request.header("if-none-match") == etag) {
    r.status = 304;
    return r;
  }
  // Read on the worker pool (see scan_file); the UI's files are at most a few MB.
  auto bytes = read_whole_file(sent.string());
  if (!bytes.ok()) return error_response(bytes.status());
  r.body = std::move(*bytes);
  return r;
}

}  // namespace bodyscan::server

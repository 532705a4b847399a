// The browser UI's files, served only from the web root: the decoded path is
// checked segment by segment (no "..", ".", empty, hidden or backslashed
// segments) and the canonical file must still lie under the root (no symlink out).
#pragma once

#include <string>

#include "server/api/http_types.hpp"

namespace bodyscan::server {

// The MIME type for a file name's extension (.glb model/gltf-binary, .wasm
// application/wasm, .mjs text/javascript ...); application/octet-stream otherwise.
std::string mime_type(const std::string& name);

// GET/HEAD of a decoded path under `web_root`. "/" and paths without an extension
// that name no file (the UI's own routes, e.g. /s/TOKEN) give index.html. Files
// under assets/ (hashed names from the UI build) are cached for a year; the rest
// revalidate (ETag from size and modification time).
HttpResponse serve_static(const std::string& web_root, const HttpRequest& request);

}  // namespace bodyscan::server

// What the scan routes and the share routes both send: a scan's result file with
// its ETag (a stored measurement's JSON is storage::to_json).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "server/api/http_types.hpp"
#include "server/workstation/workstation.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::server {

// A scan's result file from the archive ("" version: the current one, which
// revalidates; a named version is immutable), 304 on a matching If-None-Match.
HttpResponse scan_file(Workstation& ws, const std::string& scan_id, const std::string& name,
                       const std::string& version_text, const std::string& if_none_match);

}  // namespace bodyscan::server

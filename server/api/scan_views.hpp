// What the scan routes and the share routes both send: a stored measurement as
// JSON, and a scan's result file with its ETag.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "server/api/http_types.hpp"
#include "server/workstation/workstation.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::server {

nlohmann::json measurement_json(const storage::MeasurementRecord& m);

// A scan's result file from the archive ("" version: the current one, which
// revalidates; a named version is immutable), 304 on a matching If-None-Match.
HttpResponse scan_file(Workstation& ws, const std::string& scan_id, const std::string& name,
                       const std::string& version_text, const std::string& if_none_match);

}  // namespace bodyscan::server

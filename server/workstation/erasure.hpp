// Erasing a customer or a scan, by every path (the API, `bodyscan archive`):
// the share links first (a link must never outlive what it shows), then the
// archive's records and files, then both databases' write-ahead logs are
// checkpointed and truncated, so nothing of what was erased lingers in a file.
#pragma once

#include <string>
#include <vector>

#include "core/status.hpp"
#include "server/auth/auth_store.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::server {

// `accounts` may be null where there is no accounts database (an archive
// without a workstation): there are no links then.
Status erase_customer(storage::Archive& archive, AuthStore* accounts, const std::string& customer_id,
                      const std::string& actor);
Status erase_scan(storage::Archive& archive, AuthStore* accounts, const std::string& scan_id, const std::string& actor);
// A shop's retention period: erases every scan that started before `before`
// (ISO 8601 UTC) and is not running, as erase_scan does. Returns the ids erased.
StatusOr<std::vector<std::string>> erase_scans_started_before(storage::Archive& archive, AuthStore* accounts,
                                                              const std::string& before, const std::string& actor);

}  // namespace bodyscan::server

#include "server/workstation/erasure.hpp"

namespace bodyscan::server {

Status erase_customer(storage::Archive& archive, AuthStore* accounts, const std::string& customer_id,
                      const std::string& actor) {
  RETURN_IF_ERROR(archive.customer(customer_id).status());
  if (accounts) {
    storage::ScanQuery q;
    q.customer_id = customer_id;
    q.limit = 1 << 30;
    ASSIGN_OR_RETURN(std::vector<storage::ScanRecord> scans, archive.scans(q));
    for (const storage::ScanRecord& s : scans) RETURN_IF_ERROR(accounts->delete_shares_of_scan(s.id));
  }
  return archive.delete_customer(customer_id, actor);
}

Status erase_scan(storage::Archive& archive, AuthStore* accounts, const std::string& scan_id,
                  const std::string& actor) {
  RETURN_IF_ERROR(archive.scan(scan_id).status());
  if (accounts) RETURN_IF_ERROR(accounts->delete_shares_of_scan(scan_id));
  return archive.delete_scan(scan_id, actor);
}

StatusOr<std::vector<std::string>> erase_scans_started_before(storage::Archive& archive, AuthStore* accounts,
                                                              const std::string& before, const std::string& actor) {
  storage::ScanQuery q;
  q.limit = 1 << 30;
  ASSIGN_OR_RETURN(std::vector<storage::ScanRecord> scans, archive.scans(q));
  std::vector<std::string> erased;
  for (const storage::ScanRecord& s : scans) {
    if (s.status == storage::ScanStatus::kRunning || !(s.started_at < before)) continue;
    RETURN_IF_ERROR(erase_scan(archive, accounts, s.id, actor));
    erased.push_back(s.id);
  }
  return erased;
}

}  // namespace bodyscan::server

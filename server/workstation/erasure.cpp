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

}  // namespace bodyscan::server

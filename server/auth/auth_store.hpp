// Who may use the workstation: staff accounts, their login sessions (with a CSRF
// token each), a limit on password guessing, and the links that let a customer
// see the measurements staff chose to share.
//
// One SQLite file (DATA/accounts.db; WAL, synchronous=FULL, foreign keys,
// secure_delete), created readable by its owner only. It never holds a password
// or a usable token: passwords are Argon2id strings, session and share tokens are
// stored as their BLAKE2b hash, so a copy of the file (a backup, a stolen disk)
// lets no one log in or open a share. The login rate limiter lives in memory: a
// restart forgets failures, which costs an attacker a restart per few guesses.
//
// Thread-safe: one connection behind one lock. Password hashing runs outside the
// lock so a login does not stall every other request.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"

namespace bodyscan::server {

enum class Role { kOperator, kTailor, kAdmin };
const char* to_string(Role r);  // "operator", "tailor", "admin"
std::optional<Role> role_from_string(std::string_view s);

struct Account {
  std::string username;
  Role role = Role::kOperator;
  std::string created_at;  // ISO 8601 UTC
};

struct Session {
  std::string username;
  Role role = Role::kOperator;  // the account's current role, not the one at login
  std::string csrf_token;       // random, per session; state-changing requests must echo it
  int64_t expires_at = 0;       // unix seconds: the earlier of the absolute and the idle limit
};

struct LoginResult {
  // kError: the store failed (disk full, damaged database); `error` says how.
  // Not the user's fault, so not reported as bad credentials.
  enum Outcome { kOk, kBadCredentials, kRateLimited, kError } outcome = kBadCredentials;
  std::string token;  // the session cookie value (kOk only): 256-bit random, base64url (43 chars)
  Session session;
  int retry_after_s = 0;  // kRateLimited: seconds until another attempt is allowed
  Status error;           // kError only
};

struct ShareLink {
  std::string id;  // public id to list/revoke ("sh_" + 16 hex)
  std::string scan_id;
  std::vector<std::string> measurements;  // names of the measurements staff chose to share
  std::string created_by, created_at;     // created_at: ISO 8601 UTC
  int64_t expires_at = 0;                 // unix seconds
  bool revoked = false;
  // Staff chose to show the head; otherwise the model the link serves has none.
  bool include_head = false;
  // The link opens only with a PIN that staff read out to the customer.
  bool pin = false;
};

struct ShareOptions {
  bool include_head = false;
  bool pin = false;  // make a PIN (NewShare::pin) that the link asks for
};

// token: 128-bit random, base64url (22 chars). Returned once; only its hash is kept.
struct NewShare {
  ShareLink link;
  std::string token;
  std::string pin;  // six digits, shown once; empty without one
};

// A PIN tried on a link: right, wrong (with the tries left), or wrong once too
// often, which withdraws the link.
enum class PinAnswer { kRight, kWrong, kWithdrawn };

// Sessions that ended or changed: every session of `username` (password, role
// or account deleted, end_sessions), or the one session `token` (logout). One of
// the two is set.
struct SessionChange {
  enum Reason { kLogout, kEnded, kPassword, kRole, kDeleted } reason = kEnded;
  std::string username;  // as stored (kLogout: empty)
  std::string token;     // the cookie value (kLogout only)
};

struct AuthOptions {
  // Argon2id cost. 0: libsodium's INTERACTIVE limits. Tests use
  // crypto_pwhash_OPSLIMIT_MIN / crypto_pwhash_MEMLIMIT_MIN.
  unsigned long long opslimit = 0, memlimit = 0;
  int64_t session_lifetime_s = 12 * 3600;  // absolute lifetime
  int64_t session_idle_s = 2 * 3600;       // expires when unused this long
  // Login failures within failure_window_s before refusing (see the limiter in
  // auth_store.cpp): per account at one address; per address over all accounts
  // (higher: a shop's tablets may share a NAT address); per account from all
  // addresses, and over everything, past which each address gets one failure.
  // max_failures <= 0 turns the limits off; the others <= 0 take their default
  // multiple of max_failures (4, 4, 20).
  int max_failures = 5;
  int max_address_failures = 20;
  int max_account_failures = 20;
  int max_total_failures = 100;
  int64_t failure_window_s = 300;
  std::function<int64_t()> now;  // unix seconds; default: the system clock
};

class AuthStore {
 public:
  static constexpr size_t kMaxUsername = 64;
  static constexpr size_t kMinPasswordChars = 10;
  static constexpr size_t kMaxPasswordBytes = 1024;
  static constexpr int64_t kMaxShareValidity = 365 * 24 * 3600;

  static StatusOr<std::unique_ptr<AuthStore>> open(const std::string& db_path, AuthOptions options = {});
  ~AuthStore();
  AuthStore(const AuthStore&) = delete;
  AuthStore& operator=(const AuthStore&) = delete;

  // Accounts. Usernames: 1-64 characters of [A-Za-z0-9._-], unique regardless of
  // case ("Anna" and "anna" are one account; login accepts either spelling).
  // Passwords: at least 10 characters, at most 1024 bytes. An existing username
  // is failed_precondition; an unknown one not_found.
  StatusOr<Account> add_account(const std::string& username, const std::string& password, Role role);
  // set_password ends that user's sessions. set_role refuses to demote the last
  // admin; delete_account refuses to delete it, and ends the account's sessions.
  Status set_password(const std::string& username, const std::string& password);
  Status set_role(const std::string& username, Role role);
  Status delete_account(const std::string& username);
  StatusOr<Account> account(const std::string& username) const;
  StatusOr<std::vector<Account>> accounts() const;  // by username
  bool has_admin() const;

  // The same work whether or not the user exists (an unknown user is verified
  // against a dummy hash). Past the failure limits (AuthOptions) attempts, even
  // with the right password, are kRateLimited without hashing; an address that
  // has failed at nothing is never refused. Success clears the failures of that
  // username at that address. Expired sessions are purged here.
  // `remote_address` is the client's (behind a trusted proxy, the address it
  // forwarded for).
  LoginResult login(const std::string& username, const std::string& password, const std::string& remote_address);
  // The session for a cookie token: unexpired (absolute and idle) and its account
  // still there. Refreshes its last use. Anything malformed is just nullopt.
  // With `refresh` false the last use stays as it was: for a check that is not
  // the user doing something (an open WebSocket re-checking its session).
  std::optional<Session> session(const std::string& token, bool refresh = true);
  void logout(const std::string& token);
  Status end_sessions(const std::string& username);  // every session of that user

  // Calls `fn` after every change that ends or alters sessions (logout,
  // end_sessions, set_password, set_role, delete_account), outside the store's
  // lock, on the caller's thread. Returns an id for unwatch_sessions.
  int watch_sessions(std::function<void(const SessionChange&)> fn);
  void unwatch_sessions(int id);

  // Share links. valid_for_s in (0, 365 days].
  StatusOr<NewShare> create_share(const std::string& scan_id, const std::vector<std::string>& measurements,
                                  int64_t valid_for_s, const std::string& created_by, const ShareOptions& options = {});
  // A link's PIN checked against what the customer typed: at most
  // kMaxPinFailures wrong in the link's life, then it is withdrawn. The PIN is
  // kept as a hash keyed by the token, which the database does not hold.
  static constexpr int kMaxPinFailures = 5;
  StatusOr<PinAnswer> check_share_pin(const std::string& token, const std::string& pin, int* tries_left = nullptr);
  std::optional<ShareLink> share_by_token(const std::string& token);          // unexpired and not revoked
  StatusOr<std::vector<ShareLink>> shares(const std::string& scan_id) const;  // all, oldest first
  Status revoke_share(const std::string& share_id);                           // not_found if unknown
  // When a scan or customer is erased (server/workstation/erasure.hpp); the
  // write-ahead log is checkpointed and truncated after.
  Status delete_shares_of_scan(const std::string& scan_id);

 private:
  struct Impl;
  explicit AuthStore(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyscan::server

#include "server/auth/auth_store.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <deque>
#include <initializer_list>
#include <map>
#include <mutex>
#include <unordered_map>

#include "core/json_text.hpp"
#include "storage/archive/ids.hpp"
#include "storage/archive/sqlite.hpp"

namespace bodyscan::server {

using storage::Database;
using storage::Statement;
using storage::Transaction;

const char* to_string(Role r) {
  switch (r) {
    case Role::kOperator: return "operator";
    case Role::kTailor: return "tailor";
    case Role::kAdmin: return "admin";
  }
  return "?";
}

std::optional<Role> role_from_string(std::string_view s) {
  if (s == "operator") return Role::kOperator;
  if (s == "tailor") return Role::kTailor;
  if (s == "admin") return Role::kAdmin;
  return std::nullopt;
}

namespace {

constexpr int kSchemaVersion = 1;
constexpr size_t kSessionTokenBytes = 32;
constexpr size_t kShareTokenBytes = 16;
// Writing last_used on every request would mean an fsync per request
// (synchronous=FULL); a minute's slack in the idle limit costs nothing.
constexpr int64_t kTouchEvery = 60;
// The limiter forgets keys whose failures have aged out only when it holds
// this many, so guessing across many usernames or addresses cannot grow it
// without bound, yet a quiet workstation never sweeps.
constexpr size_t kLimiterSweepAbove = 4096;
constexpr size_t kMaxRemoteKey = 128;
constexpr size_t kMaxScanId = 200;
constexpr size_t kMaxMeasurementName = 200;
constexpr size_t kMaxMeasurements = 1000;

int64_t system_now() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

constexpr int kBase64Url = sodium_base64_VARIANT_URLSAFE_NO_PADDING;

size_t base64url_chars(size_t bytes) { return sodium_base64_ENCODED_LEN(bytes, kBase64Url) - 1; }

std::string random_token(size_t bytes) {
  std::vector<unsigned char> b(bytes);
  randombytes_buf(b.data(), b.size());
  std::string out(base64url_chars(bytes) + 1, '\0');
  sodium_bin2base64(out.data(), out.size(), b.data(), b.size(), kBase64Url);
  sodium_memzero(b.data(), b.size());
  out.pop_back();
  return out;
}

// Cheap to check before touching the database: anything else was never issued.
bool well_formed_token(const std::string& token, size_t bytes) {
  if (token.size() != base64url_chars(bytes)) return false;
  return std::all_of(token.begin(), token.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
  });
}

// What the database keeps instead of a token. The tokens carry 128 or 256
// random bits, so a fast unsalted hash is enough: there is nothing to guess.
std::string token_hash(const std::string& token) {
  unsigned char h[32];
  crypto_generichash(h, sizeof h, reinterpret_cast<const unsigned char*>(token.data()), token.size(), nullptr, 0);
  char hex[65];
  sodium_bin2hex(hex, sizeof hex, h, sizeof h);
  return hex;
}

// The row was found by an index lookup on the hash, which leaks at most how
// much of a hash of a random secret matched; comparing again in constant time
// keeps the final decision free of early exits all the same.
bool same_hash(const std::string& a, const std::string& b) {
  return a.size() == b.size() && sodium_memcmp(a.data(), b.data(), a.size()) == 0;
}

// A link's PIN as the database keeps it: hashed with the link's token as the key.
// Six digits are a million guesses, but the token is not in the database, so a
// copy of the database alone does not give the PIN away; online, a link allows
// AuthStore::kMaxPinFailures wrong tries.
std::string share_pin_hash(const std::string& token, const std::string& pin) {
  unsigned char key[crypto_generichash_KEYBYTES];
  crypto_generichash(key, sizeof key, reinterpret_cast<const unsigned char*>(token.data()), token.size(), nullptr, 0);
  unsigned char h[32];
  crypto_generichash(h, sizeof h, reinterpret_cast<const unsigned char*>(pin.data()), pin.size(), key, sizeof key);
  char hex[65];
  sodium_bin2hex(hex, sizeof hex, h, sizeof h);
  return hex;
}

bool valid_username(const std::string& u) {
  if (u.empty() || u.size() > AuthStore::kMaxUsername) return false;
  return std::all_of(u.begin(), u.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
}

Status check_username(const std::string& u) {
  if (!valid_username(u))
    return invalid_argument("username must be 1-64 characters of letters, digits, '.', '_' and '-'");
  return Status::Ok();
}

// Characters, not bytes, so a passphrase in any script gets the same minimum.
size_t utf8_chars(const std::string& s) {
  return static_cast<size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

Status check_password(const std::string& p) {
  if (p.size() > AuthStore::kMaxPasswordBytes) return invalid_argument("password is longer than 1024 bytes");
  if (utf8_chars(p) < AuthStore::kMinPasswordChars) return invalid_argument("password must be at least 10 characters");
  return Status::Ok();
}

// Measurement names end up on a customer's page: no control characters, no
// byte sequences a browser or the JSON encoder would have to guess at.
bool printable_utf8(const std::string& s) {
  size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7f) return false;
      ++i;
      continue;
    }
    const size_t n = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
    if (n == 0 || c > 0xF4 || i + n > s.size()) return false;
    uint32_t cp = c & (0xFF >> (n + 1));
    for (size_t k = 1; k < n; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    const uint32_t min = n == 2 ? 0x80 : n == 3 ? 0x800 : 0x10000;
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF) || (cp >= 0x80 && cp < 0xA0)) return false;
    i += n;
  }
  return true;
}

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

// Remembers recent login failures, in a sliding window, under four keys: the
// account at one address, the address, the account from anywhere, and all.
// - An account guessed at from one address: that pair is refused.
// - Many accounts guessed at from one address: that address is refused.
// - One account guessed at from many addresses, or guessing all over (more than
//   an overall limit): the brake. Every address then gets one failure for that
//   account (or for any, under the overall limit) before it is refused.
// Failures at one address never refuse the right password from an address that
// has made none: a shop's staff cannot be locked out from elsewhere.
//
// A failure is recorded before the password is checked and forgiven on success,
// so parallel guesses cannot all slip past the check before any is counted.
class Limiter {
 public:
  struct Keys {
    std::string pair, address, account;
  };

  explicit Limiter(const AuthOptions& o)
      : pair_max_(o.max_failures),
        address_max_(o.max_address_failures > 0 ? o.max_address_failures : 4 * o.max_failures),
        account_max_(o.max_account_failures > 0 ? o.max_account_failures : 4 * o.max_failures),
        total_max_(o.max_total_failures > 0 ? o.max_total_failures : 20 * o.max_failures),
        window_(o.failure_window_s) {}

  // 0 having reserved a failure under every key, else seconds to wait.
  int reserve(const Keys& k, int64_t now) {
    std::lock_guard lock(mu_);
    if (pair_max_ <= 0) return 0;
    if (failures_.size() > kLimiterSweepAbove) sweep(now);
    auto& pair = failures_[k.pair];
    auto& address = failures_[k.address];
    auto& account = failures_[k.account];
    for (auto* d : {&pair, &address, &account, &total_}) expire(*d, now);
    const bool brake_all = static_cast<int>(total_.size()) >= total_max_;
    const bool brake_account = brake_all || static_cast<int>(account.size()) >= account_max_;
    int64_t wait = 0;
    for (auto [d, max] :
         {std::pair{&pair, brake_account ? 1 : pair_max_}, std::pair{&address, brake_all ? 1 : address_max_}}) {
      const auto n = static_cast<int>(d->size());
      // Until enough of this key's failures age out to go under its limit.
      if (n >= max) wait = std::max<int64_t>(wait, (*d)[n - max] + window_ - now);
      if (n >= max && wait <= 0) wait = 1;
    }
    // Clamped: a clock stepped backwards must not lock anyone out for longer.
    if (wait > 0) return static_cast<int>(std::clamp<int64_t>(wait, 1, window_));
    for (auto* d : {&pair, &address, &account, &total_}) d->push_back(now);
    return 0;
  }

  // The reserved failure was no failure: the pair starts afresh; the other keys
  // keep the failures made before.
  void forgive(const Keys& k, int64_t reserved_at) {
    std::lock_guard lock(mu_);
    failures_.erase(k.pair);
    unreserve({&k.address, &k.account}, reserved_at);
  }

  // Not the user's fault (the store failed): the attempt does not count.
  void release(const Keys& k, int64_t reserved_at) {
    std::lock_guard lock(mu_);
    unreserve({&k.pair, &k.address, &k.account}, reserved_at);
  }

 private:
  static void drop_one(std::deque<int64_t>& d, int64_t at) {
    auto pos = std::find(d.rbegin(), d.rend(), at);
    if (pos != d.rend()) d.erase(std::next(pos).base());
  }
  void unreserve(std::initializer_list<const std::string*> keys, int64_t at) {
    for (const std::string* key : keys) {
      auto it = failures_.find(*key);
      if (it == failures_.end()) continue;
      drop_one(it->second, at);
      if (it->second.empty()) failures_.erase(it);
    }
    drop_one(total_, at);
  }
  void expire(std::deque<int64_t>& d, int64_t now) const {
    while (!d.empty() && d.front() <= now - window_) d.pop_front();
  }
  void sweep(int64_t now) {
    for (auto it = failures_.begin(); it != failures_.end();) {
      expire(it->second, now);
      it = it->second.empty() ? failures_.erase(it) : std::next(it);
    }
  }

  const int pair_max_, address_max_, account_max_, total_max_;
  const int64_t window_;
  std::mutex mu_;
  std::unordered_map<std::string, std::deque<int64_t>> failures_;
  std::deque<int64_t> total_;
};

}  // namespace

struct AuthStore::Impl {
  mutable Database db;  // const queries prepare statements too
  mutable std::mutex mu;
  AuthOptions options;
  std::string dummy_hash;  // what unknown users are verified against
  Limiter limiter;
  std::mutex watch_mu;
  std::map<int, std::function<void(const SessionChange&)>> watchers;
  int next_watcher = 1;

  Impl(Database d, AuthOptions o) : db(std::move(d)), options(std::move(o)), limiter(options) {}

  int64_t now() const { return options.now ? options.now() : system_now(); }

  Status schema() {
    RETURN_IF_ERROR(
        db.exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON; PRAGMA "
                "secure_delete=ON;"
                "PRAGMA busy_timeout=5000;"));
    RETURN_IF_ERROR(db.exec(R"sql(
      CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
      CREATE TABLE IF NOT EXISTS accounts(
        username TEXT PRIMARY KEY COLLATE NOCASE,
        password_hash TEXT NOT NULL,
        role TEXT NOT NULL CHECK (role IN ('operator', 'tailor', 'admin')),
        created_at TEXT NOT NULL);
      CREATE TABLE IF NOT EXISTS sessions(
        token_hash TEXT PRIMARY KEY,
        username TEXT NOT NULL COLLATE NOCASE REFERENCES accounts(username) ON DELETE CASCADE,
        csrf_token TEXT NOT NULL,
        created_at INTEGER NOT NULL,
        last_used INTEGER NOT NULL,
        expires_at INTEGER NOT NULL);
      CREATE INDEX IF NOT EXISTS sessions_by_user ON sessions(username);
      CREATE TABLE IF NOT EXISTS shares(
        id TEXT PRIMARY KEY,
        token_hash TEXT NOT NULL UNIQUE,
        scan_id TEXT NOT NULL,
        measurements TEXT NOT NULL,
        created_by TEXT NOT NULL,
        created_at TEXT NOT NULL,
        created_at_s INTEGER NOT NULL,
        expires_at INTEGER NOT NULL,
        revoked INTEGER NOT NULL DEFAULT 0,
        include_head INTEGER NOT NULL DEFAULT 0,
        pin_hash TEXT,
        pin_failures INTEGER NOT NULL DEFAULT 0);
      CREATE INDEX IF NOT EXISTS shares_by_scan ON shares(scan_id);
    )sql"));
    // Links made before the head could be left out showed it: they keep doing so.
    RETURN_IF_ERROR(add_share_column("include_head", "include_head INTEGER NOT NULL DEFAULT 1"));
    RETURN_IF_ERROR(add_share_column("pin_hash", "pin_hash TEXT"));
    RETURN_IF_ERROR(add_share_column("pin_failures", "pin_failures INTEGER NOT NULL DEFAULT 0"));
    ASSIGN_OR_RETURN(Statement ins, db.prepare("INSERT OR IGNORE INTO meta(key, value) VALUES ('schema_version', ?)"));
    RETURN_IF_ERROR(ins.bind(1, std::to_string(kSchemaVersion)).run());
    ASSIGN_OR_RETURN(Statement st, db.prepare("SELECT value FROM meta WHERE key = 'schema_version'"));
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row || std::atoi(st.text(0).c_str()) > kSchemaVersion)
      return failed_precondition("accounts database: made by a newer bodyscan; update this one");
    return Status::Ok();
  }

  // A column the shares table gained after databases were made: added to those.
  Status add_share_column(const std::string& name, const std::string& definition) {
    ASSIGN_OR_RETURN(Statement cols, db.prepare("SELECT 1 FROM pragma_table_info('shares') WHERE name = ?"));
    cols.bind(1, name);
    ASSIGN_OR_RETURN(bool has, cols.step());
    return has ? Status::Ok() : db.exec("ALTER TABLE shares ADD COLUMN " + definition);
  }

  unsigned long long opslimit() const {
    return options.opslimit ? options.opslimit : crypto_pwhash_OPSLIMIT_INTERACTIVE;
  }
  size_t memlimit() const {
    return static_cast<size_t>(options.memlimit ? options.memlimit : crypto_pwhash_MEMLIMIT_INTERACTIVE);
  }

  StatusOr<std::string> hash_password(const std::string& password) const {
    char out[crypto_pwhash_STRBYTES];
    if (crypto_pwhash_str_alg(out, password.data(), password.size(), opslimit(), memlimit(),
                              crypto_pwhash_ALG_ARGON2ID13) != 0)
      return unavailable("accounts: not enough memory to hash the password");
    return std::string(out);
  }

  // mu held.
  struct Stored {
    std::string username, hash;
    Role role;
  };
  StatusOr<std::optional<Stored>> find_account(const std::string& username) const {
    ASSIGN_OR_RETURN(Statement st, db.prepare("SELECT username, password_hash, role FROM accounts WHERE username = ?"));
    st.bind(1, username);
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) return std::optional<Stored>();
    const auto role = role_from_string(st.text(2));
    if (!role) return internal_error("accounts: account '" + st.text(0) + "' has an unknown role");
    return std::optional<Stored>(Stored{st.text(0), st.text(1), *role});
  }

  StatusOr<int64_t> admin_count() const {
    ASSIGN_OR_RETURN(Statement st, db.prepare("SELECT COUNT(*) FROM accounts WHERE role = 'admin'"));
    ASSIGN_OR_RETURN(bool row, st.step());
    return row ? st.integer(0) : int64_t{0};
  }

  Status delete_sessions_of(const std::string& username) {
    ASSIGN_OR_RETURN(Statement st, db.prepare("DELETE FROM sessions WHERE username = ?"));
    return st.bind(1, username).run();
  }

  // A session for `stored`, provided its password is still the one just
  // verified: a password change while the hash ran must not be outlived.
  StatusOr<std::optional<LoginResult>> create_session(const Stored& stored, int64_t now) {
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(db));
    ASSIGN_OR_RETURN(auto current, find_account(stored.username));
    if (!current || !same_hash(current->hash, stored.hash)) return std::optional<LoginResult>();
    ASSIGN_OR_RETURN(Statement purge, db.prepare("DELETE FROM sessions WHERE expires_at <= ? OR last_used <= ?"));
    RETURN_IF_ERROR(purge.bind(1, now).bind(2, now - options.session_idle_s).run());
    LoginResult r;
    r.outcome = LoginResult::kOk;
    r.token = random_token(kSessionTokenBytes);
    r.session.username = current->username;
    r.session.role = current->role;
    r.session.csrf_token = random_token(kSessionTokenBytes);
    const int64_t expires = now + options.session_lifetime_s;
    r.session.expires_at = std::min(expires, now + options.session_idle_s);
    ASSIGN_OR_RETURN(Statement ins, db.prepare("INSERT INTO sessions(token_hash, username, csrf_token, created_at, "
                                               "last_used, expires_at) VALUES (?, ?, ?, ?, ?, ?)"));
    ins.bind(1, token_hash(r.token)).bind(2, current->username).bind(3, r.session.csrf_token);
    RETURN_IF_ERROR(ins.bind(4, now).bind(5, now).bind(6, expires).run());
    RETURN_IF_ERROR(tx.commit());
    return std::optional<LoginResult>(std::move(r));
  }

  void notify(const SessionChange& change) {
    std::vector<std::function<void(const SessionChange&)>> fns;
    {
      std::lock_guard lock(watch_mu);
      for (const auto& [id, fn] : watchers) fns.push_back(fn);
    }
    for (const auto& fn : fns) fn(change);
  }

  StatusOr<std::optional<Session>> find_session(const std::string& hash, int64_t now, bool refresh) {
    ASSIGN_OR_RETURN(Statement st, db.prepare("SELECT s.token_hash, s.csrf_token, s.last_used, s.expires_at, "
                                              "a.username, a.role FROM sessions s JOIN accounts a "
                                              "ON a.username = s.username WHERE s.token_hash = ?"));
    st.bind(1, hash);
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row || !same_hash(st.text(0), hash)) return std::optional<Session>();
    const int64_t last_used = st.integer(2), expires = st.integer(3);
    const auto role = role_from_string(st.text(5));
    if (!role || now >= expires || now >= last_used + options.session_idle_s) {
      ASSIGN_OR_RETURN(Statement del, db.prepare("DELETE FROM sessions WHERE token_hash = ?"));
      RETURN_IF_ERROR(del.bind(1, hash).run());
      return std::optional<Session>();
    }
    Session s;
    s.username = st.text(4);
    s.role = *role;
    s.csrf_token = st.text(1);
    int64_t used = last_used;
    if (refresh && now - last_used >= kTouchEvery) {
      ASSIGN_OR_RETURN(Statement touch, db.prepare("UPDATE sessions SET last_used = ? WHERE token_hash = ?"));
      // The session is valid either way; a failed refresh only shortens it.
      if (touch.bind(1, now).bind(2, hash).run().ok()) used = now;
    }
    s.expires_at = std::min(expires, used + options.session_idle_s);
    return std::optional<Session>(std::move(s));
  }

  static StatusOr<ShareLink> read_share(const Statement& st) {
    // Columns: id, scan_id, measurements, created_by, created_at, expires_at, revoked, include_head,
    // pin_hash.
    ShareLink l;
    l.id = st.text(0), l.scan_id = st.text(1), l.created_by = st.text(3), l.created_at = st.text(4);
    l.expires_at = st.integer(5);
    l.revoked = st.integer(6) != 0;
    l.include_head = st.integer(7) != 0;
    l.pin = st.maybe_text(8).has_value();
    const auto j = parse_json(st.text(2));
    if (!j.is_array()) return internal_error("accounts: share " + l.id + " has damaged measurements");
    for (const auto& m : j) {
      if (!m.is_string()) return internal_error("accounts: share " + l.id + " has damaged measurements");
      l.measurements.push_back(m.get<std::string>());
    }
    return l;
  }
};

AuthStore::AuthStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AuthStore::~AuthStore() = default;

StatusOr<std::unique_ptr<AuthStore>> AuthStore::open(const std::string& db_path, AuthOptions options) {
  if (sodium_init() < 0) return internal_error("accounts: libsodium failed to start");
  if (options.session_lifetime_s <= 0 || options.session_idle_s <= 0 || options.failure_window_s <= 0)
    return invalid_argument("accounts: session lifetimes and the failure window must be positive");
  // Password hashes are nobody else's business: create the file (and so, as
  // SQLite copies its mode, the WAL beside it) readable by its owner only.
  if (!db_path.empty() && db_path != ":memory:") {
    const int fd = ::open(db_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (fd < 0) return io_error("accounts: cannot open " + db_path + ": " + std::strerror(errno));
    ::close(fd);
  }
  ASSIGN_OR_RETURN(Database db, Database::open(db_path));
  auto impl = std::make_unique<Impl>(std::move(db), std::move(options));
  RETURN_IF_ERROR(impl->schema().with_context(db_path));
  ASSIGN_OR_RETURN(impl->dummy_hash, impl->hash_password(storage::random_hex(32)));
  return std::unique_ptr<AuthStore>(new AuthStore(std::move(impl)));
}

// --- accounts ------------------------------------------------------------------

StatusOr<Account> AuthStore::add_account(const std::string& username, const std::string& password, Role role) {
  RETURN_IF_ERROR(check_username(username));
  RETURN_IF_ERROR(check_password(password));
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(auto existing, impl_->find_account(username));
    if (existing) return failed_precondition("an account named '" + existing->username + "' already exists");
  }
  ASSIGN_OR_RETURN(std::string hash, impl_->hash_password(password));
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  // Again: another thread may have added the name while the hash ran.
  ASSIGN_OR_RETURN(auto existing, impl_->find_account(username));
  if (existing) return failed_precondition("an account named '" + existing->username + "' already exists");
  Account a{username, role, storage::iso8601_utc(impl_->now())};
  ASSIGN_OR_RETURN(
      Statement st,
      impl_->db.prepare("INSERT INTO accounts(username, password_hash, role, created_at) VALUES (?, ?, ?, ?)"));
  RETURN_IF_ERROR(st.bind(1, a.username).bind(2, hash).bind(3, to_string(role)).bind(4, a.created_at).run());
  RETURN_IF_ERROR(tx.commit());
  return a;
}

Status AuthStore::set_password(const std::string& username, const std::string& password) {
  RETURN_IF_ERROR(check_password(password));
  std::string stored_name;
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(auto existing, impl_->find_account(username));
    if (!existing) return not_found("no account named '" + username + "'");
    stored_name = existing->username;
  }
  ASSIGN_OR_RETURN(std::string hash, impl_->hash_password(password));
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("UPDATE accounts SET password_hash = ? WHERE username = ?"));
    RETURN_IF_ERROR(st.bind(1, hash).bind(2, username).run());
    if (sqlite3_changes(impl_->db.handle()) == 0) return not_found("no account named '" + username + "'");
    RETURN_IF_ERROR(impl_->delete_sessions_of(username));
    RETURN_IF_ERROR(tx.commit());
  }
  impl_->notify({SessionChange::kPassword, stored_name, ""});
  return Status::Ok();
}

Status AuthStore::set_role(const std::string& username, Role role) {
  std::string stored_name;
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    ASSIGN_OR_RETURN(auto existing, impl_->find_account(username));
    if (!existing) return not_found("no account named '" + username + "'");
    if (existing->role == role) return Status::Ok();
    if (existing->role == Role::kAdmin) {
      ASSIGN_OR_RETURN(int64_t admins, impl_->admin_count());
      if (admins <= 1)
        return failed_precondition("'" + existing->username + "' is the last admin; make another admin first");
    }
    ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("UPDATE accounts SET role = ? WHERE username = ?"));
    RETURN_IF_ERROR(st.bind(1, to_string(role)).bind(2, username).run());
    RETURN_IF_ERROR(tx.commit());
    stored_name = existing->username;
  }
  impl_->notify({SessionChange::kRole, stored_name, ""});
  return Status::Ok();
}

Status AuthStore::delete_account(const std::string& username) {
  std::string stored_name;
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    ASSIGN_OR_RETURN(auto existing, impl_->find_account(username));
    if (!existing) return not_found("no account named '" + username + "'");
    if (existing->role == Role::kAdmin) {
      ASSIGN_OR_RETURN(int64_t admins, impl_->admin_count());
      if (admins <= 1)
        return failed_precondition("'" + existing->username + "' is the last admin; make another admin first");
    }
    // Sessions go with it (ON DELETE CASCADE); said explicitly so it does not
    // hang on a pragma.
    RETURN_IF_ERROR(impl_->delete_sessions_of(username));
    ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("DELETE FROM accounts WHERE username = ?"));
    RETURN_IF_ERROR(st.bind(1, username).run());
    RETURN_IF_ERROR(tx.commit());
    stored_name = existing->username;
  }
  impl_->notify({SessionChange::kDeleted, stored_name, ""});
  return Status::Ok();
}

StatusOr<Account> AuthStore::account(const std::string& username) const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("SELECT username, role, created_at FROM accounts WHERE username = ?"));
  st.bind(1, username);
  ASSIGN_OR_RETURN(bool row, st.step());
  if (!row) return not_found("no account named '" + username + "'");
  const auto role = role_from_string(st.text(1));
  if (!role) return internal_error("accounts: account '" + st.text(0) + "' has an unknown role");
  return Account{st.text(0), *role, st.text(2)};
}

StatusOr<std::vector<Account>> AuthStore::accounts() const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("SELECT username, role, created_at FROM accounts ORDER BY username"));
  std::vector<Account> out;
  for (;;) {
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) break;
    const auto role = role_from_string(st.text(1));
    if (!role) return internal_error("accounts: account '" + st.text(0) + "' has an unknown role");
    out.push_back({st.text(0), *role, st.text(2)});
  }
  return out;
}

bool AuthStore::has_admin() const {
  std::lock_guard lock(impl_->mu);
  const auto n = impl_->admin_count();
  return n.ok() && *n > 0;
}

// --- sessions ------------------------------------------------------------------

LoginResult AuthStore::login(const std::string& username, const std::string& password,
                             const std::string& remote_address) {
  LoginResult r;
  const int64_t now = impl_->now();
  // Bounded keys: an absurd username or address is still one key, not a megabyte.
  const std::string user = lower(username.substr(0, kMaxUsername + 1));
  const std::string address = remote_address.substr(0, kMaxRemoteKey);
  // NUL cannot occur in a username that reaches here bounded, nor in an address.
  const Limiter::Keys keys{"p:" + user + std::string(1, '\0') + address, "a:" + address, "u:" + user};
  if (const int wait = impl_->limiter.reserve(keys, now)) {
    r.outcome = LoginResult::kRateLimited;
    r.retry_after_s = wait;
    return r;
  }
  auto fail = [&](Status s) {
    impl_->limiter.release(keys, now);
    r.outcome = LoginResult::kError;
    r.error = std::move(s);
    return r;
  };

  std::optional<Impl::Stored> stored;
  if (valid_username(username)) {
    std::lock_guard lock(impl_->mu);
    auto found = impl_->find_account(username);
    if (!found.ok()) return fail(found.status());
    stored = std::move(*found);
  }
  // No password that long was ever accepted, and refusing early bounds the
  // work an anonymous request can cause.
  if (password.size() > kMaxPasswordBytes) return r;
  const std::string& hash = stored ? stored->hash : impl_->dummy_hash;
  const bool match = crypto_pwhash_str_verify(hash.c_str(), password.data(), password.size()) == 0;
  if (!match || !stored) return r;

  std::optional<LoginResult> ok;
  {
    std::lock_guard lock(impl_->mu);
    auto created = impl_->create_session(*stored, now);
    if (!created.ok()) return fail(created.status());
    ok = std::move(*created);
  }
  if (!ok) return r;  // the password changed (or the account went) while verifying
  impl_->limiter.forgive(keys, now);

  // Accounts made under weaker settings get the current cost now that the
  // password is at hand; failing to is no reason to refuse the login.
  if (crypto_pwhash_str_needs_rehash(stored->hash.c_str(), impl_->opslimit(), impl_->memlimit()) != 0) {
    if (auto rehashed = impl_->hash_password(password); rehashed.ok()) {
      std::lock_guard lock(impl_->mu);
      auto st = impl_->db.prepare("UPDATE accounts SET password_hash = ? WHERE username = ? AND password_hash = ?");
      if (st.ok()) (void)st->bind(1, *rehashed).bind(2, stored->username).bind(3, stored->hash).run();
    }
  }
  return std::move(*ok);
}

std::optional<Session> AuthStore::session(const std::string& token, bool refresh) {
  if (!well_formed_token(token, kSessionTokenBytes)) return std::nullopt;
  const std::string hash = token_hash(token);
  const int64_t now = impl_->now();
  std::lock_guard lock(impl_->mu);
  auto s = impl_->find_session(hash, now, refresh);
  // A store that cannot answer lets no one in.
  if (!s.ok()) return std::nullopt;
  return std::move(*s);
}

void AuthStore::logout(const std::string& token) {
  if (!well_formed_token(token, kSessionTokenBytes)) return;
  const std::string hash = token_hash(token);
  {
    std::lock_guard lock(impl_->mu);
    auto st = impl_->db.prepare("DELETE FROM sessions WHERE token_hash = ?");
    if (st.ok()) (void)st->bind(1, hash).run();
  }
  impl_->notify({SessionChange::kLogout, "", token});
}

Status AuthStore::end_sessions(const std::string& username) {
  {
    std::lock_guard lock(impl_->mu);
    RETURN_IF_ERROR(impl_->delete_sessions_of(username));
  }
  impl_->notify({SessionChange::kEnded, username, ""});
  return Status::Ok();
}

int AuthStore::watch_sessions(std::function<void(const SessionChange&)> fn) {
  std::lock_guard lock(impl_->watch_mu);
  const int id = impl_->next_watcher++;
  impl_->watchers.emplace(id, std::move(fn));
  return id;
}

void AuthStore::unwatch_sessions(int id) {
  std::lock_guard lock(impl_->watch_mu);
  impl_->watchers.erase(id);
}

// --- share links ---------------------------------------------------------------

StatusOr<NewShare> AuthStore::create_share(const std::string& scan_id, const std::vector<std::string>& measurements,
                                           int64_t valid_for_s, const std::string& created_by,
                                           const ShareOptions& options) {
  if (scan_id.empty() || scan_id.size() > kMaxScanId) return invalid_argument("share: bad scan id");
  if (valid_for_s <= 0 || valid_for_s > kMaxShareValidity)
    return invalid_argument("share: validity must be more than 0 seconds and at most 365 days");
  if (measurements.size() > kMaxMeasurements) return invalid_argument("share: too many measurements");
  nlohmann::json names = nlohmann::json::array();
  for (const auto& m : measurements) {
    if (m.empty() || m.size() > kMaxMeasurementName || !printable_utf8(m))
      return invalid_argument("share: measurement names must be 1-200 bytes of printable UTF-8");
    names.push_back(m);
  }
  const std::string names_json = names.dump();  // cannot throw: the names are valid UTF-8

  const int64_t now = impl_->now();
  NewShare out;
  out.token = random_token(kShareTokenBytes);
  ShareLink& l = out.link;
  l.id = "sh_" + storage::random_hex(8);
  l.scan_id = scan_id;
  l.measurements = measurements;
  l.created_by = created_by;
  l.created_at = storage::iso8601_utc(now);
  l.expires_at = now + valid_for_s;
  l.include_head = options.include_head;
  l.pin = options.pin;
  std::optional<std::string> pin_hash;
  if (options.pin) {
    out.pin = std::to_string(100000 + randombytes_uniform(900000));
    pin_hash = share_pin_hash(out.token, out.pin);
  }
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(
      Statement st,
      impl_->db.prepare("INSERT INTO shares(id, token_hash, scan_id, measurements, created_by, created_at, "
                        "created_at_s, expires_at, include_head, pin_hash) "
                        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"));
  st.bind(1, l.id).bind(2, token_hash(out.token)).bind(3, l.scan_id).bind(4, names_json).bind(5, l.created_by);
  st.bind(6, l.created_at).bind(7, now).bind(8, l.expires_at).bind(9, options.include_head ? 1 : 0);
  RETURN_IF_ERROR(st.bind(10, pin_hash).run());
  return out;
}

std::optional<ShareLink> AuthStore::share_by_token(const std::string& token) {
  if (!well_formed_token(token, kShareTokenBytes)) return std::nullopt;
  const std::string hash = token_hash(token);
  const int64_t now = impl_->now();
  std::lock_guard lock(impl_->mu);
  auto st = impl_->db.prepare(
      "SELECT id, scan_id, measurements, created_by, created_at, expires_at, revoked, include_head, pin_hash, "
      "token_hash FROM shares WHERE token_hash = ?");
  if (!st.ok()) return std::nullopt;
  st->bind(1, hash);
  const auto row = st->step();
  if (!row.ok() || !*row || !same_hash(st->text(9), hash)) return std::nullopt;
  auto link = Impl::read_share(*st);
  if (!link.ok() || link->revoked || now >= link->expires_at) return std::nullopt;
  return std::move(*link);
}

StatusOr<std::vector<ShareLink>> AuthStore::shares(const std::string& scan_id) const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(
      Statement st,
      impl_->db.prepare("SELECT id, scan_id, measurements, created_by, created_at, expires_at, revoked, "
                        "include_head, pin_hash FROM shares WHERE scan_id = ? ORDER BY created_at_s, rowid"));
  st.bind(1, scan_id);
  std::vector<ShareLink> out;
  for (;;) {
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) break;
    ASSIGN_OR_RETURN(ShareLink l, Impl::read_share(st));
    out.push_back(std::move(l));
  }
  return out;
}

StatusOr<PinAnswer> AuthStore::check_share_pin(const std::string& token, const std::string& pin, int* tries_left) {
  if (!well_formed_token(token, kShareTokenBytes)) return not_found("no such link");
  const std::string hash = token_hash(token);
  const int64_t now = impl_->now();
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("SELECT pin_hash, pin_failures, revoked, expires_at, token_hash "
                                                   "FROM shares WHERE token_hash = ?"));
  st.bind(1, hash);
  ASSIGN_OR_RETURN(bool row, st.step());
  if (!row || !same_hash(st.text(4), hash) || st.integer(2) != 0 || now >= st.integer(3))
    return not_found("no such link");
  const std::optional<std::string> stored = st.maybe_text(0);
  if (!stored) return PinAnswer::kRight;
  const int64_t failures = st.integer(1);
  if (same_hash(*stored, share_pin_hash(token, pin))) {
    if (tries_left) *tries_left = static_cast<int>(kMaxPinFailures - failures);
    return PinAnswer::kRight;
  }
  const bool withdraw = failures + 1 >= kMaxPinFailures;
  ASSIGN_OR_RETURN(Statement up, impl_->db.prepare("UPDATE shares SET pin_failures = pin_failures + 1, "
                                                   "revoked = ? WHERE token_hash = ?"));
  RETURN_IF_ERROR(up.bind(1, withdraw ? 1 : 0).bind(2, hash).run());
  if (tries_left) *tries_left = static_cast<int>(std::max<int64_t>(0, kMaxPinFailures - failures - 1));
  return withdraw ? PinAnswer::kWithdrawn : PinAnswer::kWrong;
}

Status AuthStore::revoke_share(const std::string& share_id) {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("UPDATE shares SET revoked = 1 WHERE id = ?"));
  RETURN_IF_ERROR(st.bind(1, share_id).run());
  if (sqlite3_changes(impl_->db.handle()) == 0) return not_found("no share link '" + share_id + "'");
  return Status::Ok();
}

Status AuthStore::delete_shares_of_scan(const std::string& scan_id) {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("DELETE FROM shares WHERE scan_id = ?"));
  RETURN_IF_ERROR(st.bind(1, scan_id).run());
  // An erased scan's id must not linger in the write-ahead log (secure_delete
  // already overwrites the freed pages of the database itself).
  return impl_->db.exec("PRAGMA wal_checkpoint(TRUNCATE)");
}

}  // namespace bodyscan::server

#include "storage/archive/sqlite.hpp"

namespace bodyscan::storage {

namespace {
// SQLite's result code as a Status a user can act on.
Status classify(int extended_code, const std::string& msg) {
  switch (extended_code & 0xff) {
    case SQLITE_FULL: return io_error(msg + " (the disk is full)");
    case SQLITE_IOERR: return io_error(msg);
    case SQLITE_CONSTRAINT: return invalid_argument(msg);
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return unavailable(msg);
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB: return io_error(msg + " (the archive's database is damaged)");
    default: return internal_error(msg);
  }
}
}  // namespace

StatusOr<Database> Database::open(const std::string& path) {
  sqlite3* db = nullptr;
  const int rc =
      sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string msg = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close(db);
    return io_error(path + ": cannot open the archive's database: " + msg);
  }
  sqlite3_extended_result_codes(db, 1);
  return Database(db);
}

Database& Database::operator=(Database&& o) noexcept {
  if (this != &o) {
    if (db_) sqlite3_close(db_);
    db_ = o.db_;
    o.db_ = nullptr;
  }
  return *this;
}

Database::~Database() {
  if (db_) sqlite3_close(db_);
}

Status Database::error(const std::string& what) const {
  return classify(sqlite3_extended_errcode(db_), what + ": " + sqlite3_errmsg(db_));
}

Status Database::exec(const std::string& sql) {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string head = sql.substr(0, 60);
    sqlite3_free(err);
    return error("archive database, '" + head + "'");
  }
  return Status::Ok();
}

StatusOr<Statement> Database::prepare(const std::string& sql) {
  sqlite3_stmt* st = nullptr;
  if (sqlite3_prepare_v2(db_, sql.c_str(), static_cast<int>(sql.size()), &st, nullptr) != SQLITE_OK)
    return error("archive database, preparing '" + sql.substr(0, 60) + "'");
  return Statement(db_, st);
}

Statement::~Statement() {
  if (st_) sqlite3_finalize(st_);
}

Statement& Statement::bind(int i, std::string_view text) {
  sqlite3_bind_text(st_, i, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
  return *this;
}
Statement& Statement::bind(int i, const std::optional<std::string>& text) {
  return text ? bind(i, std::string_view(*text)) : bind_null(i);
}
Statement& Statement::bind(int i, int64_t v) {
  sqlite3_bind_int64(st_, i, v);
  return *this;
}
Statement& Statement::bind(int i, double v) {
  sqlite3_bind_double(st_, i, v);
  return *this;
}
Statement& Statement::bind_null(int i) {
  sqlite3_bind_null(st_, i);
  return *this;
}

StatusOr<bool> Statement::step() {
  const int rc = sqlite3_step(st_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  const std::string sql = sqlite3_sql(st_) ? sqlite3_sql(st_) : "";
  return classify(sqlite3_extended_errcode(db_),
                  "archive database, '" + sql.substr(0, 60) + "': " + sqlite3_errmsg(db_));
}

Status Statement::run() {
  for (;;) {
    ASSIGN_OR_RETURN(bool row, step());
    if (!row) return Status::Ok();
  }
}

std::string Statement::text(int col) const {
  const unsigned char* t = sqlite3_column_text(st_, col);
  return t ? std::string(reinterpret_cast<const char*>(t), static_cast<size_t>(sqlite3_column_bytes(st_, col)))
           : std::string();
}
std::optional<std::string> Statement::maybe_text(int col) const {
  if (sqlite3_column_type(st_, col) == SQLITE_NULL) return std::nullopt;
  return text(col);
}
int64_t Statement::integer(int col) const { return sqlite3_column_int64(st_, col); }
double Statement::real(int col) const { return sqlite3_column_double(st_, col); }

StatusOr<Transaction> Transaction::begin(Database& db) {
  RETURN_IF_ERROR(db.exec("BEGIN IMMEDIATE"));
  return Transaction(&db);
}

Transaction::~Transaction() {
  if (db_) db_->exec("ROLLBACK");
}

Status Transaction::commit() {
  Database* db = db_;
  db_ = nullptr;
  const Status s = db->exec("COMMIT");
  if (!s.ok()) db->exec("ROLLBACK");
  return s;
}

}  // namespace bodyscan::storage

// A thin RAII layer over SQLite's C API for the archive: one connection, prepared
// statements with bound values, transactions that roll back unless committed, and
// every failure turned into a Status that names the statement.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "core/status.hpp"

namespace bodyscan::storage {

class Statement;

class Database {
 public:
  static StatusOr<Database> open(const std::string& path);
  Database(Database&& o) noexcept : db_(o.db_) { o.db_ = nullptr; }
  Database& operator=(Database&& o) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;
  ~Database();

  // Runs one or more statements without results.
  Status exec(const std::string& sql);
  StatusOr<Statement> prepare(const std::string& sql);
  Status error(const std::string& what) const;  // the connection's last error
  sqlite3* handle() const { return db_; }

 private:
  explicit Database(sqlite3* db) : db_(db) {}
  sqlite3* db_ = nullptr;
};

class Statement {
 public:
  Statement(Statement&& o) noexcept : db_(o.db_), st_(o.st_) { o.st_ = nullptr; }
  Statement(const Statement&) = delete;
  ~Statement();

  Statement& bind(int i, std::string_view text);
  Statement& bind(int i, const std::string& text) { return bind(i, std::string_view(text)); }
  Statement& bind(int i, const char* text) { return bind(i, std::string_view(text)); }
  Statement& bind(int i, const std::optional<std::string>& text);
  Statement& bind(int i, int64_t v);
  Statement& bind(int i, int v) { return bind(i, static_cast<int64_t>(v)); }
  Statement& bind(int i, double v);
  Statement& bind_null(int i);

  // Advances: true with a row, false when done; an error otherwise.
  StatusOr<bool> step();
  // Runs a statement without results to its end.
  Status run();
  // Ready to run again (bindings kept until rebound).
  void reset() { sqlite3_reset(st_); }

  std::string text(int col) const;
  std::optional<std::string> maybe_text(int col) const;
  int64_t integer(int col) const;
  double real(int col) const;

 private:
  friend class Database;
  Statement(sqlite3* db, sqlite3_stmt* st) : db_(db), st_(st) {}
  sqlite3* db_;
  sqlite3_stmt* st_;
};

// BEGIN IMMEDIATE ... COMMIT; rolled back when destroyed uncommitted.
class Transaction {
 public:
  static StatusOr<Transaction> begin(Database& db);
  Transaction(Transaction&& o) noexcept : db_(o.db_) { o.db_ = nullptr; }
  ~Transaction();
  Status commit();

 private:
  explicit Transaction(Database* db) : db_(db) {}
  Database* db_;
};

}  // namespace bodyscan::storage

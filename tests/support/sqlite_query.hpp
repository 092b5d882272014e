// Reads (and, for damaged files, changes) an SQLite file from tests: the first column of every
// row of a query, as text.
#pragma once

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <string>
#include <vector>

namespace crowddb::test {

inline std::vector<std::string> query(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* h = nullptr;
  EXPECT_EQ(sqlite3_open_v2(db.c_str(), &h, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  std::vector<std::string> out;
  sqlite3_exec(
      h, sql.c_str(),
      [](void* p, int, char** v, char**) {
        static_cast<std::vector<std::string>*>(p)->push_back(v[0] ? v[0] : "NULL");
        return 0;
      },
      &out, nullptr);
  sqlite3_close(h);
  return out;
}

// Changes an SQLite file from tests (a damaged or older file made from a good one): `sql` must
// succeed.
inline void execute(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  char* err = nullptr;
  EXPECT_EQ(sqlite3_exec(h, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK) << (err ? err : "");
  sqlite3_free(err);
  sqlite3_close(h);
}

// The rows of a query, read with SQLite's own types (doubles bit for bit):
//   for (Rows r(db, "SELECT ..."); r.next();) r.i64(0), r.real(1) ...
class Rows {
 public:
  Rows(const std::filesystem::path& db, const std::string& sql) {
    EXPECT_EQ(sqlite3_open_v2(db.c_str(), &h_, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    EXPECT_EQ(sqlite3_prepare_v2(h_, sql.c_str(), -1, &st_, nullptr), SQLITE_OK)
        << sqlite3_errmsg(h_);
  }
  ~Rows() {
    sqlite3_finalize(st_);
    sqlite3_close(h_);
  }
  Rows(const Rows&) = delete;
  Rows& operator=(const Rows&) = delete;
  bool next() { return st_ && sqlite3_step(st_) == SQLITE_ROW; }
  int64_t i64(int column) const { return sqlite3_column_int64(st_, column); }
  double real(int column) const { return sqlite3_column_double(st_, column); }
  std::string blob(int column) const {
    const auto* p = static_cast<const char*>(sqlite3_column_blob(st_, column));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(st_, column))) : "";
  }

 private:
  sqlite3* h_ = nullptr;
  sqlite3_stmt* st_ = nullptr;
};

}  // namespace crowddb::test

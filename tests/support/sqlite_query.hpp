// Reads an SQLite file from tests: the first column of every row of a query, as text.
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

}  // namespace crowddb::test

// read_input_file: bounded work whatever the path names.
#include "util/read_file.hpp"

#include <gtest/gtest.h>

#include "crowddb/error.hpp"
#include "support/cli.hpp"

namespace crowddb {
namespace {

std::string error_of(const std::filesystem::path& path, uint64_t limit = kMaxInputBytes) {
  try {
    read_input_file(path, limit);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::io);
    return e.what();
  }
  return "";
}

TEST(ReadInputFile, ReadsRegularFilesWhole) {
  test::TempDir dir;
  const auto f = dir.write("a.txt", std::string(100'000, 'x') + "end");
  EXPECT_EQ(read_input_file(f).size(), 100'003u);
}

TEST(ReadInputFile, RefusesDevicesDirectoriesMissingAndOverlongFiles) {
  test::TempDir dir;
  EXPECT_NE(error_of("/dev/zero").find("/dev/zero: not a regular file"), std::string::npos);
  EXPECT_NE(error_of(dir.path()).find("is a directory"), std::string::npos);
  EXPECT_NE(error_of(dir / "missing").find("cannot open file"), std::string::npos);
  const auto f = dir.write("b.txt", std::string(3 << 20, 'y'));
  EXPECT_NE(error_of(f, 2 << 20).find("longer than 2 MiB"), std::string::npos);
  EXPECT_EQ(error_of(f, 3 << 20), "");
}

}  // namespace
}  // namespace crowddb

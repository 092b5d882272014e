// The program's operator new (util/huge_page_new.cpp, linked into this test executable as into
// the crowddb executable): large blocks start at a 2 MiB boundary and, where the kernel offers
// transparent huge pages, are eligible for them; small ones are malloc's.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;

bool wanted() {
  const char* v = std::getenv("CROWDDB_HUGE_PAGES");
  return !(v && std::string(v) == "0");
}

// The kernel's transparent huge page setting: "always", "madvise" or "never" (empty: none).
std::string thp_setting() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto a = all.find('['), b = all.find(']');
  return a != std::string::npos && b != std::string::npos ? all.substr(a + 1, b - a - 1) : "";
}

// smaps' THPeligible for the mapping that holds address p (-1: not found).
int thp_eligible(const void* p) {
  std::ifstream in("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0) return std::stoi(line.substr(12));
  }
  return -1;
}

TEST(HugePageNew, LargeBlocksStartAtAHugePageAndSmallOnesAreMallocs) {
  if (!wanted()) GTEST_SKIP() << "CROWDDB_HUGE_PAGES=0";
  for (std::size_t n : {std::size_t{4} << 20, (std::size_t{5} << 20) + 3, std::size_t{64} << 20}) {
    std::unique_ptr<char[]> block(new char[n]);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(block.get()) % kHugePage, 0u) << n;
    block[0] = 1;
    block[n - 1] = 2;  // the whole block is there
    EXPECT_EQ(block[0] + block[n - 1], 3);
  }
  std::vector<double> column(1 << 20);  // 8 MiB through std::allocator
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(column.data()) % kHugePage, 0u);
  // A small block is malloc's: aligned as malloc aligns, not to a huge page (of many, at least
  // one is not: malloc packs them).
  std::vector<std::unique_ptr<int>> small;
  bool any_unaligned = false;
  for (int k = 0; k < 16; ++k) {
    small.push_back(std::make_unique<int>(k));
    any_unaligned |= reinterpret_cast<std::uintptr_t>(small.back().get()) % kHugePage != 0;
  }
  EXPECT_TRUE(any_unaligned);
}

TEST(HugePageNew, LargeBlocksAreEligibleWhereTheKernelOffersHugePages) {
  const std::string setting = thp_setting();
  if (!wanted() || (setting != "madvise" && setting != "always"))
    GTEST_SKIP() << "transparent huge pages: '" << setting << "'";
  std::vector<double> column(std::size_t{4} << 20);  // 32 MiB
  column[0] = 1;
  EXPECT_EQ(thp_eligible(column.data()), 1);
}

}  // namespace

// The program's operator new (util/huge_page_new.cpp, linked into this test executable as into
// the crowddb executable, except under the sanitizers): large blocks start at a 2 MiB boundary,
// in a mapping of their own (not the heap's) and, where the kernel offers transparent huge
// pages, are eligible for them; small ones are malloc's.
#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;

// Why the replacement is not in use here, or empty.
std::string not_in_use() {
#ifdef CROWDDB_NO_HUGE_PAGE_NEW
  return "not linked under the sanitizers";
#else
  const char* v = std::getenv("CROWDDB_HUGE_PAGES");
  return v && std::string(v) == "0" ? "CROWDDB_HUGE_PAGES=0" : "";
#endif
}

// The kernel's transparent huge page setting: "always", "madvise" or "never" (empty: none).
std::string thp_setting() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto a = all.find('['), b = all.find(']');
  return a != std::string::npos && b != std::string::npos ? all.substr(a + 1, b - a - 1) : "";
}

// The smaps entry of the mapping that holds address p: its header line and its THPeligible
// value (-1: the kernel reports none). False when no mapping holds p.
bool mapping_of(const void* p, std::string& header, int& eligible) {
  std::ifstream in("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false, found = false;
  eligible = -1;
  for (std::string line; std::getline(in, line);) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      if (found) break;  // the next mapping
      inside = lo <= at && at < hi;
      if (inside) {
        found = true;
        header = line;
      }
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0) eligible = std::stoi(line.substr(12));
  }
  return found;
}

TEST(HugePageNew, LargeBlocksStartAtAHugePageInAMappingOfTheirOwn) {
  if (const std::string why = not_in_use(); !why.empty()) GTEST_SKIP() << why;
  for (std::size_t n : {std::size_t{4} << 20, (std::size_t{5} << 20) + 3, std::size_t{64} << 20}) {
    std::unique_ptr<char[]> block(new char[n]);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(block.get()) % kHugePage, 0u) << n;
    block[0] = 1;
    block[n - 1] = 2;  // the whole block is there
    EXPECT_EQ(block[0] + block[n - 1], 3);
  }
  {  // (glibc would raise its threshold for a mapping of its own to this block's size on free)
    std::unique_ptr<char[]> freed(new char[std::size_t{12} << 20]);
    freed[0] = 1;
  }
  std::vector<double> column(1 << 20);  // 8 MiB through std::allocator
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(column.data()) % kHugePage, 0u);
  // In a mapping of its own, not the heap's (malloc's threshold fixed at 4 MiB): marks on the
  // heap would outlive the block and keep whole huge pages for the small blocks after it.
  std::string header;
  int eligible = 0;
  ASSERT_TRUE(mapping_of(column.data(), header, eligible));
  EXPECT_EQ(header.find("[heap]"), std::string::npos) << header;
}

TEST(HugePageNew, LargeBlocksAreEligibleWhereTheKernelOffersHugePages) {
  if (const std::string why = not_in_use(); !why.empty()) GTEST_SKIP() << why;
  const std::string setting = thp_setting();
  if (setting != "madvise" && setting != "always")
    GTEST_SKIP() << "transparent huge pages: '" << setting << "'";
  std::vector<double> column(std::size_t{4} << 20);  // 32 MiB
  column[0] = 1;
  std::string header;
  int eligible = 0;
  ASSERT_TRUE(mapping_of(column.data(), header, eligible));
  if (eligible < 0) GTEST_SKIP() << "this kernel's smaps has no THPeligible";
  EXPECT_EQ(eligible, 1) << header;
}

// Blocks below the 4 MiB of a mapping of their own come from the heap, and a heap's freed top is
// kept up to 8 MiB (the trim threshold glibc's own rule would have set, had the mmap threshold not
// been fixed): the next tick's blocks find those pages mapped instead of faulting them in again.
TEST(HugePageNew, FreedHeapTopIsKeptForTheNextBlocks) {
  if (const std::string why = not_in_use(); !why.empty()) GTEST_SKIP() << why;
  std::vector<std::unique_ptr<char[]>> blocks;
  blocks.reserve(3);  // (allocated now: nothing but the blocks comes after the trim)
  malloc_trim(0);     // the heap's top as small as it gets
  for (int b = 0; b < 3; ++b) {
    blocks.emplace_back(new char[std::size_t{1} << 20]);
    std::memset(blocks.back().get(), 1, std::size_t{1} << 20);
  }
  const std::size_t held = mallinfo2().arena;
  blocks.clear();
  EXPECT_EQ(mallinfo2().arena, held) << "the heap gave back its freed top";
}

// The nothrow forms keep the standard library's definitions, which pair with the replaced ones
// (libstdc++'s nothrow new calls the replaced new); the aligned forms are replaced too.
TEST(HugePageNew, NothrowAndAlignedFormsPairWithTheReplacedOnes) {
  struct alignas(64) Wide {
    double v[8];
  };
  struct alignas(4096) Page {
    char bytes[4096];
  };
  for (std::size_t n : {std::size_t{64}, std::size_t{8} << 20}) {
    char* p = new (std::nothrow) char[n];
    ASSERT_NE(p, nullptr);
    p[n - 1] = 1;
    delete[] p;
    auto wide = std::make_unique<Wide[]>(n / sizeof(Wide) + 1);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(wide.get()) % 64, 0u);
    Wide* one = new (std::nothrow) Wide;
    ASSERT_NE(one, nullptr);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(one) % 64, 0u);
    delete one;
    std::vector<Page> pages(n / sizeof(Page) + 1);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pages.data()) % 4096, 0u);
    pages.back().bytes[4095] = 1;
  }
}

// An over-aligned column (a record a cache line wide, as orca's per-row records) goes through the
// aligned new: large, it starts at a huge page in a mapping of its own and is eligible for them.
TEST(HugePageNew, LargeAlignedBlocksToo) {
  if (const std::string why = not_in_use(); !why.empty()) GTEST_SKIP() << why;
  struct alignas(64) Record {
    double v[8];
  };
  std::vector<Record> records(std::size_t{1} << 17);  // 8 MiB
  records[0].v[0] = 1;
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(records.data()) % kHugePage, 0u);
  std::string header;
  int eligible = 0;
  ASSERT_TRUE(mapping_of(records.data(), header, eligible));
  EXPECT_EQ(header.find("[heap]"), std::string::npos) << header;
  const std::string setting = thp_setting();
  if (eligible >= 0 && (setting == "madvise" || setting == "always")) {
    EXPECT_EQ(eligible, 1) << header;
  }
}

// The aligned forms' edges, as libstdc++'s own: a zero-size request is a distinct block, a size
// that wraps round when rounded up throws bad_alloc (not a small block), an alignment above a
// huge page is kept, and one that is not a power of two throws.
TEST(HugePageNew, AlignedFormsAtTheirEdges) {
#ifdef CROWDDB_NO_HUGE_PAGE_NEW
  GTEST_SKIP() << "not linked under the sanitizers (their runtime aborts on the huge request)";
#else
  void* a = ::operator new (0, std::align_val_t{64});
  void* b = ::operator new (0, std::align_val_t{64});
  EXPECT_NE(a, nullptr);
  EXPECT_NE(a, b);
  ::operator delete (a, std::align_val_t{64});
  ::operator delete (b, std::align_val_t{64});
  // (Sizes and alignments through a volatile: the compiler would warn of a size it can see.)
  volatile std::size_t wraps = SIZE_MAX - 8, odd = 48;
  const auto take = [](std::size_t n, std::size_t align, bool array) {
    if (array) {
      ::operator delete[](::operator new[](n, std::align_val_t{align}), std::align_val_t{align});
    } else {
      ::operator delete (::operator new (n, std::align_val_t{align}), std::align_val_t{align});
    }
  };
  EXPECT_THROW(take(wraps, 64, false), std::bad_alloc);
  EXPECT_THROW(take(wraps, 4096, true), std::bad_alloc);
  EXPECT_EQ(::operator new (wraps, std::align_val_t{64}, std::nothrow), nullptr);
  EXPECT_THROW(take(64, odd, false), std::bad_alloc);
  const std::size_t big = std::size_t{4} << 20;
  void* c = ::operator new (std::size_t{8} << 20, std::align_val_t{big});
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(c) % big, 0u);
  static_cast<char*>(c)[(std::size_t{8} << 20) - 1] = 1;
  ::operator delete (c, std::size_t{8} << 20, std::align_val_t{big});
#endif
}

}  // namespace

// The program's operator new, for the crowddb executable, tick_speed, rvo2_side_by_side and
// crowddb_tests (never the library: a library must not replace its users' allocator; nor under
// the sanitizers, whose runtime keeps its own to check that news and deletes pair up). Blocks of 4
// MiB and more start at a 2 MiB boundary, are rounded up to a multiple of it and are marked for
// transparent huge pages (madvise MADV_HUGEPAGE), so that the kernel maps them 2 MiB at a time
// where it can; the rest is plain malloc. At 10^6 agents the columns, lists and buffers are tens of
// such blocks, and their first touch took 257,000 page faults of 4 KiB, about 1.8 s of system time
// on the 2-core VM the benchmarks run on (a run of one tick, loading included: 4.5-5.5 s); now
// 56,000 (2.8-3.8 s).
//
// malloc's threshold for giving a block a mapping of its own is fixed at the same 4 MiB (glibc
// otherwise raises it to the size of each such block freed, up to 32 MiB, and serves later ones
// from its heap). Marked blocks thus nearly always have their own mapping, returned on free (a
// free stretch of the heap large enough, left by many small blocks, could still serve one): carved
// out of the heap instead, the marks stayed on the heap's pages after the blocks were freed, the
// kernel kept whole 2 MiB pages there for the small blocks that followed, and a run of 300 ticks
// at 10^6 agents peaked at 1,338 MB instead of 977.
//
// Where the system has no transparent huge pages, or has them only on request (the `madvise`
// setting, Debian's default) and this request is turned off, the blocks are 4 KiB pages as
// before, a little address space left unused before each one. CROWDDB_HUGE_PAGES=0 in the
// environment turns all of this off (read once, at start-up): with the kernel's `defrag` setting
// at `madvise` (also Debian's default), a fault in a marked block may wait for the kernel to
// compact memory when no huge page is free.
#include <malloc.h>
#include <sys/mman.h>

#include <bit>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kLargeBlock = std::size_t{4} << 20;

bool huge_pages_wanted() {
  static const bool wanted = [] {
    const char* v = std::getenv("CROWDDB_HUGE_PAGES");
    const bool on = !(v && std::strcmp(v, "0") == 0);
#ifdef MADV_HUGEPAGE
    if (on) {
      mallopt(M_MMAP_THRESHOLD, static_cast<int>(kLargeBlock));
      // Fixing the threshold also fixes glibc's trim threshold at its 128 KiB default (the
      // dynamic rule would have made it twice the mmap threshold): every free that left more
      // than that at the top of a heap gave it back, and the next tick's blocks faulted it in
      // again, 4 KiB at a time (~275 faults a tick at 10^6 agents, ~50 with the thesis model at
      // 2*10^4). The dynamic rule's value, kept: none after the first ticks.
      mallopt(M_TRIM_THRESHOLD, static_cast<int>(2 * kLargeBlock));
    }
#endif
    return on;
  }();
  return wanted;
}

// At start-up (or at the first large block, should another file's start-up make one first).
[[maybe_unused]] const bool kDecided = huge_pages_wanted();

// A block of n bytes aligned to `align` (a power of two), or null: a large one aligned to a huge
// page at least and marked, a small one of the usual alignment from malloc, the others from
// aligned_alloc (one rounding and one wrap check for both kinds).
void* try_allocate(std::size_t n, std::size_t align) {
  bool huge = false;
#ifdef MADV_HUGEPAGE
  huge = n >= kLargeBlock && huge_pages_wanted();
#endif
  if (huge && align < kHugePage) align = kHugePage;
  if (!huge && align <= alignof(std::max_align_t)) return std::malloc(n ? n : 1);
  const std::size_t rounded = (n + align - 1) & ~(align - 1);  // (C11 asks for a multiple)
  if (rounded < n) return nullptr;                             // the size wrapped round
  void* p = std::aligned_alloc(align, rounded ? rounded : align);
#ifdef MADV_HUGEPAGE
  if (p && huge) madvise(p, rounded, MADV_HUGEPAGE);  // (a refusal leaves 4 KiB pages)
#endif
  return p;
}

// As the standard asks: on failure the new-handler, if any, then another try.
void* allocate(std::size_t n, std::size_t align = alignof(std::max_align_t)) {
  for (;;) {
    if (void* p = try_allocate(n, align)) return p;
    const std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

// An alignment other than a power of two is undefined behaviour; libstdc++ throws bad_alloc.
void* allocate_aligned(std::size_t n, std::align_val_t al) {
  const auto align = static_cast<std::size_t>(al);
  if (!std::has_single_bit(align)) throw std::bad_alloc();
  return allocate(n, align);
}

}  // namespace

// Every form the library allocates with, the aligned ones included (an alignas(64) column of
// 10^6 rows, 64 MB, went to libstdc++'s aligned new and 16,000 faults of 4 KiB on the first
// tick). The nothrow forms keep the standard library's definitions, which call these.
void* operator new(std::size_t n) {
  return allocate(n);
}
void* operator new[](std::size_t n) {
  return allocate(n);
}
void* operator new(std::size_t n, std::align_val_t al) {
  return allocate_aligned(n, al);
}
void* operator new[](std::size_t n, std::align_val_t al) {
  return allocate_aligned(n, al);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

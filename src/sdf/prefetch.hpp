// A prefetch hint, for loops that probe large tables at random (graph building, readers). On
// x86-64 as inline assembly: GCC 12 silently dropped __builtin_prefetch from some loops (seen in
// the disassembly).
#pragma once

namespace sdf::detail {

inline void prefetch(const void* p) {
#if defined(__x86_64__)
  asm volatile("prefetcht0 (%0)" : : "r"(p));
#else
  __builtin_prefetch(p);  // NOLINT
#endif
}

}  // namespace sdf::detail

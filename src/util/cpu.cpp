#include "util/cpu.hpp"

namespace crowddb {

bool cpu_has_avx2() {
#if defined(__AVX2__)
  return true;  // a build for a machine that has it
#elif defined(__x86_64__) || defined(__i386__)
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
#else
  return false;
#endif
}

}  // namespace crowddb

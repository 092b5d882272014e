// What the CPU running this process can do, asked once.
#pragma once

namespace crowddb {

// Whether the CPU runs AVX2 and the OS saves its registers (libgcc's CPU model checks both): the
// run-time choice of the lanes built with -mavx2 beside a default (x86-64, SSE2) build. True in a
// build whose own instruction set has AVX2; false off x86-64.
bool cpu_has_avx2();

}  // namespace crowddb

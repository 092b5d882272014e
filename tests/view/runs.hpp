// A shipped bottleneck run of `ticks` ticks written into a test's folder (the view tests' input).
#pragma once

#include <gtest/gtest.h>

#include "support/cli.hpp"

namespace crowddb::test {

inline std::filesystem::path bottleneck_run(const TempDir& dir, int ticks) {
  const auto out = dir / "bn.sqlite";
  const CliResult r = run_cli("run " + source_path("scenarios/bottleneck.json") + " --ticks " +
                                  std::to_string(ticks) + " --quiet --out " + out.string(),
                              dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return out;
}

}  // namespace crowddb::test

// Thousands of random graphs (opt-in, label `slow`): the numbers in docs/sdf.md come from
// `sdfsched claims --graphs 500 --seed 1`; this checks the invariants on a larger sweep.
#include <gtest/gtest.h>

#include "sdf/claims.hpp"

namespace sdf {
namespace {

TEST(ClaimsSlow, TwentyThousandGraphs) {
  claims::Options o;
  o.graphs_per_class = 1000;
  o.seed = 2;
  o.max_actors = 14;
  const claims::Report r = claims::run(o);
  for (const claims::ClassStats& c : r.classes) {
    EXPECT_EQ(c.graphs, 1000u) << c.name;
    EXPECT_EQ(c.bounded.returns, c.graphs) << c.name;
    for (const claims::PolicyStats* s : {&c.online, &c.online_one, &c.bounded})
      EXPECT_EQ(s->checker_failures, 0u) << c.name;
  }
  EXPECT_EQ(r.counterexamples.count("bounded-invalid"), 0u);
}

}  // namespace
}  // namespace sdf

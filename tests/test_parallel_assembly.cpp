// Parallel assembly: the components of a batch are evaluated on several threads and scattered
// in component order by one, so a run gives the same numbers bit for bit on 1 and 2 threads.
#include "support.hpp"

#include <gtest/gtest.h>
#include <omp.h>

namespace mpx::test {
namespace {

History runOnThreads(const Model& model, Scheme scheme, int threads) {
  omp_set_num_threads(threads);
  History h = run(model, scheme, 0.1, 0.5);
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_FALSE(h.summary.failed) << h.summary.failure;
  return h;
}

// the viscoelastic L-block (hex8 solid elements, inertia, a Maxwell branch per point and a
// hat load): every state of every step, and the energy flows, agree exactly
TEST(ParallelAssembly, OneAndTwoThreadsGiveTheSameRunBitForBit) {
  const CompiledScene scene = loadScene(scenePath("lblock_viscoelastic.xml"));
  ASSERT_GE(scene.model->components().size(), 64u) << "too few components to be assembled in parallel";
  for (Scheme scheme : {Scheme::Eem, Scheme::Midpoint}) {
    const History one = runOnThreads(*scene.model, scheme, 1), two = runOnThreads(*scene.model, scheme, 2);
    ASSERT_EQ(one.states.size(), two.states.size());
    for (std::size_t n = 0; n < one.states.size(); ++n) {
      EXPECT_TRUE((one.states[n].array() == two.states[n].array()).all()) << schemeName(scheme) << ", step " << n;
      EXPECT_EQ(one.dissipated[n], two.dissipated[n]);
      EXPECT_EQ(one.externalWork[n], two.externalWork[n]);
    }
  }
}

}  // namespace
}  // namespace mpx::test

// The step loop allocates nothing: this executable replaces the C allocator (which operator
// new, Eigen and KLU all go through) by glibc's own entry points plus a counter, and counts
// the calls made during Integrator::advance and Model::measure once the solver is warmed up.
#include "support.hpp"

#include <gtest/gtest.h>

#include <malloc.h>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <string>
#include <tuple>

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void __libc_free(void* pointer);
void* __libc_memalign(std::size_t alignment, std::size_t size);
}

namespace {

std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
std::atomic<long> releases{0};

void countAllocation() {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

extern "C" {

void* malloc(std::size_t size) noexcept {
  countAllocation();
  return __libc_malloc(size);
}

void* calloc(std::size_t count, std::size_t size) noexcept {
  countAllocation();
  return __libc_calloc(count, size);
}

void* realloc(void* pointer, std::size_t size) noexcept {
  countAllocation();
  return __libc_realloc(pointer, size);
}

void free(void* pointer) noexcept {
  if (pointer && counting.load(std::memory_order_relaxed)) releases.fetch_add(1, std::memory_order_relaxed);
  __libc_free(pointer);
}

void* memalign(std::size_t alignment, std::size_t size) noexcept {
  countAllocation();
  return __libc_memalign(alignment, size);
}

void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  countAllocation();
  return __libc_memalign(alignment, size);
}

int posix_memalign(void** result, std::size_t alignment, std::size_t size) noexcept {
  countAllocation();
  void* pointer = __libc_memalign(alignment, size);
  if (!pointer) return ENOMEM;
  *result = pointer;
  return 0;
}

}  // extern "C"

namespace mpx {
namespace {

using test::schemeName;

// Allocator calls (allocations, releases) made by `work`.
struct HeapTraffic {
  long allocations = 0;
  long releases = 0;
};

template <class Work>
HeapTraffic countHeapTraffic(const Work& work) {
  allocations = 0;
  releases = 0;
  counting = true;
  work();
  counting = false;
  return {allocations.load(), releases.load()};
}

// Warm up an integrator on a scene (the first KLU factorisation allocates its factors), then
// count the heap traffic of the next 200 steps and measurements.
struct SteppingResult {
  HeapTraffic traffic;
  bool allConverged = true;
};

SteppingResult countStepLoopTraffic(const std::string& sceneFile, Scheme scheme) {
  const CompiledScene scene = loadScene(test::scenePath(sceneFile));
  const Model& model = *scene.model;
  const double dt = scene.settings.dt;
  Integrator integrator(model, scheme, scene.settings.newton);
  Eigen::VectorXd z = model.initialState(), zNew(z.size());
  Measures measures;
  double t = 0.0;
  SteppingResult result;
  auto step = [&] {
    result.allConverged &= integrator.advance(z, t, dt, zNew).converged;
    model.measure(zNew, measures);
    z.swap(zNew);
    t += dt;
  };
  for (int warmUp = 0; warmUp < 3; ++warmUp) step();
  result.traffic = countHeapTraffic([&] {
    for (int n = 0; n < 200; ++n) step();
  });
  return result;
}

class StepLoopAllocation : public testing::TestWithParam<std::tuple<std::string, Scheme>> {};

// Zero allocations and releases over 200 steps of every scheme on the thermo-mechanical
// benchmark scenes (with heat links, internal variables and both thermal variables), a rigid
// multibody scene, an FE solid (viscoelastic cells, joints to a body, gravity) and a thermal
// one linked to a reservoir on joints (temperatures, conduction, viscous heating), and a thermal
// block with every boundary (Dirichlet, flux, convection, link).
TEST_P(StepLoopAllocation, AllocatesNothingAfterWarmUp) {
  const auto& [sceneFile, scheme] = GetParam();
  const SteppingResult result = countStepLoopTraffic(sceneFile, scheme);
  EXPECT_TRUE(result.allConverged);
  EXPECT_EQ(result.traffic.allocations, 0);
  EXPECT_EQ(result.traffic.releases, 0);
}

// "<scene>_<scheme>"
std::string caseName(const testing::TestParamInfo<StepLoopAllocation::ParamType>& info) {
  std::string scene = std::get<0>(info.param);
  scene.resize(scene.find('.'));
  return scene + "_" + schemeName(std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(
    BenchmarkScenes, StepLoopAllocation,
    testing::Combine(testing::Values("two_thermo_springs.xml", "thermo_visco_elastic.xml", "damped_double_pendulum.xml",
                                     "flexible_pendulum.xml", "cooled_flexible_pendulum.xml", "thermal_block.xml"),
                     testing::Values(Scheme::Eem, Scheme::Midpoint, Scheme::Trapezoidal, Scheme::Eem4)),
    caseName);

// The counter sees allocations made inside the libraries: measuring into a fresh Measures
// sizes its node temperatures (operator new in libstdc++), and a C allocation is counted.
TEST(AllocationCounter, CountsLibraryAndCAllocations) {
  const CompiledScene scene = loadScene(test::scenePath("two_thermo_springs.xml"));
  const HeapTraffic measuring = countHeapTraffic([&] {
    Measures fresh;
    scene.model->measure(scene.model->initialState(), fresh);
  });
  EXPECT_GE(measuring.allocations, 1);
  EXPECT_GE(measuring.releases, 1);

  void* volatile block = nullptr;
  const HeapTraffic cAllocation = countHeapTraffic([&] {
    block = std::malloc(64);
    std::free(block);
  });
  EXPECT_EQ(cAllocation.allocations, 1);
  EXPECT_EQ(cAllocation.releases, 1);
}

}  // namespace
}  // namespace mpx

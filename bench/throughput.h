#pragma once
// Throughput: wall microseconds per particle-step for each stage of the water step, at several sizes,
// with hand-written C++/OpenMP density and heat-conduction loops over the same sorted data as the references.
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/scene.h"

namespace thaw {

struct ThroughputOptions {
  std::vector<std::size_t> sizes = {25000, 100000, 400000};  // fluid particles
  int steps = 30;                                            // timed steps per size (after warm-up)
};

// The benchmark scene: a water block in a walled tank (a dam break) with about `fluid` particles.
Scene throughput_scene(std::size_t fluid);

Json bench_throughput(ClRuntime& cl, const ThroughputOptions& o, bool print);

}  // namespace thaw

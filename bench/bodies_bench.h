#pragma once
// Ice bodies: wall microseconds per particle (of the whole set) for one labelling of the ice particles
// and one pass of per-body sums on the device (sim/ice_bodies.h), against hand-written C++ references
// over the same sorted data: an OpenMP union-find for the labels, a plain loop in double for the sums.
#include <cstddef>

#include "sim/cl_runtime.h"
#include "sim/scene.h"

namespace thaw {

struct BodiesBenchOptions {
  std::size_t particles = 100000;  // lattice particles in all: an ice block split into 4 bodies, in water
  double radius = 1.5;             // connection radius [particle spacings]; at most the kernel support (2)
  int reps = 10;                   // timed runs of each (after one untimed); the fastest is reported
};

Json bench_bodies(ClRuntime& cl, const BodiesBenchOptions& o, bool print);

}  // namespace thaw

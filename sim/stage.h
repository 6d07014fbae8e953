#pragma once
// What the stages of a step share. A stage is a class the solver builds only when the scene needs it, from a
// StageContext; its constructor declares the particle fields it owns in the store (sim/particle_store.h) and
// builds its kernels with only the options the scene uses; it offers its limit on the time step (max_dt) and
// the state it keeps beyond its fields (save / restore) where it has any, and its passes take the views
// below. The order of the passes in a step is sim/step_plan.h's; docs/ARCHITECTURE.md lists the stages.
#include <CL/opencl.hpp>
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include "sim/cl_grid.h"
#include "sim/particle_store.h"
#include "sim/solver_constants.h"

namespace thaw {

// What the neighbour loops read, as the grid stage left it: the structure-of-arrays copy of position,
// mass and velocity (blocks of `stride` floats), the cell ranges and the grid.
struct NeighbourView {
  const cl::Buffer& soa;
  cl_uint stride = 0;
  const cl::Buffer& cell_start;
  ClGrid grid;
};

// How the particles' arrays are laid out: n particles in use of `capacity` (emitters add particles up to
// it, open sides remove them), structure-of-arrays blocks of `stride` floats, and the tiles of `tile`
// particles that per-tile reductions (time-step limits, budgets) use. Stages size their buffers by the
// capacity (max_tiles tiles) and run over n (ntiles tiles).
struct ParticleLayout {
  std::size_t n = 0, capacity = 0;
  cl_uint stride = 0, tile = 256, ntiles = 0, max_tiles = 0;

  // Uses the first n particles of the capacity.
  void use(std::size_t count) {
    n = count;
    ntiles = static_cast<cl_uint>((n + tile - 1) / tile);
  }
};

// The layout for a capacity of particles, n of them in use: about `tiles` tiles of the capacity (whole
// multiples of 256 particles). Each tile is one work-item of the per-tile passes (the sort's histogram
// and scatter, time-step limits, budgets), which walk their particles in order: a CPU wants few (about
// 32: enough to keep its cores busy, few enough that each tile's per-digit bookkeeping in the sort is
// small beside its particles), a GPU thousands (ClRuntime::layout_tiles). Lane loads
// (sim/kernels/grid_common.h) read up to 15 floats past the last particle.
inline ParticleLayout layout_for(std::size_t n, std::size_t capacity, std::size_t tiles = 32) {
  ParticleLayout l;
  l.capacity = std::max(n, capacity);
  const std::size_t per_tile = l.capacity / std::max<std::size_t>(tiles, 1);
  l.tile = static_cast<cl_uint>(std::max<std::size_t>(256, (per_tile + 255) / 256 * 256));
  l.max_tiles = static_cast<cl_uint>((l.capacity + l.tile - 1) / l.tile);
  l.stride = static_cast<cl_uint>((l.capacity + 16 + 15) / 16 * 16);
  l.use(n);
  return l;
}
inline ParticleLayout layout_for(std::size_t n) { return layout_for(n, n); }

// The handles of the core fields (core_fields() in sim/particles.h), which most stages read.
struct CoreFields {
  ParticleStore::Field position = 0, velocity = 0, density = 0, phase = 0, material = 0, id = 0;
};

// Declares the core fields in `store` and returns their handles.
inline CoreFields add_core_fields(ParticleStore& store) {
  CoreFields f;
  for (const FieldSpec& spec : core_fields()) {
    const ParticleStore::Field h = store.add(spec);
    if (spec.name == "position") f.position = h;
    if (spec.name == "velocity") f.velocity = h;
    if (spec.name == "density") f.density = h;
    if (spec.name == "phase") f.phase = h;
    if (spec.name == "material") f.material = h;
    if (spec.name == "id") f.id = h;
  }
  return f;
}

// A neighbour pass's program: the headers every one starts with (sim/kernels/: the smoothing kernel, the grid
// and its walk, the SIMD lanes and the pair geometry of walk.h), then `files`.
inline std::vector<std::string> neighbour_program(std::initializer_list<std::string> files) {
  std::vector<std::string> all = {"sph_kernel.h", "grid_common.h", "sph_lanes.h", "walk.h"};
  all.insert(all.end(), files);
  return all;
}

// What every stage is built from: the run's device, its particle store and core fields, the scene and the
// constants it implies, the kernels' build options (the SPH kernel, the equation of state, the lanes:
// program_options in sim/solver.cpp) and the particles' layout.
struct StageContext {
  ClRuntime& cl;
  ParticleStore& store;
  const CoreFields& core;
  const Scene& scene;
  const SolverConstants& k;
  const std::string& options;
  const ParticleLayout& layout;
};

}  // namespace thaw

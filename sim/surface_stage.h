#pragma once
// The surface stage: each ice and water particle's share of the surface to the air (or to empty space) it
// lies under, its outward normal and signed distance (Orthmann et al. 2013 sec. 4, eqs 2-9; the model is
// heat.exposed_area). Built by the solver only when something reads it: today the heat stage's exchange
// with the ambient air and the cone dryers (sim/heat_stage.h), and surface-active substances
// (sim/substance_stage.h). Declares "surface_area" [m^2],
// "surface_normal" (outward normal, phi [m]) and "surface_delta" [1/m], the state eq. 9 relaxes from.
#include <CL/opencl.hpp>
#include <string>

#include "sim/cl_runtime.h"
#include "sim/kernels/surface_params.h"
#include "sim/particle_store.h"
#include "sim/scene.h"
#include "sim/stage.h"

namespace thaw {

struct SolverConstants;

class SurfaceStage {
 public:
  SurfaceStage(const StageContext& c);

  ParticleStore::Field area() const { return area_; }
  ExposedArea model() const { return model_; }
  ParticleStore::Field normal() const { return normal_; }

  // The areas, normals and deltas of the particles where they are now.
  void run(const NeighbourView& nv);

 private:
  ClRuntime& cl_;
  ParticleStore& store_;
  CoreFields core_;
  const Scene& scene_;
  const ParticleLayout& layout_;
  ExposedArea model_;
  surface::SurfaceParams params_{};  // all but n, from the scene and the kernel at construction
  ParticleStore::Field area_ = 0, normal_ = 0, delta_ = 0;
  cl::Kernel k_inside_, k_delta_, k_area_, k_layer_, k_project_;
  // Padded blocks of stride floats the neighbour loops read on lanes: who is inside; orthmann2013's deltas
  // for its eq 7, or brackbill1992's outer-layer marks; and brackbill1992's layer normals, three blocks
  // (surface.cl).
  cl::Buffer inside_, delta_lanes_, layer_n_;
};

}  // namespace thaw

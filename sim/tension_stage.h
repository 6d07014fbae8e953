#pragma once
// The tension stage: interfacial tension of water (tension.model), accelerations added to the forces pass's
// before the time step is chosen, so both WCSPH and DFSPH (its predicted velocities) take them. Three models,
// selectable by name (sim/kernels/tension_<model>.cl has each one's equations, tension.cl what they share):
//   akinci2013: Akinci, Akinci & Teschner 2013, cohesion (eqs. 1, 3) and curvature (eqs. 2, 4) between
//     water particles, K_ij-corrected (eq. 5);
//   iwasaki2010: Iwasaki et al. 2010 eq. 4, an attraction k (x_j - x_i) / r^2 to water and ice neighbours
//     (solids here too);
//   brackbill1992: Brackbill, Kothe & Zemach 1992's continuum surface force sigma kappa n on the outer
//   layer's
//     particles, each with its share of the area (the layer's 2-D density) and kappa from a quadric fitted to
//     the surface points near it; sigma enters as it is, no calibration.
// The two pair-force models are calibrated from the scene's sigma [N/m]: a pair force f(r) between particles
// of number density n gives a flat surface the tension sigma = (pi n^2 / 8) int r^4 f dr (Kirkwood & Buff
// 1949, the particles taken as uniform). Water clings to solids and ice by Akinci et al. 2013's adhesion
// (eqs. 6, 7) (brackbill1992 too), Iwasaki's model by its own k_ice term, set from the contact angles: a pair
// force f_fs gives a water-solid face the work of adhesion W = (pi n_f n_s / 4) int r^4 f_fs dr, set to sigma
// (1 + cos theta) (Young-Dupre), the water's face against the solid having tension sigma in every model.
// Built only for scenes with flow and tension.model other than none.
#include <CL/opencl.hpp>
#include <string>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/kernels/tension_params.h"
#include "sim/particle_store.h"
#include "sim/scene.h"
#include "sim/stage.h"

namespace thaw {

struct SolverConstants;

// The calibration of a tension model from the scene's sigma and contact angles.
struct TensionCoefficients {
  double cohesion = 0;          // akinci2013: gamma; iwasaki2010: k_w [N m]
  std::vector<float> adhesion;  // per scene material: beta (iwasaki2010: k [N m]); 0 for fluids
  // The cohesion's pull inside bulk water, (2 pi n^2 / 3) int r^3 f dr [Pa] (the virial of the pair force
  // over uniformly spread particles): the equation of state holds it as a pressure, so it sets a floor on
  // WCSPH's stiffness (derive_constants).
  double cohesive_pressure = 0;
};
// Reads only the scene and k.support and k.rest_density.
TensionCoefficients tension_coefficients(const Scene& scene, const SolverConstants& k);

class TensionStage {
 public:
  TensionStage(const StageContext& c);

  // Adds the tension accelerations to `accel` (the forces pass's), from the densities of the last density
  // pass.
  void run(const NeighbourView& nv, const cl::Buffer& accel);
  // Where the scene's surface-active substances lower the tension (substances_lower_tension): the field of
  // each particle's sigma_i / sigma0 that the substance stage keeps. Each model scales its force by it; the
  // pair models a pair's cohesion by the mean of its two, brackbill1992 sigma kappa n, plus Marangoni's
  // stress along the surface.
  void ratio_from(ParticleStore::Field ratio) { ratio_ = ratio; }

 private:
  ClRuntime& cl_;
  ParticleStore& store_;
  CoreFields core_;
  const ParticleLayout& layout_;
  TensionModel model_;
  tension::TensionParams params_{};
  cl::Kernel k_columns_, k_normals_, k_forces_;
  cl::Kernel k_surface_, k_curvature_, k_smooth_;  // brackbill1992
  cl::Buffer adhesion_, columns_;
  bool lowered_ = false;  // THAW_TENSION_LOWERED
  ParticleStore::Field ratio_ = 0;
};

}  // namespace thaw

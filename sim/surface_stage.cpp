#include "sim/surface_stage.h"

#include <bit>
#include <cmath>
#include <limits>

#include "sim/cl_launch.h"
#include "sim/kernels/sph_kernel.h"
#include "sim/kernels/surface_params.h"
#include "sim/solver_constants.h"
#include "sim/substance_stage.h"

namespace thaw {

namespace {

// Orthmann et al. 2013 eq. 9: kappa in [0.1, 0.5] for thin sheets; the middle of that range.
constexpr float kSingularRate = 0.3f;
// Sec. 4.3 calls a neighbourhood singular below 30 neighbours, for a support that held about twice that many
// at rest; here a share of a full neighbourhood (sph::full_neighbourhood, 33.5 at H = 2 dx): 13.4, so a sheet
// one particle thick (13 within 2 dx) is singular, and about the count along a box's edge.
constexpr double kSingularShare = 0.4;
// det C / (tr C / 3)^3 of eq. 8 below this: flat. A sheet one particle thick has 0; a flat face's top layer
// about 0.5 (cubic spline, H = 2 dx).
constexpr float kMinFlatness = 0.1f;

std::uint32_t nan_bits() { return std::bit_cast<std::uint32_t>(std::numeric_limits<float>::quiet_NaN()); }

}  // namespace

SurfaceStage::SurfaceStage(const StageContext& c)
    : cl_(c.cl),
      store_(c.store),
      core_(c.core),
      scene_(c.scene),
      layout_(c.layout),
      // heat.exposed_area's model; iwasaki2010 needs no stage, and surface-active substances then take the
      // default's areas.
      model_(c.scene.heat.exposed_area == ExposedArea::Orthmann2013 ? ExposedArea::Orthmann2013
                                                                    : ExposedArea::Brackbill1992) {
  // Saved where the areas outlive a step (heat.area_interval > 1 in a flowing scene), so a resumed run
  // reads the areas the straight run had.
  const bool outlive = c.scene.solver.flow && c.scene.heat.area_interval > 1;
  area_ = c.store.add({"surface_area", FieldType::Float32, 1, outlive, true});
  // The normals too where surface-active substances read them (their points on the surface).
  normal_ = c.store.add(
      {"surface_normal", FieldType::Float32, 4, outlive && substances_need_surface(c.scene), true});
  // Saved, so a resumed run relaxes from where it stopped; NaN (none yet) where a state has none.
  delta_ = c.store.add({"surface_delta", FieldType::Float32, 1, true, false, nan_bits()});

  const bool wendland = c.scene.solver.kernel == KernelFunction::WendlandC2;
  auto grad = wendland ? sph::wendland_c2_grad_factor : sph::cubic_spline_grad_factor;

  std::string opts = c.options;
  opts += model_ == ExposedArea::Orthmann2013 ? " -DTHAW_AREA_ORTHMANN2013" : " -DTHAW_AREA_BRACKBILL1992";
  for (int a = 0; a < 3; ++a)
    if (c.scene.solver.periodic[static_cast<std::size_t>(a)])
      opts += std::string(" -DTHAW_PERIODIC_") + "XYZ"[a];
  const auto program =
      c.cl.build(neighbour_program({"wrapped_walk.h", "surface_params.h", "surface.cl"}), opts);
  k_inside_ = cl::Kernel(program, "surface_inside");
  k_delta_ = cl::Kernel(program, "surface_delta");
  const std::size_t padded = std::size_t(c.layout.stride) * 4;
  inside_ = cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, padded);
  if (model_ == ExposedArea::Orthmann2013) {
    k_area_ = cl::Kernel(program, "surface_area");
  } else {
    k_layer_ = cl::Kernel(program, "surface_layer");
    k_project_ = cl::Kernel(program, "surface_project");
    layer_n_ =
        cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, padded * 3);  // the layer's normals: x, y, z blocks
    c.cl.queue().enqueueFillBuffer(layer_n_, 0.0f, 0, padded * 3);
  }
  delta_lanes_ = cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, padded);
  c.cl.queue().enqueueFillBuffer(delta_lanes_, 0.0f, 0, padded);

  const double dx = c.scene.spacing;
  params_.support = c.k.support;
  params_.volume = static_cast<float>(dx * dx * dx);
  params_.radius = static_cast<float>(0.5 * dx);
  params_.spacing = static_cast<float>(dx);
  float* period[3] = {&params_.period_x, &params_.period_y, &params_.period_z};
  for (int a = 0; a < 3; ++a)
    if (c.scene.solver.periodic[static_cast<std::size_t>(a)])
      *period[a] = static_cast<float>(c.scene.domain.max[a] - c.scene.domain.min[a]);
  params_.colour_scale = static_cast<float>(1.0 / sph::flat_face_colour_gradient(grad, dx, c.k.support));
  params_.rim_scale = static_cast<float>(1.0 / sph::flat_edge_colour_gradient(grad, dx, c.k.support));
  params_.min_neighbours = static_cast<float>(kSingularShare * sph::full_neighbourhood(dx, c.k.support));
  params_.min_flatness = kMinFlatness;
  params_.rate = kSingularRate;
  // A neighbourhood with 0.9 of a resting lattice's colour lacks too few particles to be sparse or flat.
  params_.full_colour = static_cast<float>(
      0.9 * sph::lattice_sum(wendland ? sph::wendland_c2_w : sph::cubic_spline_w, dx, c.k.support));
}

void SurfaceStage::run(const NeighbourView& nv) {
  if (layout_.n == 0) return;
  surface::SurfaceParams P = params_;
  P.n = static_cast<cl_uint>(layout_.n);
  auto& q = cl_.queue();
  set_args(k_inside_, store_[core_.phase], inside_, P.n, nv.stride);
  launch(q, k_inside_, nv.stride);
  // orthmann2013's surface_delta neither reads nor writes its last argument, the layer's normals
  const bool orthmann = model_ == ExposedArea::Orthmann2013;
  set_args(k_delta_, store_[core_.position], store_[core_.phase], nv.soa, inside_, nv.cell_start, nv.grid, P,
           nv.stride, store_[normal_], store_[delta_], delta_lanes_, store_[area_],
           orthmann ? delta_lanes_ : layer_n_);
  launch(q, k_delta_, layout_.n);
  if (orthmann) {
    set_args(k_area_, store_[core_.position], store_[core_.phase], nv.soa, inside_, nv.cell_start, nv.grid, P,
             nv.stride, delta_lanes_, store_[area_]);
    launch(q, k_area_, layout_.n);
  } else {
    // delta_lanes_ holds the outer layer's marks here
    set_args(k_layer_, store_[core_.position], store_[core_.phase], nv.soa, inside_, nv.cell_start, nv.grid,
             P, nv.stride, store_[normal_], delta_lanes_, layer_n_, store_[area_]);
    launch(q, k_layer_, layout_.n);
    set_args(k_project_, store_[core_.position], store_[core_.phase], nv.soa, nv.cell_start, nv.grid, P,
             nv.stride, store_[normal_], delta_lanes_, layer_n_, store_[delta_], store_[area_]);
    launch(q, k_project_, layout_.n);
  }
}

}  // namespace thaw

#include "sim/tension_stage.h"

#include <cctype>
#include <cmath>
#include <numbers>

#include "sim/cl_launch.h"
#include "sim/solver_constants.h"
#include "sim/substance_stage.h"

namespace thaw {

namespace {

constexpr std::size_t kColumns = 7;  // tension.cl's column block: W, R, V, B, NX, NY, NZ
// brackbill1992's block adds A, K, K2, OK, BAND.
constexpr std::size_t kCsfColumns = 12;

// int_0^1 q^p f(q) dq by Simpson's rule on 2000 intervals per half (the shapes have a kink at q = 1/2).
double moment(double (*f)(double), int p) {
  const int n = 2000;
  double sum = 0;
  for (double a : {0.0, 0.5}) {
    const double h = 0.5 / n;
    for (int i = 0; i <= n; ++i) {
      const double q = a + i * h;
      // The shapes' value just inside each half, so the kink at 1/2 is taken from the right side.
      const double x = i == 0 && a > 0 ? q + 1e-12 : (i == n && a == 0 ? q - 1e-12 : q);
      const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      sum += w * std::pow(x, p) * f(x) * h / 3;
    }
  }
  return sum;
}

double deg(double angle) { return angle * std::numbers::pi / 180.0; }

// brackbill1992: sum over a square lattice of spacing dx of the 2-D cubic spline on support H (q = r / H:
// 6 q^3 - 6 q^2 + 1 to 1/2, 2 (1 - q)^3 to 1; unnormalised, as tension.cl sums it), the outer layer's points
// per spacing squared on a flat face of the lattice.
double layer_density(double dx, double H) {
  const int m = static_cast<int>(std::ceil(H / dx));
  double sum = 0;
  for (int a = -m; a <= m; ++a)
    for (int b = -m; b <= m; ++b) {
      const double q = dx * std::sqrt(double(a * a + b * b)) / H;
      sum += q < 0.5 ? 6 * q * q * (q - 1) + 1 : (q < 1 ? 2 * (1 - q) * (1 - q) * (1 - q) : 0.0);
    }
  return sum;
}

}  // namespace

TensionCoefficients tension_coefficients(const Scene& scene, const SolverConstants& k) {
  const TensionSettings& t = scene.tension;
  const double H = k.support, rho0 = k.rest_density, dx = scene.spacing, pi = std::numbers::pi;
  const double sigma = t.coefficient;
  TensionCoefficients out;
  out.adhesion.assign(scene.materials.size(), 0.0f);
  // Per unit of the adhesion weight: the work of adhesion the pair force gives a water-solid face.
  // f(r) = beta m_i Psi_b A(r), n_f m_i = rho0 = n_s Psi_b: W = (pi / 4) rho0^2 beta int r^4 A.
  double adhesion_per_weight =
      pi / 4.0 * rho0 * rho0 * 0.007 * H * H * moment(tension::akinci_adhesion_shape, 4);
  if (t.model == TensionModel::Akinci2013) {
    // f(r) = gamma m_i m_j C(r): sigma = (pi / 8) rho0^2 gamma int r^4 C, C = 32 / (pi H^3) c(r / H).
    const double c4 = 32.0 / pi * H * H * moment(tension::akinci_cohesion_shape, 4);
    out.cohesion = 8.0 * sigma / (pi * rho0 * rho0 * c4);
    out.cohesive_pressure = 2.0 * pi / 3.0 * rho0 * rho0 * out.cohesion * 32.0 / pi * H *
                            moment(tension::akinci_cohesion_shape, 3);
  } else if (t.model == TensionModel::Iwasaki2010) {
    // f(r) = k / r between particles of number density 1 / dx^3: sigma = pi n^2 k H^4 / 32, and
    // W = (pi / 4) n^2 k H^4 / 4 against a solid.
    const double n = 1.0 / (dx * dx * dx);
    out.cohesion = 32.0 * sigma / (pi * n * n * std::pow(H, 4));
    out.cohesive_pressure = 2.0 * pi / 3.0 * n * n * out.cohesion * std::pow(H, 3) / 3.0;
    adhesion_per_weight = pi / 4.0 * n * n * std::pow(H, 4) / 4.0;
  }
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const MaterialKind kind = scene.materials[m].kind;
    if (kind != MaterialKind::Solid && kind != MaterialKind::Ice) continue;
    const double angle = kind == MaterialKind::Ice ? t.ice_contact_angle : t.solid_contact_angle;
    out.adhesion[m] = static_cast<float>(sigma * (1.0 + std::cos(deg(angle))) / adhesion_per_weight);
  }
  return out;
}

TensionStage::TensionStage(const StageContext& c)
    : cl_(c.cl), store_(c.store), core_(c.core), layout_(c.layout), model_(c.scene.tension.model) {
  std::string opts = c.options + " -DTHAW_TENSION_";
  for (const char* ch = name(model_); *ch; ++ch) opts += static_cast<char>(std::toupper(*ch));
  const bool csf = model_ == TensionModel::Brackbill1992;
  const double dx = c.scene.spacing;
  // Cells are the support wide (grid_common.h): the fit's patch reaches this many of them.
  if (csf)
    opts += " -DTHAW_FIT_REACH=" +
            std::to_string(static_cast<int>(std::ceil(tension::kFitRadius * dx / c.k.support)));
  // Adhesion only where water can meet solids or ice.
  if (!c.scene.walls.empty() || !c.scene.solids.empty() || !c.scene.ice.empty())
    opts += " -DTHAW_TENSION_ADHESION";
  lowered_ = substances_lower_tension(c.scene);
  if (lowered_) opts += " -DTHAW_TENSION_LOWERED";
  const std::string model_file = std::string("tension_") + name(model_) + ".cl";
  const auto program = c.cl.build(neighbour_program({"tension_params.h", "tension.cl", model_file}), opts);
  k_columns_ = cl::Kernel(program, "tension_columns");
  if (model_ == TensionModel::Akinci2013) k_normals_ = cl::Kernel(program, "tension_normals");
  if (csf) {
    k_surface_ = cl::Kernel(program, "tension_surface");
    k_curvature_ = cl::Kernel(program, "tension_curvature");
    k_smooth_ = cl::Kernel(program, "tension_smooth");
  }
  k_forces_ = cl::Kernel(program, "tension_forces");

  const TensionCoefficients tc = tension_coefficients(c.scene, c.k);
  params_.support = c.k.support;
  params_.rest_density = c.k.rest_density;
  params_.cohesion = static_cast<float>(tc.cohesion);
  params_.curvature = c.scene.tension.curvature ? 1.0f : 0.0f;
  params_.stride = c.layout.stride;
  if (csf) {
    params_.sigma = static_cast<float>(c.scene.tension.coefficient);
    params_.volume = static_cast<float>(dx * dx * dx);
    params_.spacing = static_cast<float>(dx);
    params_.layer_area = static_cast<float>(dx * dx * layer_density(dx, c.k.support));
    params_.fit_radius = static_cast<float>(tension::kFitRadius * dx);
    params_.smooth_radius = static_cast<float>(tension::kSmoothRadius * dx);
  }
  std::vector<float> adhesion = tc.adhesion;
  if (adhesion.empty()) adhesion.push_back(0.0f);
  adhesion_ = cl::Buffer(c.cl.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                         adhesion.size() * sizeof(float), adhesion.data());
  const std::size_t bytes =
      std::size_t(c.layout.stride) * ((csf ? kCsfColumns : kColumns) + (lowered_ ? 1 : 0)) * sizeof(float);
  columns_ = cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, bytes);
  c.cl.queue().enqueueFillBuffer(columns_, 0.0f, 0, bytes);
}

void TensionStage::run(const NeighbourView& nv, const cl::Buffer& accel) {
  if (layout_.n == 0) return;
  tension::TensionParams P = params_;
  P.n = static_cast<cl_uint>(layout_.n);
  P.stride = nv.stride;
  auto& q = cl_.queue();
  set_args(k_columns_, store_[core_.phase], store_[core_.material], store_[core_.position],
           store_[core_.density], adhesion_, P, columns_, lowered_ ? store_[ratio_] : adhesion_);
  launch(q, k_columns_, nv.stride);
  if (model_ == TensionModel::Akinci2013) {
    set_args(k_normals_, store_[core_.position], store_[core_.phase], nv.soa, nv.cell_start, nv.grid, P,
             columns_);
    launch(q, k_normals_, layout_.n);
  }
  if (model_ == TensionModel::Brackbill1992) {
    set_args(k_surface_, store_[core_.position], store_[core_.phase], nv.soa, nv.cell_start, nv.grid, P,
             columns_);
    launch(q, k_surface_, layout_.n);
    set_args(k_curvature_, store_[core_.position], store_[core_.phase], nv.soa, nv.cell_start, nv.grid, P,
             columns_);
    launch(q, k_curvature_, layout_.n);
    // twice: K into K2, then K2 back into K
    for (const cl_int into_k2 : {1, 0}) {
      set_args(k_smooth_, store_[core_.position], store_[core_.phase], nv.soa, nv.cell_start, nv.grid, P,
               columns_, into_k2);
      launch(q, k_smooth_, layout_.n);
    }
  }
  set_args(k_forces_, store_[core_.position], store_[core_.phase], nv.soa, nv.cell_start, nv.grid, P,
           columns_, accel);
  launch(q, k_forces_, layout_.n);
}

}  // namespace thaw

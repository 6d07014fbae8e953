// Turning a scene into particles: fluid and ice on a lattice, solids and walls as boundary particles, each
// with the enthalpy of its initial temperature.
#include "sim/scene_sampling.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <utility>

#include "sim/emitters.h"
#include "sim/error.h"
#include "sim/geometry/voxelize.h"
#include "sim/solver_constants.h"
#include "sim/substance_stage.h"
#include "sim/thermal.h"

namespace thaw {
namespace {

using Vec3 = Eigen::Vector3d;

bool inside(const Box& b, const Vec3& p) {
  return (p.array() >= b.min.array()).all() && (p.array() <= b.max.array()).all();
}

// Lattice points min + (i + 1/2) dx filling [min, max].
template <class F>
void lattice(const Vec3& min, const Vec3& max, double dx, F&& visit) {
  const Eigen::Array3i n =
      ((max - min) / dx).array().unaryExpr([](double v) { return static_cast<int>(std::floor(v + 1e-6)); });
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) visit(Vec3(min + dx * Vec3(i + 0.5, j + 0.5, k + 0.5)));
}

// Keeps the points for which `covered` is 0, in their order.
void drop(std::vector<Vec3>& points, const std::vector<std::uint8_t>& covered) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!covered[i]) points[kept++] = points[i];
  points.resize(kept);
}

void drop_inside(std::vector<Vec3>& points, const Shape& shape) { drop(points, shape.contains(points)); }

void drop_inside(std::vector<Vec3>& points, const Solid& s) {
  if (!s.plane) return drop_inside(points, s.shape);
  std::vector<std::uint8_t> behind(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) behind[i] = (points[i] - s.point).dot(s.normal) < 0;
  drop(points, behind);
}

void drop_outside(std::vector<Vec3>& points, const Box& b) {
  std::vector<std::uint8_t> outside(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) outside[i] = !inside(b, points[i]);
  drop(points, outside);
}

void add(HostParticles& p, const Vec3& x, const Vec3& v, float mass, Phase phase, int material,
         double enthalpy, bool anchored = false) {
  p.position.push_back({float(x.x()), float(x.y()), float(x.z()), mass});
  const float hi = static_cast<float>(enthalpy);
  p.enthalpy.push_back({hi, static_cast<float>(enthalpy - double(hi))});
  p.velocity.push_back({float(v.x()), float(v.y()), float(v.z()), 0.f});
  p.density.push_back(0.f);
  p.phase.push_back(static_cast<std::uint8_t>(phase));
  p.material.push_back(static_cast<std::uint8_t>(material));
  p.id.push_back(static_cast<std::uint32_t>(p.id.size()));
  p.anchored.push_back(anchored ? 1 : 0);
}

// The air's region on the domain's lattice, less the solids (which never move) and the air dryers' pipes:
// an air dryer's pipe holds its own air, laid as it blows (sim/emitters.h), and room air there would be
// taken in at the first step.
std::vector<Vec3> air_lattice(const Scene& scene) {
  const double dx = scene.spacing;
  std::vector<Vec3> points =
      voxelize(Shape::box(scene.air.region.min, scene.air.region.max), dx, &scene.domain.min);
  drop_outside(points, scene.domain);
  for (const auto& s : scene.solids) drop_inside(points, s);
  for (const Dryer& d : scene.dryers) {
    if (d.model != DryerModel::Air) continue;
    const double pipe = EmitterStage::pipe_length(scene), r = EmitterStage::pipe_radius(d, dx);
    std::vector<std::uint8_t> in_pipe(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 x = points[i] - d.position;
      const double along = x.dot(d.direction);
      in_pipe[i] = along >= -pipe && along < 0 && (x - along * d.direction).squaredNorm() < r * r;
    }
    drop(points, in_pipe);
  }
  return points;
}

}  // namespace

std::vector<Eigen::Vector3d> room_air_sites(const Scene& scene) {
  if (!scene.has_air() || !scene.open_faces) return {};
  std::vector<Vec3> points = air_lattice(scene);
  const double dx = scene.spacing;
  std::vector<std::uint8_t> deep(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    bool near = false;
    for (int a = 0; a < 3; ++a) {
      if (scene.open_faces & (1u << (2 * a))) near = near || points[i][a] - scene.domain.min[a] < dx;
      if (scene.open_faces & (2u << (2 * a))) near = near || scene.domain.max[a] - points[i][a] < dx;
    }
    deep[i] = !near;
  }
  drop(points, deep);
  return points;
}

HostParticles sample_scene(const Scene& scene) {
  HostParticles p;
  const double dx = scene.spacing;
  const int layers = wall_layer_count(scene);
  const double depth = layers * dx;

  // Boundary particles first; their mass (Psi) is left 0 for the solver to compute. Those of a solid's outer
  // layer, where it has deposits, by solid.
  std::vector<std::pair<std::size_t, std::size_t>> outer;  // (particle, solid)
  for (std::size_t si = 0; si < scene.solids.size(); ++si) {
    const auto& s = scene.solids[si];
    const double h_solid = enthalpy_at(scene, s.material, s.temperature);
    const bool dirty = std::any_of(s.deposits.begin(), s.deposits.end(), [](double d) { return d > 0; });
    if (!s.plane) {
      std::set<std::array<long long, 3>> skin;  // the outer layer's lattice points
      auto key = [&](const Vec3& x) {
        const Vec3 k = (x - scene.domain.min) / dx;
        return std::array<long long, 3>{std::llround(k.x()), std::llround(k.y()), std::llround(k.z())};
      };
      if (dirty)
        for (const Vec3& x : voxelize_shell(s.shape, dx, 1, &scene.domain.min)) skin.insert(key(x));
      for (const Vec3& x : voxelize_shell(s.shape, dx, layers, &scene.domain.min)) {
        if (dirty && skin.count(key(x))) outer.emplace_back(p.size(), si);
        add(p, x, Vec3::Zero(), 0.f, Phase::Solid, s.material, h_solid);
      }
    } else {
      // Layers behind the plane, clipped to the domain grown by the layer depth; along a periodic axis
      // to one period [min, max), which its neighbours see repeated.
      const Vec3 nrm = s.normal.normalized();
      const Vec3 u = nrm.unitOrthogonal(), v = nrm.cross(u);
      Box grown{scene.domain.min - Vec3::Constant(depth), scene.domain.max + Vec3::Constant(depth)};
      Box period = grown;
      for (int a = 0; a < 3; ++a)
        if (scene.solver.periodic[static_cast<std::size_t>(a)]) {
          period.min[a] = scene.domain.min[a];
          period.max[a] = scene.domain.max[a] - 1e-9 * dx;
        }
      // The plane's (u, v) coordinates, relative to s.point, that cover the grown domain.
      const double umin = -grown.max_along(-u) - s.point.dot(u), umax = grown.max_along(u) - s.point.dot(u);
      const double vmin = -grown.max_along(-v) - s.point.dot(v), vmax = grown.max_along(v) - s.point.dot(v);
      for (double a = std::floor(umin / dx) * dx; a <= umax; a += dx)
        for (double b = std::floor(vmin / dx) * dx; b <= vmax; b += dx)
          for (int k = 0; k < layers; ++k) {
            const Vec3 x = s.point + (a + 0.5 * dx) * u + (b + 0.5 * dx) * v - (k + 0.5) * dx * nrm;
            if (!inside(period, x)) continue;
            if (dirty && k == 0) outer.emplace_back(p.size(), si);
            add(p, x, Vec3::Zero(), 0.f, Phase::Solid, s.material, h_solid);
          }
    }
  }
  // Domain walls: lattice points outside the domain, within the layer depth, on walled sides only.
  if (!scene.walls.empty()) {
    const double h_wall = enthalpy_at(
        scene, scene.wall_material,
        scene.heat.wall_coefficient > 0 ? scene.heat.wall_temperature : scene.heat.ambient_temperature);
    const auto& d = scene.domain;
    auto walled = [&](int axis, bool upper) {
      const std::string side = std::string(upper ? "+" : "-") + "xyz"[axis];
      for (const auto& w : scene.walls)
        if (w == side) return true;
      return false;
    };
    const Vec3 lo = d.min - Vec3::Constant(depth), hi = d.max + Vec3::Constant(depth);
    const Vec3 start = d.min - Vec3::Constant(depth);
    lattice(start, hi, dx, [&](const Vec3& x) {
      bool outside = false, ok = true;
      for (int a = 0; a < 3; ++a) {
        if (x[a] < d.min[a]) outside = true, ok = ok && walled(a, false);
        if (x[a] > d.max[a]) outside = true, ok = ok && walled(a, true);
      }
      if (outside && ok && inside(Box{lo, hi}, x))
        add(p, x, Vec3::Zero(), 0.f, Phase::Solid, scene.wall_material, h_wall);
    });
  }
  // Ice: the lattice points of its shape, with the SPH mass of a boundary particle (rho0 dx^3;
  // sim/thermal.h), skipping points inside solids or earlier ice.
  const float boundary_mass = static_cast<float>(derive_constants(scene).rest_density * dx * dx * dx);
  for (std::size_t b = 0; b < scene.ice.size(); ++b) {
    const auto& c = scene.ice[b];
    const double h = enthalpy_at(scene, c.material, c.temperature);
    std::vector<Vec3> points = voxelize(c.shape, dx, &scene.domain.min);
    // Ice that became no particles is a scene mistake, not a melt that ends at once: a one-triangle mesh
    // ran a scene with no ice, exit 0 and no word.
    const std::string path = "ice[" + std::to_string(b) + "]";
    if (points.empty())
      throw SceneError(path, "its shape holds no particle at a spacing of " + std::to_string(dx * 1e3) +
                                 " mm: a mesh must be closed around a volume (an open or flat one encloses "
                                 "none), and a shape must be wider than one spacing");
    drop_outside(points, scene.domain);
    for (const auto& s : scene.solids) drop_inside(points, s);
    for (std::size_t e = 0; e < b; ++e) drop_inside(points, scene.ice[e].shape);
    if (points.empty())
      throw SceneError(path,
                       "every particle of its shape lies outside the domain, inside a solid or inside "
                       "earlier ice");
    const bool anchored = c.motion == IceBlock::Motion::Fixed;
    for (const Vec3& x : points) add(p, x, Vec3::Zero(), boundary_mass, Phase::Ice, c.material, h, anchored);
  }
  // Fluid blocks, skipping lattice points inside solids, ice or an earlier block.
  std::vector<std::size_t> first_of;  // each block's first particle, then one past the last block's
  for (std::size_t b = 0; b < scene.fluids.size(); ++b) {
    first_of.push_back(p.size());
    const auto& f = scene.fluids[b];
    const float mass = static_cast<float>(scene.materials[f.material].density * dx * dx * dx);
    const double h = enthalpy_at(scene, f.material, f.temperature);
    std::vector<Vec3> points = voxelize(f.shape, dx, &scene.domain.min);
    drop_outside(points, scene.domain);
    for (const auto& s : scene.solids) drop_inside(points, s);
    for (const auto& c : scene.ice) drop_inside(points, c.shape);
    for (std::size_t e = 0; e < b; ++e) drop_inside(points, scene.fluids[e].shape);
    for (const Vec3& x : points) add(p, x, f.velocity, mass, Phase::Water, f.material, h);
  }
  first_of.push_back(p.size());
  // Air: the domain's lattice over its region, skipping points inside solids, ice or fluid blocks.
  if (scene.has_air()) {
    const AirFill& a = scene.air;
    const float mass = static_cast<float>(rest_density_at(scene, a.material, a.temperature) * dx * dx * dx);
    const double h = enthalpy_at(scene, a.material, a.temperature);
    std::vector<Vec3> points = air_lattice(scene);
    for (const auto& c : scene.ice) drop_inside(points, c.shape);
    for (const auto& f : scene.fluids) drop_inside(points, f.shape);
    if (points.empty())
      throw SceneError("air", "its region holds no particle outside the solids, ice and fluid blocks");
    for (const Vec3& x : points) add(p, x, Vec3::Zero(), mass, Phase::Air, a.material, h);
  }
  if (p.size() > std::size_t(0xffffffffu)) throw SceneError("spacing", "too many particles for 32-bit ids");
  if (!scene.substances.empty()) {
    std::vector<std::vector<double>> concentrations;
    for (const FluidBlock& f : scene.fluids) concentrations.push_back(f.substances);
    add_substance_columns(p, scene, first_of, concentrations);
    add_deposit_columns(p, scene, outer);
  }
  return p;
}

SimState initial_state(const Scene& scene) {
  SimState s;
  s.particles = sample_scene(scene);
  s.scene_json = scene.source.dump();
  return s;
}

}  // namespace thaw

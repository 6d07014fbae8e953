#include "render/snapshot.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/error.h"
#include "sim/substance_stage.h"

namespace thaw {

RenderSnapshot make_snapshot(const HostParticles& p, const std::vector<float>& temperature,
                             const Scene& scene, double time, std::uint64_t step) {
  if (!temperature.empty() && temperature.size() != p.size())
    throw Error("render snapshot: " + std::to_string(temperature.size()) + " temperatures for " +
                std::to_string(p.size()) + " particles");
  RenderSnapshot s;
  s.position.reserve(p.size());
  s.bounds_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  s.bounds_max = -s.bounds_min;
  for (const Float4& x : p.position) {
    const Eigen::Vector3f v(x[0], x[1], x[2]);
    s.position.push_back(v);
    s.bounds_min = s.bounds_min.cwiseMin(v);
    s.bounds_max = s.bounds_max.cwiseMax(v);
  }
  if (p.size() == 0) s.bounds_min = s.bounds_max = Eigen::Vector3f::Zero();
  s.phase = p.phase;
  if (std::any_of(scene.materials.begin(), scene.materials.end(),
                  [](const Material& m) { return m.transparent; }) &&
      p.material.size() == p.size()) {
    s.glass.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i)
      s.glass[i] = p.material[i] < scene.materials.size() && scene.materials[p.material[i]].transparent;
  }
  s.temperature = temperature;
  if (p.velocity.size() == p.size()) {
    s.speed.reserve(p.size());
    for (const Float4& v : p.velocity) s.speed.push_back(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
  }
  for (const Substance& sub : scene.substances) {
    std::vector<float> c(p.size(), 0.0f);
    bool bulk = true;
    for (const std::string& field : {substance_field(sub.name).name, adsorbed_field(sub.name).name}) {
      const HostColumn* col = p.column(field);
      const bool dissolved = bulk;
      bulk = false;
      if (!col || col->size() != p.size() || p.material.size() != p.size()) continue;
      const Float2* q = col->as<Float2>();
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double m = p.position[i][3];
        const double rho =
            p.material[i] < scene.materials.size() ? scene.materials[p.material[i]].density : 0.0;
        if (!(m > 0 && rho > 0)) continue;
        double held = (double(q[i][0]) + double(q[i][1])) * rho / m;
        // Past its solubility a particle holds the rest undissolved (sim/kernels/liquidus.h): the view shows
        // the saturated solution, never more than water dissolves.
        if (dissolved && sub.solubility > 0) held = std::min(held, sub.solubility * rho);
        c[i] += static_cast<float>(held);
      }
    }
    s.substances.push_back({sub.name, std::move(c)});
    s.substance_colours.push_back(sub.colour);
    if (!sub.coating()) continue;
    std::vector<float> d(p.size(), 0.0f);
    const HostColumn* col = p.column(deposited_field(sub.name).name);
    const double face = scene.spacing * scene.spacing;
    if (col && col->size() == p.size())
      for (std::size_t i = 0; i < p.size(); ++i) {
        const Float2& q = col->as<Float2>()[i];
        d[i] = static_cast<float>((double(q[0]) + double(q[1])) / face);
      }
    s.deposits.push_back({sub.name, std::move(d)});
    s.deposit_capacity.push_back(static_cast<float>(sub.coating_capacity));
  }
  for (const Dryer& d : scene.dryers)
    s.dryers.push_back({d.position.cast<float>(), d.direction.normalized().cast<float>(),
                        static_cast<float>(0.5 * d.nozzle_diameter), static_cast<float>(d.half_angle),
                        // An air dryer's air is drawn by its particles: no cone.
                        d.model == DryerModel::Air ? 0.0f : static_cast<float>(d.reach), d.on});
  for (const Emitter& e : scene.emitters)
    s.dryers.push_back({e.position.cast<float>(), e.direction.normalized().cast<float>(),
                        static_cast<float>(e.radius), 0.0f, 0.0f, false});
  for (const Lamp& l : scene.lamps) {
    // The rectangle's width runs horizontally (across the normal and z) where it can, as the photon
    // tracer lays it out (sim/heat_stage.cpp).
    const Eigen::Vector3d n = l.normal.normalized();
    Eigen::Vector3d u = n.cross(Eigen::Vector3d::UnitZ());
    u = u.norm() > 1e-6 ? u.normalized() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d v = n.cross(u);
    s.lamps.push_back({l.centre.cast<float>(), (0.5 * l.width * u).cast<float>(),
                       (0.5 * l.height * v).cast<float>(), static_cast<float>(l.temperature), l.on});
  }
  s.spacing = static_cast<float>(scene.spacing);
  s.domain_min = scene.domain.min.cast<float>();
  s.domain_max = scene.domain.max.cast<float>();
  s.time = time;
  s.step = step;
  return s;
}

}  // namespace thaw

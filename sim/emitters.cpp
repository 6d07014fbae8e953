#include "sim/emitters.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/error.h"
#include "sim/thermal.h"

namespace thaw {

std::vector<Eigen::Vector2i> EmitterStage::disc(double radius, double spacing) {
  const double r = radius / spacing;
  const int reach = static_cast<int>(std::floor(r));
  std::vector<Eigen::Vector2i> out;
  for (int j = -reach; j <= reach; ++j)
    for (int i = -reach; i <= reach; ++i)
      if (double(i) * i + double(j) * j <= r * r) out.emplace_back(i, j);
  return out;
}

namespace {
// N dx^3 / (pi r^2) for a disc of N lattice points.
double spacing_of(std::size_t points, const Emitter& e, double dx) {
  return double(points) * dx * dx * dx / e.area();
}
}  // namespace

double EmitterStage::disc_spacing(const Emitter& e, double spacing) {
  return spacing_of(disc(e.radius, spacing).size(), e, spacing);
}

double EmitterStage::particles_per_second(const Emitter& e, double spacing) {
  return double(disc(e.radius, spacing).size()) * e.speed / disc_spacing(e, spacing);
}

HostParticles EmitterStage::emit(double t, double dt, std::uint32_t& next_id) {
  HostParticles out;
  const double dx = scene_.spacing;
  for (std::size_t k = 0; k < scene_.emitters.size(); ++k) {
    const Emitter& e = scene_.emitters[k];
    // The part of [t, t + dt] the tap pours in.
    const double stop = e.stop > 0 ? e.stop : std::numeric_limits<double>::infinity();
    const double open_for = std::min(t + dt, stop) - std::max(t, e.start);
    if (!e.open || !(open_for > 0)) continue;
    pending_[k] += e.speed * open_for;
    const std::vector<Eigen::Vector2i> offsets = disc(e.radius, dx);  // once a step: a client may resize it
    const double d = spacing_of(offsets.size(), e, dx);
    if (pending_[k] < d) continue;
    const Eigen::Vector3d u = e.direction.unitOrthogonal(), w = e.direction.cross(u);
    const Material& m = scene_.materials[static_cast<std::size_t>(e.material)];
    const float mass = static_cast<float>(m.density * dx * dx * dx);
    const double h = enthalpy_at(scene_, e.material, e.temperature);
    const float h_hi = static_cast<float>(h), h_lo = static_cast<float>(h - double(h_hi));
    const Eigen::Vector3d v = e.speed * e.direction;
    while (pending_[k] >= d) {
      pending_[k] -= d;
      // This disc crossed the nozzle when the pending length reached d: it has since gone the rest.
      const Eigen::Vector3d centre = e.position + pending_[k] * e.direction;
      for (const Eigen::Vector2i& o : offsets) {
        const Eigen::Vector3d x = centre + dx * (o.x() * u + o.y() * w);
        out.position.push_back({float(x.x()), float(x.y()), float(x.z()), mass});
        out.velocity.push_back({float(v.x()), float(v.y()), float(v.z()), 0.f});
        out.density.push_back(0.f);
        out.phase.push_back(static_cast<std::uint8_t>(Phase::Water));
        out.material.push_back(static_cast<std::uint8_t>(e.material));
        out.id.push_back(next_id++);
        out.enthalpy.push_back({h_hi, h_lo});
        out.anchored.push_back(0);
        books_.particles += 1;
        books_.mass += double(mass);
        books_.momentum +=
            double(mass) * Eigen::Vector3d(double(float(v.x())), double(float(v.y())), double(float(v.z())));
      }
    }
  }
  return out;
}

std::vector<double> EmitterStage::save(const Saved& solver) const {
  std::vector<double> v = {double(books_.particles), books_.mass,         books_.momentum.x(),
                           books_.momentum.y(),      books_.momentum.z(), double(solver.next_id),
                           double(solver.capacity)};
  v.insert(v.end(), pending_.begin(), pending_.end());
  return v;
}

EmitterStage::Saved EmitterStage::restore(const std::vector<double>& v) {
  if (v.empty()) return {};
  if (v.size() != 7 + pending_.size())
    throw Error("state: the inflow section has " + std::to_string(v.size()) + " entries, expected " +
                std::to_string(7 + pending_.size()) + " for a scene with " + std::to_string(pending_.size()) +
                " emitters");
  books_.particles = static_cast<std::uint64_t>(v[0]);
  books_.mass = v[1];
  books_.momentum = {v[2], v[3], v[4]};
  std::copy(v.begin() + 7, v.end(), pending_.begin());
  return {static_cast<std::uint64_t>(v[5]), static_cast<std::uint64_t>(v[6])};
}

}  // namespace thaw

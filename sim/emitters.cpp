#include "sim/emitters.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/error.h"
#include "sim/scene_sampling.h"
#include "sim/substance_stage.h"
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
double spacing_of(std::size_t points, double radius, double dx) {
  return double(points) * dx * dx * dx / (M_PI * radius * radius);
}
}  // namespace

double EmitterStage::disc_spacing(const Emitter& e, double spacing) {
  return spacing_of(disc(e.radius, spacing).size(), e.radius, spacing);
}

double EmitterStage::particles_per_second(const Emitter& e, double spacing) {
  return double(disc(e.radius, spacing).size()) * e.speed / disc_spacing(e, spacing);
}

// The disc's N points each carry dx^3 and the discs follow at N dx^3 / A: A v / dx^3 a second.
double EmitterStage::particles_per_second(const Dryer& d, double spacing) {
  return d.area() * d.speed / (spacing * spacing * spacing);
}

EmitterStage::EmitterStage(const Scene& scene)
    : scene_(scene),
      pending_(scene.emitters.size() + scene.dryers.size(), 0.0),
      owed_(scene.dryers.size(), 0.0),
      room_sites_(admits_room_air(scene) ? room_air_sites(scene) : std::vector<Eigen::Vector3d>{}) {}

bool EmitterStage::needed(const Scene& scene) {
  return !scene.emitters.empty() || scene.air_dryer_count() > 0 || admits_room_air(scene);
}

void EmitterStage::admit_room_air(const std::vector<std::uint32_t>& empty,
                                  const std::vector<Eigen::Vector3f>& velocity, HostParticles& out,
                                  std::uint32_t& next_id) {
  if (empty.empty()) return;
  const double dx = scene_.spacing;
  const int air = scene_.air.material;
  const double T = scene_.heat.ambient_temperature;
  const float mass = static_cast<float>(rest_density_at(scene_, air, T) * dx * dx * dx);
  const double h = enthalpy_at(scene_, air, T);
  for (std::size_t k = 0; k < empty.size(); ++k)
    append(out, room_sites_.at(empty[k]), velocity.at(k), mass, Phase::Air, air, h, next_id);
}

void EmitterStage::append(HostParticles& out, const Eigen::Vector3d& x, const Eigen::Vector3f& v, float mass,
                          Phase phase, int material, double h, std::uint32_t& next_id) {
  const float h_hi = static_cast<float>(h), h_lo = static_cast<float>(h - double(h_hi));
  out.position.push_back({float(x.x()), float(x.y()), float(x.z()), mass});
  out.velocity.push_back({v.x(), v.y(), v.z(), 0.f});
  out.density.push_back(0.f);
  out.phase.push_back(static_cast<std::uint8_t>(phase));
  out.material.push_back(static_cast<std::uint8_t>(material));
  out.id.push_back(next_id++);
  out.enthalpy.push_back({h_hi, h_lo});
  out.anchored.push_back(0);
  books_.particles += 1;
  books_.mass += double(mass);
  books_.momentum += double(mass) * v.cast<double>();
}

std::size_t EmitterStage::lay(const Nozzle& z, double open_for, double& pending, HostParticles& out,
                              std::uint32_t& next_id) {
  const std::size_t before = out.size();
  const double dx = scene_.spacing;
  pending += z.speed * open_for;
  const std::vector<Eigen::Vector2i> offsets = disc(z.radius, dx);  // once a step: a client may resize it
  const double d = spacing_of(offsets.size(), z.radius, dx);
  if (pending < d) return 0;
  const Eigen::Vector3d u = z.direction.unitOrthogonal(), w = z.direction.cross(u);
  const float mass = static_cast<float>(rest_density_at(scene_, z.material, z.temperature) * dx * dx * dx);
  const double h = enthalpy_at(scene_, z.material, z.temperature);
  const Eigen::Vector3f v = (z.speed * z.direction).cast<float>();
  while (pending >= d) {
    pending -= d;
    // This disc crossed the nozzle when the pending length reached d: it has since gone the rest.
    const Eigen::Vector3d centre = z.position + pending * z.direction;
    for (const Eigen::Vector2i& o : offsets)
      append(out, centre + dx * (o.x() * u + o.y() * w), v, mass, z.phase, z.material, h, next_id);
  }
  return out.size() - before;
}

HostParticles EmitterStage::emit(double t, double dt, std::uint32_t& next_id) {
  HostParticles out;
  const std::size_t ne = scene_.emitters.size();
  std::vector<std::size_t> first_of(ne + 1, 0);  // each emitter's first particle in `out`
  for (std::size_t k = 0; k < ne; ++k) {
    const Emitter& e = scene_.emitters[k];
    first_of[k] = out.size();
    // The part of [t, t + dt] the tap pours in.
    const double stop = e.stop > 0 ? e.stop : std::numeric_limits<double>::infinity();
    const double open_for = std::min(t + dt, stop) - std::max(t, e.start);
    if (!e.open || !(open_for > 0)) continue;
    lay({e.position, e.direction, e.radius, e.speed, e.temperature, e.material, Phase::Water}, open_for,
        pending_[k], out, next_id);
  }
  first_of[ne] = out.size();
  for (std::size_t k = 0; k < scene_.dryers.size(); ++k) {
    const Dryer& d = scene_.dryers[k];
    if (!d.blows_air() || !(dt > 0)) continue;
    // Laid at the back of the dryer's pipe, which carries them to the exit at its speed (grid.cl).
    owed_[k] += double(lay({d.position - pipe_length(scene_) * d.direction, d.direction,
                            0.5 * d.nozzle_diameter, d.speed, d.temperature, scene_.air.material, Phase::Air},
                           dt, pending_[ne + k], out, next_id));
  }
  // What the taps pour carries their substances (the dryers' air none).
  if (!scene_.substances.empty()) {
    std::vector<std::vector<double>> concentrations;
    for (const Emitter& e : scene_.emitters) concentrations.push_back(e.substances);
    add_substance_columns(out, scene_, first_of, concentrations);
  }
  return out;
}

std::vector<double> EmitterStage::save(const Saved& solver) const {
  std::vector<double> v = {double(books_.particles), books_.mass,         books_.momentum.x(),
                           books_.momentum.y(),      books_.momentum.z(), double(solver.next_id),
                           double(solver.capacity)};
  v.insert(v.end(), pending_.begin(), pending_.end());
  v.insert(v.end(), owed_.begin(), owed_.end());
  return v;
}

EmitterStage::Saved EmitterStage::restore(const std::vector<double>& v) {
  if (v.empty()) return {};
  // States written before air dryers kept the emitters' pending lengths only: the dryers' start at 0.
  const std::size_t with_emitters = 7 + scene_.emitters.size();
  const std::size_t full = 7 + pending_.size() + owed_.size();
  if (v.size() != full && v.size() != with_emitters)
    throw Error("state: the inflow section has " + std::to_string(v.size()) + " entries, expected " +
                std::to_string(full) + " for a scene with " + std::to_string(scene_.emitters.size()) +
                " emitters and " + std::to_string(scene_.dryers.size()) + " dryers");
  books_.particles = static_cast<std::uint64_t>(v[0]);
  books_.mass = v[1];
  books_.momentum = {v[2], v[3], v[4]};
  std::fill(pending_.begin(), pending_.end(), 0.0);
  std::fill(owed_.begin(), owed_.end(), 0.0);
  std::copy(v.begin() + 7, v.begin() + std::ptrdiff_t(std::min(v.size(), 7 + pending_.size())),
            pending_.begin());
  if (v.size() == full) std::copy(v.end() - std::ptrdiff_t(owed_.size()), v.end(), owed_.begin());
  return {static_cast<std::uint64_t>(v[5]), static_cast<std::uint64_t>(v[6])};
}

}  // namespace thaw

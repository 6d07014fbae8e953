#pragma once
// Pouring fluid (Iwasaki et al. 2010, Fig. 7: water poured onto ice in a glass): each open emitter lays
// discs of particles across its nozzle that leave along its direction at its exit speed. A disc holds
// the N lattice points (spacing dx, centred on the nozzle) that lie within the nozzle's radius r, and
// discs follow each other at the distance d = N dx^3 / (pi r^2), so each particle carries the volume
// dx^3 it would have at rest and the mass flow is rho pi r^2 v exactly, whatever r / dx is. The stage
// keeps, per emitter, the length of fluid that has left the nozzle since the last disc; a disc is laid
// each time that reaches d, already (length - d) downstream, where it would be had it left on time.
//
// Capacity: emitted particles go into the store's spare capacity (sim/stage.h, ParticleLayout); the
// solver grows the capacity when it runs out (Solver::step). What came in is booked like what leaves
// through open sides: particles, mass, momentum here, enthalpy in the energy budget.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "sim/particles.h"
#include "sim/scene.h"

namespace thaw {

// What came in through emitters: particles, their physical mass [kg] and momentum [kg m/s].
struct InflowBooks {
  std::uint64_t particles = 0;
  double mass = 0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
};

class EmitterStage {
 public:
  // Offsets of a nozzle disc's particles in units of dx: the lattice points (i, j) with
  // i^2 + j^2 <= (r / dx)^2.
  static std::vector<Eigen::Vector2i> disc(double radius, double spacing);
  // The distance between successive discs [m]: N dx^3 / (pi r^2).
  static double disc_spacing(const Emitter& e, double spacing);
  // Particles an emitter pours per second while open [1/s].
  static double particles_per_second(const Emitter& e, double spacing);

  explicit EmitterStage(const Scene& scene) : scene_(scene), pending_(scene.emitters.size(), 0.0) {}

  // The particles the emitters pour between t and t + dt (each emitter open within [start, stop)),
  // with ids from next_id on (advanced), in the order of the emitters and, for each, oldest disc first;
  // books their particles, mass and momentum (the solver books their enthalpy in the energy budget).
  // Empty when nothing is due.
  HostParticles emit(double t, double dt, std::uint32_t& next_id);

  const InflowBooks& books() const { return books_; }

  // The stage's state for state files: the books, each emitter's pending length, and the run's next
  // particle id and capacity (kept by the solver, saved here so a resumed run lays out and numbers its
  // particles as the original did). restore() takes what save() gave; an empty vector: a fresh run.
  struct Saved {
    std::uint64_t next_id = 0, capacity = 0;
  };
  std::vector<double> save(const Saved& solver) const;
  Saved restore(const std::vector<double>& v);

 private:
  const Scene& scene_;  // the solver's, whose emitters a client may change between steps
  std::vector<double> pending_;
  InflowBooks books_;
};

}  // namespace thaw

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
//
// Air dryers (dryers[].model "air", Domaradzki & Martyn sec. 7's dryer made an emitter) are nozzles of the
// same kind that lay air particles of the scene's air material at the dryer's temperature, while on. Unlike
// a tap, a dryer blows into air that is already there, so it has a pipe and a housing (grid.cl,
// intake_flags): the discs are laid at the back of a pipe one kernel support long behind the exit, whose
// own air moves out at the exit speed, so the air leaving the exit is evenly spaced and has air behind it
// (laid at the exit itself, with nothing behind, the jet's first spacings were 10-40 % under-dense, room
// air mixed into it and the jet carried 25 % less than it blew a diameter on); the slow room air that
// drifts into the pipe is taken in (removed, booked with the outflow), and the housing around and behind
// the pipe takes the room's air in as long as the dryer owes particles: blown and not yet taken in. So a
// dryer draws room air in as a real one does, and over time takes in as many particles as it blows: a
// closed room keeps its air (tests/sim/air_test.cpp).
//
// Open sides (domain.open) of a scene with air are the room beyond the domain: air that leaves through one
// is removed (sim/kernels/grid.cl, booked as outflow), and the room's air comes back in. The sites are the
// air's lattice points within one spacing of an open side (room_air_sites); at the end of each step a
// site that no particle is near and where air is not leaving (grid.cl, empty_sites) gets a particle of
// air at the ambient temperature (ambient.temperature) that moves as the air around the site does,
// booked here as inflow. So a plume rises out of an open top while still air beside it stays (no site
// there is empty), and the particle count stays bounded where a closed side would hold every particle
// that reaches it (clamped and counted). Measured limit (docs/ARCHITECTURE.md): the pressure solve
// resists only compression, so pushes on the air vent some through an open side and nothing draws the
// room's air back; the shipped air scenes lost 22-53 % of their air with the top open, and hold it.
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
  // Particles an air dryer blows per second while on [1/s].
  static double particles_per_second(const Dryer& d, double spacing);
  // An air dryer's geometry (see above): its pipe's length [m], one kernel support (so the air leaving
  // the exit has air behind it), and in spacings the depth of the mouth in front of the exit (where slow
  // room air is taken in) and of the body behind the pipe.
  static double pipe_length(const Scene& scene) { return scene.solver.support_ratio * scene.spacing; }
  // The pipe's radius: the nozzle's and half a spacing, so the discs' outer particles are inside it.
  static double pipe_radius(const Dryer& d, double spacing) {
    return 0.5 * d.nozzle_diameter + 0.5 * spacing;
  }
  static constexpr double mouth_depth = 1.5, body_depth = 3.0;
  // A room-air site takes air when no particle is within room_air_gap spacings of it and the air there is
  // not leaving (grid.cl, empty_sites): in a lattice moving inward, when the last layer has gone a spacing.
  static constexpr double room_air_gap = 0.95;

  // Emitters first, then the air dryers, in the scene's order.
  explicit EmitterStage(const Scene& scene);
  // Whether the scene has anything this stage pours: an emitter, an air dryer, or air beside an open side.
  static bool needed(const Scene& scene);
  // Whether the room's air comes in through open sides: air, an open side, and flow.
  static bool admits_room_air(const Scene& scene) {
    return scene.solver.flow && scene.has_air() && scene.open_faces != 0;
  }
  // The room-air sites (room_air_sites(scene)), fixed for the run.
  const std::vector<Eigen::Vector3d>& room_sites() const { return room_sites_; }

  // The particles the emitters pour between t and t + dt (each emitter open within [start, stop)) and the
  // air dryers blow (each while on), with ids from next_id on (advanced), in the order of the emitters
  // then the dryers and, for each, oldest disc first;
  // books their particles, mass and momentum (the solver books their enthalpy in the energy budget).
  // Empty when nothing is due.
  HostParticles emit(double t, double dt, std::uint32_t& next_id);
  // Air at the ambient temperature on the room-air sites `empty` (indices into room_sites(), in increasing
  // order), each moving at its `velocity`, appended to `out` with ids from next_id on; books them.
  void admit_room_air(const std::vector<std::uint32_t>& empty, const std::vector<Eigen::Vector3f>& velocity,
                      HostParticles& out, std::uint32_t& next_id);

  const InflowBooks& books() const { return books_; }
  // Per dryer, the particles it has blown and not yet taken in (NeighbourGrid::build takes them in).
  std::vector<double>& owed() { return owed_; }

  // The stage's state for state files: the books, each emitter's pending length, and the run's next
  // particle id and capacity (kept by the solver, saved here so a resumed run lays out and numbers its
  // particles as the original did). restore() takes what save() gave; an empty vector: a fresh run.
  struct Saved {
    std::uint64_t next_id = 0, capacity = 0;
  };
  std::vector<double> save(const Saved& solver) const;
  Saved restore(const std::vector<double>& v);

 private:
  // One nozzle's share of emit(): `pending` advanced by speed * open_for, discs laid while it reaches d.
  struct Nozzle {
    Eigen::Vector3d position, direction;  // where discs are laid (an air dryer's: its pipe's back)
    double radius, speed, temperature;
    int material;
    Phase phase;
  };
  // Appends one particle of `material` at x moving at v with enthalpy h (split into float hi + lo) and the
  // next id, and books it: what lay() and admit_room_air() share.
  void append(HostParticles& out, const Eigen::Vector3d& x, const Eigen::Vector3f& v, float mass, Phase phase,
              int material, double h, std::uint32_t& next_id);
  // Returns the particles laid.
  std::size_t lay(const Nozzle& z, double open_for, double& pending, HostParticles& out,
                  std::uint32_t& next_id);

  const Scene& scene_;  // the solver's, whose emitters a client may change between steps
  std::vector<double> pending_, owed_;
  std::vector<Eigen::Vector3d> room_sites_;
  InflowBooks books_;
};

}  // namespace thaw

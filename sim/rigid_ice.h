#pragma once
// Ice that moves (Iwasaki et al. 2010 sec. 5-6): each connected piece of ice is a rigid body. The
// stage labels the ice's connected components on the device, turns each into a body (mass, centre,
// principal inertia, the rigid motion its particles carry), and each step sums the forces on its
// particles (water pressure and viscosity, contacts with solids and other bodies), integrates the
// bodies on the host and moves the particles with their bodies.
//
// A body is fixed when any of its particles comes from an ice object with "motion": "fixed" (an
// icicle's root, a pedestal glued to the floor); the rest are free. Labels are recomputed after the
// neighbour sort of a step that follows a phase change of ice (melting can cut a body in two, freezing
// can join two), at most every `relabel_interval` steps; between labellings a melted particle leaves
// its body at once and a frozen one stays in place until the next labelling adopts it. Bodies that merely
// touch stay apart: a labelling connects particles of one body, or a particle in none (the first
// labelling's, newly frozen ones), never two of different bodies.
//
// A free body stays inside the domain, as water does: a body that a step would carry past a face (an
// open side, or a fall past the edge of a floor) is moved back onto it, its velocity out of the face
// removed, and the event counted with the solver's clamps.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/cl_grid.h"
#include "sim/cl_runtime.h"
#include "sim/ice_bodies.h"
#include "sim/particle_store.h"
#include "sim/particles.h"
#include "sim/rigid_body.h"
#include "sim/scene.h"

namespace thaw {

// The solver's per-particle device buffers in their current (sorted) order, and the grid over them.
struct ParticleBuffers {
  const cl::Buffer& position;
  const cl::Buffer& velocity;
  const cl::Buffer& state;  // (rho, p / rho^2, is_boundary, p) from the density pass
  const cl::Buffer& phase;
  const cl::Buffer& material;
  const cl::Buffer& id;
  const cl::Buffer& cell_start;
  ClGrid grid;
  std::uint32_t n = 0;
  std::uint32_t ids = 0;  // one past the largest particle id of the run (emitters add ids past n)
};

// Contact between ice and solids or other ice bodies (Tanaka et al. 2007 as Iwasaki 2010 cites; see
// sim/kernels/rigid.cl).
struct ContactModel {
  double stiffness = 0;  // k_n [N/m]
  double damping = 0;    // c_n [N s/m]
  double friction = 0;   // Coulomb mu
  double distance = 0;   // contact diameter [m]
};

// One body as the metrics and tests see it.
struct IceBody {
  std::uint32_t label = 0;  // the largest particle id in the body: stable while that particle is ice
  std::size_t particles = 0;
  double radius = 0;  // the farthest particle from the centre of mass [m]
  RigidBody body;
};

class RigidIce {
 public:
  struct Settings {
    double spacing = 0;        // particle spacing dx [m]
    double support = 0;        // kernel support H [m]
    double smoothing = 0;      // h [m] (viscosity's eps h^2)
    double visc_boundary = 0;  // the forces pass's boundary viscosity coefficient
    double rest_density = 0;   // rho0 of the fluid, in the viscous pair term [kg/m^3]
    Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
    Eigen::Vector3d domain_min = Eigen::Vector3d::Constant(-1e30);  // particle centres stay in it [m]
    Eigen::Vector3d domain_max = Eigen::Vector3d::Constant(1e30);
    ContactModel contact;
    int relabel_interval = 10;  // steps between labellings while ice changes phase
    int grid_reach = 1;         // cells the neighbour walk visits on each side (Solver::GridInfo::reach)
  };

  // `build_options` are the solver's program options (kernel, lanes, reach); `anchored_by_id[id]` is 1
  // for particles of fixed ice objects; `mass_scale[material]` turns a particle's SPH mass into its
  // physical mass (ice is sampled with the fluid's rest mass; sim/thermal.h).
  // Declares its per-particle fields ("body", "body_offset") in `store`, which must outlive it and be
  // allocated before the first step; its own per-particle buffers hold `capacity` particles.
  RigidIce(ClRuntime& cl, ParticleStore& store, const std::string& build_options, std::size_t capacity,
           Settings settings, std::vector<std::uint8_t> anchored_by_id, std::vector<float> mass_scale);
  ~RigidIce();

  // After the sort: labels the ice into bodies when a phase change of ice asked for it (or `force`).
  void relabel_if_due(const ParticleBuffers& p, std::uint64_t step, bool force = false);
  // After the density pass: the force on each ice particle of a free body.
  void compute_forces(const ParticleBuffers& p);
  // Multiphase builds (THAW_MULTIPHASE): the fluid passes' material table and the DFSPH solve's columns
  // (blocks of `stride` floats), whose rest volumes the forces from fluid of several densities need
  // (sim/kernels/rigid.cl). Both must outlive this.
  void use_multiphase(const cl::Buffer& flow, const cl::Buffer& columns, std::uint32_t stride) {
    flow_ = &flow;
    columns_ = &columns;
    columns_stride_ = stride;
  }
  // Builds with THAW_TENSION_REACTION: each material's adhesion coefficient (tension_coefficients in
  // sim/tension_stage.h), so the ice takes the reaction of the water's adhesion to it.
  void use_tension(const std::vector<float>& adhesion);
  // The fastest point of any free body [m/s] (the time step's CFL limit covers it).
  double max_point_speed() const;
  // Sums the forces per body, integrates the bodies over dt and moves their particles.
  void advance(const ParticleBuffers& p, double dt);
  // The heat stage saw ice change phase this step.
  void note_phase_change() { phase_changed_ = true; }
  // Held, the free bodies stay where they are (forces are still computed) until let go: a validation
  // case settles its water around a floating body that way.
  void hold(bool held) { held_ = held; }

  const std::vector<IceBody>& bodies() const { return bodies_; }
  // The force on each particle from the last compute_forces() [N] (benchmarks and tests).
  std::vector<Float4> forces(std::size_t n) const;
  std::uint64_t labellings() const { return labellings_; }
  // Times a free body was moved back inside the domain since this object was made.
  std::uint64_t clamped() const { return clamped_; }
  int last_iterations() const { return last_iterations_; }

  // State for state files beyond the per-particle fields (which the store saves): the bodies and the
  // labelling schedule as doubles; the last labelling's sweeps (empty: 0, as in older files).
  struct Saved {
    std::vector<double> bodies;
    std::vector<double> labelling;
  };
  Saved save() const;
  void restore(const Saved& s);

 private:
  void upload_bodies();
  // Moves body b back inside the domain if any of its particles left it; true if it did.
  bool confine(std::size_t b);

  ClRuntime& cl_;
  ParticleStore& store_;
  Settings settings_;
  std::vector<std::uint8_t> anchored_by_id_;
  std::vector<float> mass_scale_;
  std::unique_ptr<IceLabeller> labeller_;
  std::unique_ptr<BodyReducer> reducer_;
  cl::Kernel k_forces_, k_place_;
  ParticleStore::Field body_ = 0, offset_ = 0;
  cl::Buffer force_, label_, bodies_dev_, refs_;
  cl::Buffer adhesion_;               // use_tension
  const cl::Buffer* flow_ = nullptr;  // use_multiphase
  const cl::Buffer* columns_ = nullptr;
  std::uint32_t columns_stride_ = 0;
  std::size_t bodies_capacity_ = 0;
  std::vector<IceBody> bodies_;
  std::vector<std::vector<Eigen::Vector3f>> shapes_;  // each body's particle offsets in its own frame
  bool phase_changed_ = false;
  bool held_ = false;
  bool labelled_ = false;
  std::uint64_t labelled_step_ = 0;
  std::uint64_t labellings_ = 0;
  int last_iterations_ = 0;
  std::uint64_t clamped_ = 0;
};

}  // namespace thaw

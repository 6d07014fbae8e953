#pragma once
// Ice bodies on the device (Iwasaki et al. 2010, sec. 5 and 6): which ice particles form one rigid body
// (connected-component labelling, Fig. 4), and the per-body sums the rigid-body stage needs (mass, first
// and second moments, force, torque). Kernels: sim/kernels/ice_labels.cl, sim/kernels/body_sums.cl.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "sim/cl_grid.h"
#include "sim/cl_runtime.h"

namespace thaw {

// Label and body index of particles that are not ice.
inline constexpr std::uint32_t kNoLabel = 0xffffffffu;
inline constexpr std::uint32_t kNoBody = 0xffffffffu;

// The solver's particles after its grid build: sorted by cell (keys as sim/kernels/grid_common.h makes
// them, x fastest) with the cell ranges of that sort.
struct SortedIceParticles {
  cl::Buffer position;    // float4 [n]: x, y, z [m]; w unused here
  cl::Buffer phase;       // uchar [n]: Phase; ice (1) takes part
  cl::Buffer id;          // uint [n]: stable identity, unique among the n particles, < id_capacity
  cl::Buffer cell_start;  // uint [ncells + 1]: first sorted particle of each cell; the last entry is n
  std::uint32_t n = 0;
  std::uint32_t id_capacity = 0;  // every id is below this (sizes the id -> sorted index map)
  // Optional, uint [n]: each particle's body before this labelling, or kNoBody. Two particles in different
  // bodies are never connected, so bodies that come to touch stay apart; a particle in none (ice that
  // froze since, or every particle at the first labelling) connects to any. Left empty: no groups.
  cl::Buffer group;
};

struct LabelOptions {
  // Pointer jumps per sweep (Fig. 4c): after the neighbours' largest label, a particle follows its label to
  // the particle with that id and takes that one's label, up to this many times while it rises. Iwasaki
  // take one; 0 is plain max propagation. On chains and lattices with ids in creation order, 4 take a
  // third fewer sweeps than 1 (tests/sim/ice_bodies_test.cpp, `thaw bench bodies`).
  std::uint32_t jumps = 4;
  // Hooking (Shiloach & Vishkin 1982): a particle whose label rose also hands the new label to the particle
  // its old label names, where everyone still pointing there finds it by the next jump. Without it the
  // jumps stall when ids lie scattered along a body (water that froze after mixing): on a chain of 800
  // with shuffled ids, 16 sweeps instead of 218. Costs atomics in the sweeps that raise many labels.
  bool hook = true;
};

// The bodies of one labelling, indexed 0 .. size() - 1 in ascending label order.
struct IceBodies {
  std::vector<std::uint32_t> labels;  // per body: its label, the largest particle id in it
  std::vector<std::uint32_t> counts;  // per body: particles
  std::size_t size() const { return labels.size(); }
};

class IceLabeller {
 public:
  // reach: cells the solver's neighbour walk visits on each side of a particle's cell
  // (Solver::GridInfo::reach): the connection radius may span at most that many cells. Throws Error (with
  // the build log) if the kernels do not build.
  IceLabeller(ClRuntime& cl, int reach);

  // Connected components of the ice particles: two are connected when their distance is below radius [m]
  // and their groups allow it (p.group). The radius must not exceed the grid's cell size times reach along
  // any axis (Error otherwise; so must every id be below p.id_capacity). grid must be the one the particles
  // were sorted with; its axes do not wrap (a periodic axis, of the heat-only mode, joins nothing across its
  // faces). Writes label (a caller-owned uint buffer of at least p.n entries): for ice, the largest id in its
  // component; kNoLabel for other phases. Returns the number of sweeps run, the last being the one that
  // changed nothing. Blocks: reads a flag back after each walk and sweep. Scratch: about (row_width() + 7) *
  // 4 bytes per particle and 4 per id below id_capacity, kept for the next call.
  std::uint32_t label(const SortedIceParticles& p, const ClGrid& grid, float radius, cl::Buffer& label,
                      const LabelOptions& options = {});

  // Numbers the distinct labels of label (n entries, as label() writes them; every ice label is below
  // id_capacity) 0 .. B-1 in ascending order and writes each particle's number to body (a caller-owned
  // uint buffer of at least n entries; kNoBody for non-ice). Done on the host: labelling runs only when a
  // phase change touched ice.
  IceBodies compact(const cl::Buffer& label, std::uint32_t n, std::uint32_t id_capacity, cl::Buffer& body);

  // label() then compact().
  IceBodies find_bodies(const SortedIceParticles& p, const ClGrid& grid, float radius, cl::Buffer& label,
                        cl::Buffer& body, const LabelOptions& options = {});

  // Sweeps of the last label() call.
  std::uint32_t last_sweeps() const { return sweeps_; }
  // Neighbour slots kept per particle: the most any labelling so far needed, at least 32.
  std::uint32_t row_width() const { return width_; }

 private:
  ClRuntime& cl_;
  int reach_;
  std::uint32_t sweeps_ = 0;
  cl::Kernel k_points_, k_neighbours_, k_slots_, k_propagate_;
  // Scratch, grown on demand: the walk's coordinate blocks, neighbour counts, rows of `width_` neighbours
  // per particle, the id -> sorted index map, the second label buffer of the Jacobi sweeps, the two hook
  // buffers, flags. The rows start wide enough for a lattice at a radius of the kernel support (26
  // neighbours) and widen when a particle has more.
  std::uint32_t width_ = 32;
  cl::Buffer points_, degree_, edges_, slot_of_, spare_label_, hooks_[2], changed_, overflow_, bad_;
  std::size_t particles_cap_ = 0, edges_cap_ = 0, ids_cap_ = 0;
  std::vector<std::uint32_t> host_labels_, host_body_, lookup_;
};

// Sums over the particles of one body, with r = x - ref for the body's reference point ref and
// m = position.w * mass_scale[material] (see BodyReducer::reduce).
struct BodySums {
  std::uint32_t count = 0;
  double mass = 0;                                          // sum m [kg]
  Eigen::Vector3d first_moment = Eigen::Vector3d::Zero();   // sum m r [kg m]
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();  // sum m r r^T [kg m^2], symmetric
  Eigen::Vector3d force = Eigen::Vector3d::Zero();          // sum f [N]
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();         // sum r x f [N m]

  // The 16 sums in one array, in the kernel's order: m, m r (3), m r r^T (xx, yy, zz, xy, xz, yz), f (3),
  // r x f (3) (for comparing against reference loops).
  std::array<double, 16> terms() const {
    const Eigen::Matrix3d& S = second_moment;
    return {mass,      first_moment.x(), first_moment.y(), first_moment.z(), S(0, 0),   S(1, 1),
            S(2, 2),   S(0, 1),          S(0, 2),          S(1, 2),          force.x(), force.y(),
            force.z(), torque.x(),       torque.y(),       torque.z()};
  }

  // Inertia tensor about ref: sum m (|r|^2 1 - r r^T) [kg m^2].
  Eigen::Matrix3d inertia() const {
    return second_moment.trace() * Eigen::Matrix3d::Identity() - second_moment;
  }
};

// Per-particle inputs of the body sums, in any order (the solver's sorted one).
struct BodyParticles {
  cl::Buffer position;  // float4 [n]: x, y, z [m]; w = mass before the material's scale [kg]
  cl::Buffer material;  // uchar [n]: index into the mass-scale table
  cl::Buffer force;     // float4 [n]: x, y, z [N]; w unused
  cl::Buffer body;      // uint [n]: body index < nbodies, or kNoBody (not summed)
  std::uint32_t n = 0;
};

// Per-body sums, deterministic (bitwise the same on every run: fixed-order compensated sums, no float
// atomics) whatever order work-items run in, and accurate to a few float roundings of each term.
class BodyReducer {
 public:
  // mass_scale: per material, the factor from position.w to the mass summed. Throws Error if empty or if
  // the kernels do not build.
  BodyReducer(ClRuntime& cl, const std::vector<float>& mass_scale);

  // reference: a float4 buffer of at least nbodies entries, xyz = each body's reference point ref [m] (w
  // unused). Returns nbodies entries (a body with no particle gets zeros). Throws Error naming the first
  // particle whose body is neither below nbodies nor kNoBody, or whose material is outside the table.
  // Blocks until the sums are on the host.
  std::vector<BodySums> reduce(const BodyParticles& p, const cl::Buffer& reference, std::uint32_t nbodies);

 private:
  ClRuntime& cl_;
  std::uint32_t materials_ = 0;
  cl::Buffer mass_scale_;
  cl::Kernel k_hist_, k_scan_, k_offsets_, k_scatter_, k_pieces_, k_totals_;
  // Scratch, grown on demand: histogram, counts, offsets, grouped order, pieces, totals, error flags.
  cl::Buffer hist_, count_, offsets_, order_, pieces_, totals_, bad_;
  std::size_t hist_cap_ = 0, bodies_cap_ = 0, particles_cap_ = 0, pieces_cap_ = 0;
};

}  // namespace thaw

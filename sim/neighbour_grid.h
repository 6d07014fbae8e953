#pragma once
// The neighbour grid stage: cell keys, a stable radix sort of the particles by cell, the reorder of every
// declared field into that order (ParticleStore::reorder, which also writes the structure-of-arrays copy
// the neighbour loops read) and each cell's range of sorted particles (sim/kernels/grid.cl). Every
// stage that visits neighbours reads what this one leaves: view().
#include <CL/opencl.hpp>
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/cl_grid.h"
#include "sim/cl_runtime.h"
#include "sim/particle_store.h"
#include "sim/scene.h"
#include "sim/stage.h"

namespace thaw {

// Cell geometry of the neighbour grid (for reference loops and tests).
struct GridInfo {
  Eigen::Vector3f origin;
  float cell = 0;
  int nx = 0, ny = 0, nz = 0;
  Eigen::Vector3f cells = Eigen::Vector3f::Zero();  // cell size per axis: `cell`, or a periodic axis's
  int reach = 1;                                    // cells visited on each side
};
ClGrid cl_grid(const GridInfo& g);

class NeighbourGrid {
 public:
  // Cells of support / reach over the domain and every particle (min, max) plus one cell; whole cells
  // along periodic axes. Throws SceneError ("spacing") when the grid would need more than 2^28 cells.
  // `layout` (the solver's, which must outlive the grid) gives the particle count and the tiles.
  NeighbourGrid(ClRuntime& cl, const Scene& scene, float support, int reach, const std::string& build_options,
                const ParticleLayout& layout, const Eigen::Vector3f& particle_min,
                const Eigen::Vector3f& particle_max);

  // Sorts the particles by cell: keys (clamping particles that left the domain through a closed side
  // back into it and counting them in `clamped`), the radix sort, the reorder of every field of `store`,
  // the cell ranges. Returns how many particles are still in: those that left through an open side
  // (Scene::open_faces) or that an air dryer took in (sim/emitters.h) are sorted behind them, in no cell,
  // for the caller to remove.
  // `owed` (scenes with air dryers: EmitterStage::owed()) holds, per dryer, the particles it has blown
  // and not yet taken in: the air in a dryer's mouth is always taken in, the air in its body while owed.
  std::size_t build(ParticleStore& store, const CoreFields& f, const cl::Buffer& clamped,
                    std::vector<double>* owed = nullptr);

  // Air dryers: their pipes' air set moving out at the exit speed (grid.cl, pipe_drive), with the
  // dryers as the last build() saw them. Nothing without blowing air dryers.
  void drive_pipes(ParticleStore& store, const CoreFields& f);

  // Open sides with air (EmitterStage::room_sites): the sites that no particle is within `gap` [m] of, in
  // increasing order, each with the kernel-weighted mean velocity of the moving particles around it, from
  // the positions as they are now and the cells of the last build() (grid.cl, empty_sites). Nothing
  // without room air. The sites are set once: set_room_sites.
  struct EmptySites {
    std::vector<std::uint32_t> site;
    std::vector<Eigen::Vector3f> velocity;
  };
  void set_room_sites(const std::vector<Eigen::Vector3d>& sites);
  EmptySites empty_sites(ParticleStore& store, const CoreFields& f, double gap);

  NeighbourView view() const { return {soa_, layout_.stride, cell_start_, cl_grid(info_)}; }
  const GridInfo& info() const { return info_; }
  const cl::Buffer& cell_start() const { return cell_start_; }
  const cl::Buffer& soa() const { return soa_; }
  std::vector<std::uint32_t> cell_starts() const;  // read back: ncells + 1 entries

 private:
  ClRuntime& cl_;
  const Scene& scene_;
  const ParticleLayout& layout_;
  GridInfo info_;
  bool intake_ = false;            // the scene has air dryers: the key pass takes in what their intakes hold
  std::vector<cl_uint2> flagged_;  // (index, flag) of the particles intake_flags listed
  std::uint32_t ncells_ = 0, sort_passes_ = 0, radix_bits_ = 8;
  cl_uint blowing_ = 0;  // air dryers blowing at the last build()
  float support_ = 0;
  cl_uint room_sites_ = 0;
  cl::Kernel k_empty_sites_, k_pipe_drive_, k_intake_flags_, k_set_flags_, k_cell_keys_, k_hist_,
      k_chunk_counts_, k_scan_chunks_, k_scan_tiles_, k_scatter_, k_starts_;
  cl::Buffer keys_[2], order_[2], hist_, totals_, chunks_, cell_start_, soa_, intakes_, take_, listed_, list_,
      sites_, site_out_, empty_, site_vel_;
};

}  // namespace thaw

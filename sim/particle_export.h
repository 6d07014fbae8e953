#pragma once
// Particle frames for other tools: VTK XML (.vtu per frame, one particles.pvd collection) for ParaView,
// binary PLY for Blender. Particles are written in id order so frames compare across steps whatever
// the device's sort order; every file is replaced atomically so a reader never sees half a frame and an
// interrupted run leaves a valid collection.
#include <cstddef>
#include <string>
#include <vector>

#include "sim/particles.h"

namespace thaw {

class ParticleExporter {
 public:
  // Creates `dir` and its parents; throws thaw::Error if that is not possible. Frames are numbered from
  // 0, so an existing particles.pvd in `dir` is replaced by this run's.
  explicit ParticleExporter(std::string dir);

  // Writes frame_%06d.vtu and frame_%06d.ply for simulated time `time` [s], then rewrites particles.pvd.
  // `temperature` [°C], one per particle in p's order, is written when not empty (scenes with heat).
  void write(const HostParticles& p, double time, const std::vector<float>& temperature = {});

  std::size_t frames() const { return times_.size(); }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  std::vector<double> times_;  // of every frame written, for the .pvd
};

}  // namespace thaw

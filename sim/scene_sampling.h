#pragma once
// Turning a scene into particles (sim/scene_sampling.cpp): the state a run starts from.
#include <Eigen/Core>
#include <vector>

#include "sim/particles.h"
#include "sim/scene.h"
#include "sim/state_file.h"

namespace thaw {

// Samples a scene into particles: fluid blocks on a lattice, static solids and domain walls as
// boundary particles (their Psi is computed on the device when the solver starts).
HostParticles sample_scene(const Scene& scene);

// Where the room's air comes in through the open sides (Scene::open_faces) of a scene with air: the points
// of the air's lattice (its region, less solids and air dryers' pipes) within one spacing of an open
// side. Empty without air or open sides. EmitterStage lays air at those that no particle is near.
std::vector<Eigen::Vector3d> room_air_sites(const Scene& scene);

// The state a run starts from: sampled particles at t = 0.
SimState initial_state(const Scene& scene);

}  // namespace thaw

#pragma once
// The scene most cases and benchmarks use: a block of water in one corner of an open-top tank whose
// five other sides are walls, both starting at the origin. Built as a document so it is validated like
// any scene file.
#include <Eigen/Core>
#include <string>

#include "sim/scene.h"

namespace thaw {

struct TankScene {
  std::string name;
  Eigen::Vector3d tank;   // tank size [m], from the origin; open at +z
  Eigen::Vector3d water;  // water block size [m], from the origin
  double spacing = 0.01;  // [m]
  double gravity = 9.81;  // along -z [m/s^2]
  double density = 1000.0;
  double viscosity = 1.0e-3;
  Json solver = Json::object();  // the "solver" section, defaults where absent
  bool heat = false;             // thermal stages: water at 30 °C in 20 °C air (benchmarks); off for mechanics
};

Json tank_scene_json(const TankScene& t);

}  // namespace thaw

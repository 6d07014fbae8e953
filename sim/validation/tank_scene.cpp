#include "sim/validation/tank_scene.h"

namespace thaw {

Json tank_scene_json(const TankScene& t) {
  auto vec = [](const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); };
  return {
      {"name", t.name},
      {"domain",
       {{"min", {0, 0, 0}},
        {"max", vec(t.tank)},
        {"walls", {"-x", "+x", "-y", "+y", "-z"}},
        {"wall_material", "wall"}}},
      {"gravity", {0, 0, -t.gravity}},
      {"spacing", t.spacing},
      {"solver", t.solver},
      // The validation cases measure pressure and flow; heat would only add cost to them.
      {"heat", {{"enabled", t.heat}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", t.density},
          {"viscosity", t.viscosity},
          {"conductivity", 0.56},
          {"specific_heat", 4217.0}}},
        {"wall", {{"kind", "solid"}, {"density", 2500.0}, {"conductivity", 1.0}, {"specific_heat", 840.0}}}}},
      {"fluids",
       {{{"material", "water"},
         {"box", {{"min", {0, 0, 0}}, {"max", vec(t.water)}}},
         {"temperature", 30.0}}}},
  };
}

}  // namespace thaw

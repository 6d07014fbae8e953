#pragma once
// The particle view: every particle as a small shaded sphere (drawn on the CPU with a depth buffer),
// coloured by phase, temperature, speed or a substance's concentration with a colour bar; and the slice
// view: temperature, speed or a substance on
// a plane through the scene, interpolated from the particles near it.
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/colour_map.h"
#include "render/image.h"
#include "render/snapshot.h"

namespace thaw {

// The colourings the particle view knows ("phase", "temperature", "speed"; the slice view takes the last
// two), for every place that accepts one (CLI, protocol, render worker).
const std::vector<std::string>& colourings();
// Besides those, "substance:<name>": the concentration of one of the scene's substances [g/L] (a name the
// scene lacks shows temperature).
inline constexpr const char* kSubstanceColouring = "substance:";
// Error "<what>: unknown colouring '<value>'; available: phase, temperature, speed" unless value is one.
void check_colouring(const std::string& value, const std::string& what);

struct ParticleViewOptions {
  std::string colour_by = "phase";  // "phase" | "temperature" | "speed" | "substance:<name>"
  // The scale [°C or m/s]; t_min == t_max: the particles' own range (temperature over ice, water and air;
  // for speed 0 to the fastest water or air particle).
  double t_min = 0, t_max = 0;
  bool solids = true;  // draw static solids (walls, plates); glass only when coloured by phase
};

struct ViewImage {
  Image image;
  double t_min = 0, t_max = 0;  // the scale used (colour bar bottom and top) [°C or m/s]
  ColourBar bar;                // where the colour bar is; empty for phase colours
};

ViewImage render_particles(const RenderSnapshot& s, const OrbitCamera& camera, const ParticleViewOptions& o);

struct SliceOptions {
  int axis = 1;                           // the plane's normal: 0 x, 1 y, 2 z
  double position = 0.5;                  // where along that axis, as a fraction of the domain
  std::string colour_by = "temperature";  // "speed": |v|; "substance:<name>": its g/L; else temperature
  double t_min = 0, t_max = 0;
  int width = 640, height = 480;
};

// Temperature or speed by Shepard interpolation (sum T_j W / sum W, W the cubic spline over 2 spacings) on
// the plane, framed to the domain; pixels with no particle within reach show the background.
ViewImage render_slice(const RenderSnapshot& s, const SliceOptions& o);

}  // namespace thaw

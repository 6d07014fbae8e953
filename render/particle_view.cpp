#include "render/particle_view.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "sim/error.h"
#include "sim/kernels/sph_kernel.h"
#include "sim/particles.h"

namespace thaw {
namespace {

// A neutral vertical gradient, lighter at the top.
Image background(int w, int h) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(std::size_t(w) * h * 4, 0);
  for (int y = 0; y < h; ++y) {
    const double t = double(y) / std::max(1, h - 1);
    const auto v = static_cast<std::uint8_t>(std::lround(235 - 60 * t));
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &img.rgba[(std::size_t(y) * w + x) * 4];
      p[0] = p[1] = v;
      p[2] = static_cast<std::uint8_t>(std::min(255, v + 6));
      p[3] = 255;
    }
  }
  return img;
}

// The temperature scale: the given one, else the range over ice, water and air (all particles without
// any). Air counts so that a dryer's warm jet shows beside the ice it melts: over ice and water alone, a
// scene's 22 to 70 °C air all took the top colour (the scale -4 to 0 °C in ice-air-dryer's slice).
void temperature_range(const RenderSnapshot& s, double& lo, double& hi) {
  if (lo < hi) return;
  if (s.temperature.empty()) throw Error("colouring by temperature needs a scene with heat");
  lo = std::numeric_limits<double>::infinity();
  hi = -lo;
  for (int pass = 0; pass < 2 && !(lo <= hi); ++pass)
    for (std::size_t i = 0; i < s.temperature.size(); ++i) {
      const auto ph = static_cast<Phase>(s.phase[i]);
      if (pass == 0 && ph != Phase::Water && ph != Phase::Ice && ph != Phase::Air) continue;
      lo = std::min(lo, double(s.temperature[i]));
      hi = std::max(hi, double(s.temperature[i]));
    }
  if (!(lo <= hi)) lo = hi = 0;
  if (hi - lo < 1e-3) {
    lo -= 0.5;
    hi += 0.5;
  }
}

// The speed scale: the given one, else 0 to the fastest water or air (all particles without any).
void speed_range(const RenderSnapshot& s, double& lo, double& hi) {
  if (lo < hi) return;
  if (s.speed.size() != s.position.size()) throw Error("colouring by speed needs the particles' velocities");
  lo = 0;
  hi = 0;
  bool flowing = false;
  for (std::size_t i = 0; i < s.speed.size(); ++i) {
    const auto ph = static_cast<Phase>(s.phase[i]);
    if (ph != Phase::Water && ph != Phase::Air) continue;
    flowing = true;
    hi = std::max(hi, double(s.speed[i]));
  }
  if (!flowing)
    for (float v : s.speed) hi = std::max(hi, double(v));
  if (hi < 1e-3) hi = 1e-3;
}

// What a scalar view draws: temperature [°C] or speed [m/s], with its scale (the given one, or the
// particles' range) and the colour bar's unit.
struct Scalar {
  const std::vector<float>* values;
  BarUnit unit;
};
Scalar scalar_of(const RenderSnapshot& s, const std::string& colour_by, double& lo, double& hi) {
  if (colour_by.rfind(kSubstanceColouring, 0) == 0) {
    const std::string name = colour_by.substr(std::strlen(kSubstanceColouring));
    for (const auto& [sub, values] : s.substances) {
      if (sub != name || values.size() != s.position.size()) continue;
      // 0 to the most any particle holds, as for speed.
      if (!(lo < hi)) {
        lo = 0;
        hi = 0;
        for (float v : values) hi = std::max(hi, double(v));
        if (hi <= 0) hi = 1e-3;
      }
      return {&values, BarUnit::GramsPerLitre};
    }
    // A substance this scene does not have (the scene changed under the view): temperature, as the slice
    // shows for anything but speed.
  }
  if (colour_by == "speed") {
    speed_range(s, lo, hi);
    return {&s.speed, BarUnit::MetresPerSecond};
  }
  temperature_range(s, lo, hi);
  return {&s.temperature, BarUnit::Celsius};
}

}  // namespace

const std::vector<std::string>& colourings() {
  static const std::vector<std::string> names = {"phase", "temperature", "speed"};
  return names;
}

void check_colouring(const std::string& value, const std::string& what) {
  const auto& names = colourings();
  if (std::find(names.begin(), names.end(), value) != names.end()) return;
  const std::size_t n = std::strlen(kSubstanceColouring);
  if (value.size() > n && value.compare(0, n, kSubstanceColouring) == 0) return;
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  throw Error(what + ": unknown colouring '" + value + "'; available: " + list + ", " + kSubstanceColouring +
              "<name>");
}

ViewImage render_particles(const RenderSnapshot& s, const OrbitCamera& cam, const ParticleViewOptions& o) {
  check_colouring(o.colour_by, "particle view");
  ViewImage out;
  out.image = background(cam.width, cam.height);
  const bool by_t = o.colour_by != "phase";
  out.t_min = o.t_min;
  out.t_max = o.t_max;
  const Scalar field =
      by_t ? scalar_of(s, o.colour_by, out.t_min, out.t_max) : Scalar{nullptr, BarUnit::Celsius};

  // Coloured by a coating, the solids and ice it sticks to show it as a stain, the deeper the more they hold
  // (up to the most any holds), over their phase's colour.
  const std::vector<float>* stain = nullptr;
  double stain_max = 0;
  if (o.colour_by.rfind(kSubstanceColouring, 0) == 0)
    for (const auto& [sub, values] : s.deposits)
      if (sub == o.colour_by.substr(std::strlen(kSubstanceColouring)) && values.size() == s.position.size()) {
        stain = &values;
        for (float v : values) stain_max = std::max(stain_max, double(v));
      }
  const Eigen::Matrix4f view = cam.view();
  const double focal = 0.5 * cam.height / std::tan(0.5 * cam.fov * M_PI / 180.0);
  const double radius = 0.5 * s.spacing;
  const Eigen::Vector3d light = Eigen::Vector3d(-0.4, 0.5, 0.75).normalized();  // camera space
  std::vector<float> depth(std::size_t(cam.width) * cam.height, std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (!o.solids && static_cast<Phase>(s.phase[i]) == Phase::Solid) continue;
    // Coloured by a field, glass (a transparent solid) is clear, as in the surface view: a closed glass
    // room or cup would otherwise hide all the air or water whose field was asked for.
    if (by_t && !s.glass.empty() && s.glass[i]) continue;
    const Eigen::Vector4f c = view * s.position[i].homogeneous();
    const double z = -c.z();  // distance along the view direction
    if (z <= radius) continue;
    const double px = 0.5 * cam.width + focal * c.x() / z - 0.5,
                 py = 0.5 * cam.height - focal * c.y() / z - 0.5;
    const double r = std::max(0.75, focal * radius / z);
    const bool boundary =
        static_cast<Phase>(s.phase[i]) == Phase::Solid || static_cast<Phase>(s.phase[i]) == Phase::Ice;
    Rgb colour = by_t && !(static_cast<Phase>(s.phase[i]) == Phase::Solid)
                     ? cool_warm(((*field.values)[i] - out.t_min) / (out.t_max - out.t_min))
                     : phase_rgb(s.phase[i]);
    if (stain && boundary)
      colour = stained(phase_rgb(s.phase[i]), stain_max > 0 ? (*stain)[i] / stain_max : 0.0);
    const int x0 = std::max(0, int(std::floor(px - r))), x1 = std::min(cam.width - 1, int(std::ceil(px + r)));
    const int y0 = std::max(0, int(std::floor(py - r))),
              y1 = std::min(cam.height - 1, int(std::ceil(py + r)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double u = (x - px) / r, v = (py - y) / r, d2 = u * u + v * v;
        if (d2 > 1.0) continue;
        const double nz = std::sqrt(1.0 - d2);
        const float zz = static_cast<float>(z - nz * radius);
        float& zb = depth[std::size_t(y) * cam.width + x];
        if (zz >= zb) continue;
        zb = zz;
        const double shade = 0.35 + 0.65 * std::max(0.0, u * light.x() + v * light.y() + nz * light.z());
        std::uint8_t* p = &out.image.rgba[(std::size_t(y) * cam.width + x) * 4];
        for (int k = 0; k < 3; ++k)
          p[k] = static_cast<std::uint8_t>(std::lround(colour[std::size_t(k)] * shade));
      }
  }
  if (by_t) {
    out.bar = draw_colour_bar(out.image);
    label_colour_bar(out.image, out.bar, out.t_min, out.t_max, field.unit);
  }
  return out;
}

ViewImage render_slice(const RenderSnapshot& s, const SliceOptions& o) {
  if (o.axis < 0 || o.axis > 2) throw Error("slice: axis must be x, y or z");
  if (!(o.position >= 0 && o.position <= 1)) throw Error("slice: position must be a fraction in [0, 1]");
  ViewImage out;
  out.image = background(o.width, o.height);
  out.t_min = o.t_min;
  out.t_max = o.t_max;
  const Scalar field = scalar_of(s, o.colour_by, out.t_min, out.t_max);
  const std::vector<float>& values = *field.values;
  // In-plane axes: (u, v) = (y, z) for a plane of constant x, (x, z) for y, (x, y) for z; v points up.
  const int a = o.axis, ua = a == 0 ? 1 : 0, va = a == 2 ? 1 : 2;
  const Eigen::Vector3f lo = s.domain_min, hi = s.domain_max;
  const float plane = lo[a] + static_cast<float>(o.position) * (hi[a] - lo[a]);
  const float H = 2.0f * s.spacing;
  // Particles within H of the plane, binned on an in-plane grid of H.
  const float u0 = lo[ua] - H, v0 = lo[va] - H;
  const int nu = int((hi[ua] - lo[ua]) / H) + 3, nv = int((hi[va] - lo[va]) / H) + 3;
  std::vector<std::vector<std::size_t>> bins(std::size_t(nu) * nv);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const Eigen::Vector3f& x = s.position[i];
    if (std::abs(x[a] - plane) >= H) continue;
    const int bu = int((x[ua] - u0) / H), bv = int((x[va] - v0) / H);
    if (bu < 0 || bv < 0 || bu >= nu || bv >= nv) continue;
    bins[std::size_t(bv) * nu + bu].push_back(i);
  }
  // The plane fills the image with its aspect kept.
  const double su = double(hi[ua] - lo[ua]) / o.width, sv = double(hi[va] - lo[va]) / o.height;
  const double scale = std::max(su, sv) * 1.05;
  const double cu = 0.5 * (lo[ua] + hi[ua]), cv = 0.5 * (lo[va] + hi[va]);
#pragma omp parallel for schedule(dynamic, 8)
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      const double u = cu + (x + 0.5 - 0.5 * o.width) * scale, v = cv + (0.5 * o.height - y - 0.5) * scale;
      const int bu = int((u - u0) / H), bv = int((v - v0) / H);
      double sw = 0, st = 0;
      for (int j = bv - 1; j <= bv + 1; ++j)
        for (int i = bu - 1; i <= bu + 1; ++i) {
          if (i < 0 || j < 0 || i >= nu || j >= nv) continue;
          for (std::size_t p : bins[std::size_t(j) * nu + i]) {
            Eigen::Vector3f d = s.position[p];
            d[ua] -= static_cast<float>(u);
            d[va] -= static_cast<float>(v);
            d[a] -= plane;
            const double w = sph::cubic_spline_w(d.norm(), H);
            sw += w;
            st += w * values[p];
          }
        }
      if (sw <= 0) continue;
      const Rgb c = cool_warm((st / sw - out.t_min) / (out.t_max - out.t_min));
      std::uint8_t* px = &out.image.rgba[(std::size_t(y) * o.width + x) * 4];
      px[0] = c[0];
      px[1] = c[1];
      px[2] = c[2];
    }
  out.bar = draw_colour_bar(out.image);
  label_colour_bar(out.image, out.bar, out.t_min, out.t_max, field.unit);
  return out;
}

}  // namespace thaw

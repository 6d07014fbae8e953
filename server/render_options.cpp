#include "server/render_options.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include "sim/error.h"

namespace thaw {

namespace {

// Comma-separated finite numbers, at most `most` of them; an Error quoting `expected` otherwise.
std::vector<double> numbers(const std::string& option, const std::string& text, std::size_t most,
                            const std::string& expected) {
  std::vector<double> out;
  std::istringstream in(text);
  for (std::string part; std::getline(in, part, ',');) {
    std::size_t used = 0;
    double d = 0;
    try {
      d = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || !std::isfinite(d) || out.size() >= most)
      throw Error(option + ": expected " + expected + ", got '" + text + "'");
    out.push_back(d);
  }
  return out;
}

}  // namespace

void use_camera(RenderOptions& o, const SceneCamera& camera) {
  o.azimuth = camera.azimuth;
  o.elevation = camera.elevation;
  o.distance = camera.distance;
  o.fov = camera.fov;
  o.has_target = camera.target.has_value();
  o.target = camera.target.value_or(Eigen::Vector3d::Zero());
}

RenderOptions render_options(const CliArgs& args, const SceneCamera& camera) {
  RenderOptions o;
  use_camera(o, camera);
  if (auto v = args.value("--view")) {
    if (*v != "surface" && *v != "particles" && *v != "slice")
      throw Error("--view: unknown view '" + *v + "'; available: surface, particles, slice");
    o.view = *v;
  }
  if (auto v = args.value("--quality")) {
    if (*v != "full" && *v != "fast") throw Error("--quality: expected full or fast, got '" + *v + "'");
    o.quality = *v;
  }
  if (auto v = args.value("--colour-by")) {
    check_colouring(*v, "--colour-by");
    o.colour_by = *v;
  }
  if (auto v = args.value("--slice")) {
    const std::string axis = v->substr(0, v->find(','));
    if (axis != "x" && axis != "y" && axis != "z")
      throw Error("--slice: expected AXIS[,FRACTION] with AXIS x, y or z, e.g. y,0.5, got '" + *v + "'");
    o.slice_axis = axis[0] - 'x';
    if (v->find(',') != std::string::npos) {
      const std::string f = v->substr(v->find(',') + 1);
      std::size_t used = 0;
      double d = -1;
      try {
        d = std::stod(f, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != f.size() || !(d >= 0 && d <= 1))
        throw Error("--slice: the fraction must be a number in [0, 1], got '" + f + "'");
      o.slice_position = d;
    }
  }
  if (auto v = args.value("--size")) {
    int w = 0, h = 0;
    char x = 0, rest = 0;
    std::istringstream in(*v);
    if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> rest) || w < 16 || h < 16 || w > 8192 ||
        h > 8192)
      throw Error("--size: expected WIDTHxHEIGHT between 16 and 8192 pixels, e.g. 640x480, got '" + *v + "'");
    o.width = w;
    o.height = h;
  }
  if (auto v = args.value("--camera")) {
    const std::string expected =
        "AZIMUTH,ELEVATION[,DISTANCE] in degrees and metres, e.g. 30,25 or 30,25,0.4";
    const std::vector<double> c = numbers("--camera", *v, 3, expected);
    if (c.size() < 2) throw Error("--camera: expected " + expected + ", got '" + *v + "'");
    if (std::abs(c[1]) >= 90.0) throw Error("--camera: elevation must be between -90 and 90 degrees");
    if (c.size() == 3 && c[2] <= 0) throw Error("--camera: distance must be positive");
    o.azimuth = c[0];
    o.elevation = c[1];
    if (c.size() == 3) o.distance = c[2];
  }
  if (auto v = args.value("--target")) {
    const std::string expected = "X,Y,Z in metres, e.g. 0.05,0.05,0.02";
    const std::vector<double> t = numbers("--target", *v, 3, expected);
    if (t.size() != 3) throw Error("--target: expected " + expected + ", got '" + *v + "'");
    o.target = {t[0], t[1], t[2]};
    o.has_target = true;
  }
  if (auto v = args.value("--fov")) {
    o.fov = args.number("--fov", 40.0);
    if (!(o.fov >= 5.0 && o.fov <= 120.0)) throw Error("--fov: expected 5..120 degrees, got '" + *v + "'");
  }
  if (auto v = args.value("--tint-reference")) {
    const double c = args.number("--tint-reference", 0.0);
    if (!(c >= kMinTintReference && c <= kMaxTintReference))
      throw Error("--tint-reference: expected a concentration from " + format_number(kMinTintReference) +
                  " to " + format_number(kMaxTintReference) + " g/L, got '" + *v + "'");
    o.field.tint_reference = static_cast<float>(c);
  }
  if (auto v = args.value("--field-cells")) {
    const long long cells = args.integer("--field-cells", 128);
    if (cells < 16 || cells > 512) throw Error("--field-cells: expected 16..512, got '" + *v + "'");
    o.field.max_cells = static_cast<int>(cells);
  }
  return o;
}

FieldOptions surface_fields(const RenderOptions& o) {
  FieldOptions f = o.field;
  const std::size_t n = std::strlen(kSubstanceColouring);
  f.tint = o.colour_by.rfind(kSubstanceColouring, 0) == 0 ? o.colour_by.substr(n) : std::string();
  if (f.tint.empty()) f.tint_reference = 0;
  return f;
}

FieldOptions TintLatch::apply(FieldOptions fields, double time) const {
  if (!fields.tint.empty() && fields.tint_reference == 0 && fields.tint == substance_ && time >= time_)
    fields.tint_reference = reference_;
  return fields;
}

void TintLatch::remember(const FieldOptions& fields, const DensityFields& built, double time) {
  // Only an automatic frame's reference is latched: one given outright is not what "auto" would pick.
  if (fields.tint.empty() || fields.tint_reference != 0 || !(built.tint_reference > 0)) return;
  if (fields.tint == substance_ && reference_ > 0 && time >= time_) return;
  substance_ = fields.tint;
  reference_ = built.tint_reference;
  time_ = time;
}

OrbitCamera camera_for(const RenderOptions& o, const RenderSnapshot& s) {
  OrbitCamera c = OrbitCamera::framing(s.domain_min.cast<double>(), s.domain_max.cast<double>(), o.azimuth,
                                       o.elevation, o.width, o.height);
  if (o.has_target) c.target = o.target;
  if (o.fov != c.fov) {
    // Keep the framing: the distance that fits the domain scales with 1 / sin(fov / 2).
    const double half_old = 0.5 * c.fov * M_PI / 180.0, half_new = 0.5 * o.fov * M_PI / 180.0;
    c.distance *= std::sin(half_old) / std::sin(half_new);
    c.fov = o.fov;
  }
  // The camera stays where it shows the scene: between kClosest and kFarthest times the framing
  // distance, looking at a point at most one domain diagonal outside the domain. camera.orbit with zoom
  // 100, repeated, grew the distance without bound and a frame took 3.5 s.
  if (o.distance > 0) c.distance = std::clamp(o.distance, kClosest * c.distance, kFarthest * c.distance);
  const Eigen::Vector3d lo = s.domain_min.cast<double>(), hi = s.domain_max.cast<double>();
  const double diagonal = (hi - lo).norm();
  c.target = c.target.cwiseMax((lo.array() - diagonal).matrix()).cwiseMin((hi.array() + diagonal).matrix());
  return c;
}

Image render_cpu_view(const RenderOptions& o, const RenderSnapshot& s, const OrbitCamera& camera) {
  if (o.view == "particles") {
    ParticleViewOptions p;
    p.colour_by = o.colour_by;
    return render_particles(s, camera, p).image;
  }
  SliceOptions slice;
  slice.axis = o.slice_axis;
  slice.position = o.slice_position;
  slice.width = o.width;
  slice.height = o.height;
  slice.colour_by = o.colour_by;
  return render_slice(s, slice).image;
}

FrameRenderer::FrameRenderer(RenderOptions options) : options_(std::move(options)) {
  if (options_.view == "surface") {
    gl_ = std::make_unique<EglContext>();
    surface_ = std::make_unique<SurfaceRenderer>(*gl_);
    surface_->set_quality(options_.quality == "fast" ? SurfaceRenderer::Quality::Fast
                                                     : SurfaceRenderer::Quality::Full);
    surface_->set_scale(options_.scale);
  }
}

Image FrameRenderer::render(const RenderSnapshot& s) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  times_ = {};
  if (surface_) {
    const FieldOptions wanted = tint_.apply(surface_fields(options_), s.time);
    const DensityFields fields = build_density_fields(s, wanted);
    tint_.remember(wanted, fields, s.time);
    times_.field_ms = since(t0);
    surface_->set_sources(s.dryers, s.lamps);
    Image image = surface_->render(fields, camera_for(options_, s));
    const auto t = surface_->last_times();
    times_.upload_ms = t.upload_ms;
    times_.march_ms = t.march_ms;
    times_.readback_ms = t.readback_ms;
    return image;
  }
  Image image = render_cpu_view(options_, s, camera_for(options_, s));
  times_.draw_ms = since(t0);
  return image;
}

std::string FrameRenderer::description() const {
  return gl_ ? gl_->description() : std::string("CPU (") + options_.view + " view)";
}

}  // namespace thaw

#pragma once
// The rendering options `thaw render` and `thaw run --frames` share: image size, camera, view.
#include <memory>
#include <string>

#include "render/camera.h"
#include "render/density_field.h"
#include "render/egl_context.h"
#include "render/image.h"
#include "render/particle_view.h"
#include "render/snapshot.h"
#include "render/surface_renderer.h"
#include "server/cli_args.h"
#include "sim/scene.h"

namespace thaw {

struct RenderOptions {
  std::string view = "surface";  // surface | particles | slice
  // particles: phase | temperature | speed | substance:NAME; slice: speed, a substance or temperature;
  // surface: substance:NAME tints the water by it and stains what a coating sticks to, anything else is the
  // phases
  std::string colour_by = "phase";
  std::string quality = "full";  // surface: full | fast (SurfaceRenderer::Quality)
  double scale = 1.0;            // surface: the fraction of width and height marched (SurfaceRenderer)
  int slice_axis = 1;            // slice: the plane's normal axis
  double slice_position = 0.5;   // slice: fraction of the domain along it
  int width = 640, height = 480;
  double azimuth = 30.0, elevation = 25.0;
  double distance = 0.0;  // 0: frame the domain
  bool has_target = false;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // default: the domain's centre
  double fov = 40.0;                                 // vertical [deg]
  FieldOptions field;
};

// The option names, for CliArgs: --size WxH, --camera AZ,EL[,DIST], --target X,Y,Z, --fov DEG, --view NAME,
// --colour-by phase|temperature|speed|substance:NAME, --slice AXIS[,FRACTION], --field-cells N, --quality
// full|fast, --tint-reference G/L.
inline const char* const kRenderValueOptions[] = {"--size",    "--camera",        "--target", "--fov",
                                                  "--view",    "--colour-by",     "--slice",  "--field-cells",
                                                  "--quality", "--tint-reference"};

// Puts the scene's camera (its `camera` block) into the options.
void use_camera(RenderOptions& o, const SceneCamera& camera);

// Reads the options, starting from the scene's camera; a malformed value is an Error naming the option and
// what was expected.
RenderOptions render_options(const CliArgs& args, const SceneCamera& camera);

// How close and how far the camera may go, in multiples of the distance that frames the domain.
inline constexpr double kClosest = 0.05, kFarthest = 8.0;

// The fields the surface view builds: the options' own, with the tint of a colouring by a substance.
FieldOptions surface_fields(const RenderOptions& o);

// The tint's reference concentration, latched from the first frame that holds the substance so that a run's
// frames share one scale (a dye that spreads and dilutes then fades, as it would to the eye). A new
// substance, or a snapshot earlier than the latched one (another scene, a reset), takes a new one.
class TintLatch {
 public:
  // `fields` with the latched reference, when there is one for its substance and `time`.
  FieldOptions apply(FieldOptions fields, double time) const;
  // Remembers what an automatic frame (reference 0) built with `fields` used.
  void remember(const FieldOptions& fields, const DensityFields& built, double time);

 private:
  std::string substance_;
  float reference_ = 0;
  double time_ = 0;
};

// The camera for a snapshot: the options' angles, framing the scene's domain unless a distance is given.
OrbitCamera camera_for(const RenderOptions& o, const RenderSnapshot& s);

// The views drawn on the CPU (particles, slice) in the options' settings.
Image render_cpu_view(const RenderOptions& o, const RenderSnapshot& s, const OrbitCamera& camera);

// Renders snapshots in the options' view; the EGL context is made only for the surface view.
class FrameRenderer {
 public:
  explicit FrameRenderer(RenderOptions options);
  Image render(const RenderSnapshot& s);
  // Milliseconds of the last frame by stage: field, upload, march, read-back (surface), or draw (others).
  struct Times {
    double field_ms = 0, upload_ms = 0, march_ms = 0, readback_ms = 0, draw_ms = 0;
  };
  const Times& last_times() const { return times_; }
  std::string description() const;

 private:
  RenderOptions options_;
  std::unique_ptr<EglContext> gl_;
  std::unique_ptr<SurfaceRenderer> surface_;
  TintLatch tint_;
  Times times_;
};

}  // namespace thaw

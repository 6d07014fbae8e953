#pragma once
// The metaball view (docs/ARCHITECTURE.md, Renderer): the iso-surfaces of the ice, water and solid density
// fields, ray-marched in a fragment shader (render/shaders/surface.frag) into an off-screen RGBA8 framebuffer
// and read back as an Image.
//
// What goes to the GPU per frame, and why:
//   u_field   R32F, one node per texel: the max of the three phases. Its iso-surface is the union of
//             the phases' surfaces, so the march reads one texture per step (a 32-bit float fetch is the
//             cheapest on llvmpipe; docs/ARCHITECTURE.md, machine facts).
//   u_phases  RGBA8: ice, water, solid clamped to [0, 1]; read only at hits and inside ice and water to
//             tell the phases apart, where 8 bits around iso are plenty.
//   u_tint    RG16F, only coloured by a substance: the dye and stain fields (DensityFields), read per step
//             inside water and at hits on solids and ice.
//   u_blocks  RGBA32F, one texel per block of kBlock^3 cells. R: empty-space skipping, the Chebyshev
//             distance in blocks to the nearest block that may hold surface (one with a node at or above
//             iso; trilinear values never exceed their nodes), so a ray jumps out of the whole empty cube
//             around it at once (a distance map, as in Cohen & Sheffer 1994, "Proximity clouds"). G: the
//             fraction of the block's nodes inside any phase (wide ambient occlusion). B: transmittance
//             toward the key light, marched on the CPU over the blocks (soft shadows for one fetch).
// Without OES_texture_float_linear the float textures fall back to R16F/RGBA16F, filterable in ES 3.0.
#include <GLES3/gl3.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "render/camera.h"
#include "render/density_field.h"
#include "render/egl_context.h"
#include "render/image.h"
#include "render/snapshot.h"

namespace thaw {

class SurfaceRenderer {
 public:
  // Builds the shaders; `context` must be current on this thread whenever the renderer is used.
  explicit SurfaceRenderer(EglContext& context);
  ~SurfaceRenderer();
  SurfaceRenderer(const SurfaceRenderer&) = delete;
  SurfaceRenderer& operator=(const SurfaceRenderer&) = delete;

  // Uploads `fields` and draws them as seen by `camera` (camera.width x camera.height pixels).
  Image render(const DensityFields& fields, const OrbitCamera& camera);
  // Draws the fields uploaded last from another camera, e.g. orbiting a paused scene (no upload).
  Image render(const OrbitCamera& camera);
  // The dryers and lamps drawn with the next frames (at most kMaxDryers and kMaxLamps of each).
  void set_sources(std::vector<DryerMarker> dryers, std::vector<LampMarker> lamps) {
    dryers_ = std::move(dryers);
    lamps_ = std::move(lamps);
  }
  static constexpr int kMaxDryers = 4, kMaxLamps = 4;

  struct Times {
    double upload_ms = 0;    // CPU preparation (max field, phases, blocks) and texture upload
    double march_ms = 0;     // the draw, to completion (glFinish)
    double readback_ms = 0;  // glReadPixels and the row flip
  };
  Times last_times() const { return times_; }

  // What shows through ice and water. Full: the next surface behind them, shaded. Fast: only what lies
  // inside them (solids, other phases) and the background; the march of a 640x480 frame takes about a
  // quarter less (docs/RENDERING.md).
  enum class Quality { Full, Fast };
  void set_quality(Quality q);
  Quality quality() const { return quality_; }

  // The fraction of the image's width and height the march draws (kMinScale..1): below 1 the march fills
  // a smaller framebuffer that a linear blit stretches to the camera's size (dynamic resolution, as
  // ParaView's web viewers reduce the image while the user interacts). The march's cost goes with the
  // pixels, the scale squared; the blit costs about a millisecond at 640x480 on llvmpipe.
  void set_scale(double scale);
  double scale() const { return scale_; }
  static constexpr double kMinScale = 0.25;
  // The size the march draws for an image of width x height at `scale`.
  static int marched(int pixels, double scale);

  static constexpr int kBlock = 4;         // cells per empty-space block along each axis
  static constexpr int kMaxSkip = 16;      // blocks (64 cells): the cap of the distance map
  static constexpr int kShadowSteps = 16;  // blocks toward the light that can shadow a point
  // The dye's absorption per grid length at its reference concentration, in its most absorbed channel: a
  // tenth of the grid's length of water at the reference takes about two thirds of that channel.
  static constexpr float kDyeStrength = 12.0f;
  // Shadow extinction per cell of light path inside ice, water, solid: translucent phases cast pale
  // shadows, solids dark ones.
  static constexpr float kShadowExtinction[4] = {0.06f, 0.02f, 0.45f, 0.03f};  // ice, water, solid, glass

 private:
  void upload(const DensityFields& fields);
  void upload_tint(const DensityFields& fields);  // into tint_, allocated on the volume's first tinted frame
  std::vector<DryerMarker> dryers_;
  std::vector<LampMarker> lamps_;
  void resize_volume(int nx, int ny, int nz);
  void resize_target(int width, int height);
  void resize_marched(int width, int height);

  EglContext& context_;
  GLuint program_ = 0, vao_ = 0, fbo_ = 0, colour_ = 0;
  GLuint field_ = 0, phases_ = 0, blocks_ = 0, tint_ = 0;
  int width_ = 0, height_ = 0;
  // The smaller framebuffer the march draws into when scale_ < 1.
  GLuint marched_fbo_ = 0, marched_colour_ = 0;
  int marched_width_ = 0, marched_height_ = 0;
  double scale_ = 1.0;
  int nodes_[3] = {0, 0, 0}, block_count_[3] = {0, 0, 0};
  bool has_volume_ = false;
  FieldGrid grid_;
  float iso_ = 0.5f;
  // Staging buffers, kept between frames so a steady stream of uploads does not reallocate.
  std::vector<float> max_field_, block_data_, extinction_, tint_data_;
  std::vector<std::uint8_t> phase_bytes_, skip_distance_;
  Times times_;
  Quality quality_ = Quality::Full;
  // A variant per quality and per what the frame has: glass, dryers or lamps, a tint (a glass or dryer branch
  // left in the shader slowed the march of every frame by a quarter on llvmpipe). Built when first used.
  GLuint programs_[16] = {};
  GLuint program_for(Quality q, bool glass, bool sources, bool tint);
  GLuint current_program();
  bool has_glass_ = false;  // the fields uploaded last have glass
  bool has_tint_ = false;   // ... a dye or a stain
  Eigen::Vector3f dye_absorption_ = Eigen::Vector3f::Zero(), stain_colour_ = Eigen::Vector3f::Ones();
};

}  // namespace thaw

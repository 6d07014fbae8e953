// The renderer's parts, headless (CI has no GPU: Mesa llvmpipe through EGL's surfaceless platform):
// the EGL context, PNG/JPEG encoding, the ray caster against analytic fields whose images are known
// (a sphere's silhouette, ice against water, a golden image), and CPU picking.
#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>

#include "render/egl_context.h"
#include "render/image_io.h"
#include "render/picking.h"
#include "render/snapshot.h"
#include "render/surface_renderer.h"
#include "sim/error.h"
#include "sim/scene.h"
#include "tests/render/lattice_snapshot.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;
using Eigen::Vector3f;

// An empty field grid of n nodes along its longest axis over the box [lo, hi].
DensityFields empty_fields(const Vector3f& lo, const Vector3f& hi, int n) {
  DensityFields f;
  f.grid.origin = lo;
  f.grid.cell = (hi - lo).maxCoeff() / float(n - 1);
  f.grid.nx = int(std::lround((hi.x() - lo.x()) / f.grid.cell)) + 1;
  f.grid.ny = int(std::lround((hi.y() - lo.y()) / f.grid.cell)) + 1;
  f.grid.nz = int(std::lround((hi.z() - lo.z()) / f.grid.cell)) + 1;
  f.ice.assign(f.grid.size(), 0.0f);
  f.water.assign(f.grid.size(), 0.0f);
  f.solid.assign(f.grid.size(), 0.0f);
  return f;
}

// Adds a body given by its signed distance: f = clamp(0.5 - sdf / width, 0, 1), so the iso 0.5 surface
// is the zero set of sdf and the field ramps over `width` metres around it (a sphere of radius R with
// width R gives f = clamp(1.5 - r / R, 0, 1)).
void add_body(DensityFields& f, std::vector<float>& phase, const std::function<float(const Vector3f&)>& sdf,
              float width) {
  const FieldGrid& g = f.grid;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Vector3f p = g.origin + g.cell * Vector3f(float(i), float(j), float(k));
        float& v = phase[g.index(i, j, k)];
        v = std::max(v, std::clamp(0.5f - sdf(p) / width, 0.0f, 1.0f));
      }
}

std::function<float(const Vector3f&)> sphere(const Vector3f& c, float r) {
  return [c, r](const Vector3f& p) { return (p - c).norm() - r; };
}

std::function<float(const Vector3f&)> box(const Vector3f& lo, const Vector3f& hi) {
  return [lo, hi](const Vector3f& p) {
    const Vector3f c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
    const Vector3f q = (p - c).cwiseAbs() - h;
    return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
  };
}

// A sphere of radius R at the origin, alone in a grid over [-1.5 R, 1.5 R]^3 (the field is 0 at the box).
DensityFields sphere_fields(std::vector<float> DensityFields::*phase, float radius, int n) {
  DensityFields f = empty_fields(Vector3f::Constant(-1.5f * radius), Vector3f::Constant(1.5f * radius), n);
  add_body(f, f.*phase, sphere(Vector3f::Zero(), radius), radius);
  return f;
}

// The golden scene: an ice sphere resting on a solid slab, beside a water block standing on it. `cubic`
// puts it in a cube of n^3 nodes (the timings' 128^3), otherwise in a box fitted around it.
DensityFields scene_fields(int n, bool cubic = false) {
  DensityFields f = cubic ? empty_fields(Vector3f(-0.40f, -0.40f, -0.12f), Vector3f(0.40f, 0.40f, 0.68f), n)
                          : empty_fields(Vector3f(-0.40f, -0.30f, -0.12f), Vector3f(0.40f, 0.30f, 0.30f), n);
  const float w = 2.0f * f.grid.cell;  // a ramp of two cells, like particle metaballs
  add_body(f, f.solid, box({-0.36f, -0.26f, -0.08f}, {0.36f, 0.26f, 0.0f}), w);
  add_body(f, f.ice, sphere({-0.13f, 0.0f, 0.11f}, 0.11f), w);
  add_body(f, f.water, box({0.04f, -0.18f, 0.0f}, {0.32f, 0.18f, 0.10f}), w);
  return f;
}

OrbitCamera scene_camera(int width, int height) {
  OrbitCamera c = OrbitCamera::framing({-0.36, -0.26, -0.08}, {0.36, 0.26, 0.22}, 35.0, 28.0, width, height);
  c.distance *= 0.85;
  return c;
}

// A camera looking at the origin from `distance` with the sphere at the image centre.
OrbitCamera centred_camera(double distance, int width, int height) {
  OrbitCamera c;
  c.azimuth = 20.0;
  c.elevation = 15.0;
  c.distance = distance;
  c.width = width;
  c.height = height;
  return c;
}

bool differs(const Image& a, const Image& b, int x, int y, int tolerance) {
  for (int ch = 0; ch < 3; ++ch)
    if (std::abs(int(a.pixel(x, y)[ch]) - int(b.pixel(x, y)[ch])) > tolerance) return true;
  return false;
}

// Pixels where two images of one size differ by more than `tolerance` in some channel.
long changed_pixels(const Image& a, const Image& b, int tolerance) {
  long n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) n += differs(a, b, x, y, tolerance);
  return n;
}

// Pixels that differ from the background image.
long silhouette(const Image& image, const Image& background) {
  long count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) count += differs(image, background, x, y, 2);
  return count;
}

// Area in pixels of a sphere of `radius` at `distance` in the image centre: seen from its centre's
// direction it projects to a disc of angular radius asin(R / d).
double projected_disc(const OrbitCamera& camera, double radius, double distance) {
  const double tan_half = std::tan(0.5 * camera.fov * M_PI / 180.0);
  const double r_px = std::tan(std::asin(radius / distance)) / tan_half * 0.5 * camera.height;
  return M_PI * r_px * r_px;
}

double psnr(const Image& a, const Image& b) {
  double se = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        const double e = double(a.pixel(x, y)[ch]) - double(b.pixel(x, y)[ch]);
        se += e * e;
      }
  const double mse = se / (3.0 * a.width * a.height);
  return mse == 0 ? 999.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

// One context and renderer for the suite: llvmpipe compiles the shader on first use (~100 ms).
class RenderTest : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    context_ = std::make_unique<EglContext>();
    renderer_ = std::make_unique<SurfaceRenderer>(*context_);
  }
  static void TearDownTestSuite() {
    renderer_.reset();
    context_.reset();
  }

 protected:
  static SurfaceRenderer& renderer() { return *renderer_; }
  // The picture with no fields: the background alone.
  static Image background(const OrbitCamera& camera) {
    DensityFields none;
    return renderer().render(none, camera);
  }

 private:
  static inline std::unique_ptr<EglContext> context_;
  static inline std::unique_ptr<SurfaceRenderer> renderer_;
};

TEST(EglContextTest, CreatesAndDescribesItself) {
  EglContext context;
  EXPECT_FALSE(context.renderer().empty());
  EXPECT_GE(context.gl_major(), 3);
  EXPECT_NE(context.description().find(context.renderer()), std::string::npos);
  EXPECT_TRUE(context.platform() == "surfaceless" || context.platform().rfind("device", 0) == 0);
  std::printf("[ info ] %s\n", context.description().c_str());
}

TEST(EglContextTest, TwoContextsShareOneDisplay) {
  auto a = std::make_unique<EglContext>();
  {
    EglContext b;  // same display: destroying b must not terminate it under a
  }
  a->make_current();
  EXPECT_NE(glGetString(GL_RENDERER), nullptr);
}

TEST(EglContextTest, ShaderErrorsNameTheFile) {
  EglContext context;
  try {
    build_program("fullscreen.vert", "no_such_shader.frag");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_shader.frag"), std::string::npos) << e.what();
  }
}

TEST(ImageIoTest, PngRoundTripIsExact) {
  Image image(37, 23);
  std::mt19937 rng(7);
  for (auto& b : image.rgba) b = static_cast<std::uint8_t>(rng());
  const std::string png = encode_png(image);
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  const Image back = decode_png(png);
  EXPECT_EQ(back.width, image.width);
  EXPECT_EQ(back.height, image.height);
  EXPECT_EQ(back.rgba, image.rgba);
}

TEST(ImageIoTest, JpegIsJfifOfTheRightSize) {
  Image image(64, 48);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      std::uint8_t* p = image.pixel(x, y);
      p[0] = std::uint8_t(4 * x);
      p[1] = std::uint8_t(5 * y);
      p[2] = 128;
      p[3] = 255;
    }
  const std::string jpeg = encode_jpeg(image, 80);
  ASSERT_GE(jpeg.size(), 4u);
  EXPECT_EQ(std::uint8_t(jpeg[0]), 0xFF);
  EXPECT_EQ(std::uint8_t(jpeg[1]), 0xD8);
  tjhandle tj = tjInitDecompress();
  int w = 0, h = 0, subsampling = 0, colourspace = 0;
  EXPECT_EQ(tjDecompressHeader3(tj, reinterpret_cast<const unsigned char*>(jpeg.data()),
                                static_cast<unsigned long>(jpeg.size()), &w, &h, &subsampling, &colourspace),
            0);
  tjDestroy(tj);
  EXPECT_EQ(w, 64);
  EXPECT_EQ(h, 48);
}

TEST(ImageIoTest, ErrorsSayWhatFailed) {
  EXPECT_THROW(decode_png("not a png"), Error);
  Image bad;
  bad.width = 4;
  bad.height = 4;
  bad.rgba.resize(10);
  EXPECT_THROW(encode_png(bad), Error);
  EXPECT_THROW(encode_jpeg(Image(4, 4), 0), Error);
  try {
    encode_jpeg(bad, 80);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("JPEG"), std::string::npos) << e.what();
  }
}

TEST(ImageIoTest, WritePngReplacesTheFile) {
  testing::TempDir dir("image");
  Image image(5, 3);
  image.pixel(4, 2)[0] = 200;
  const std::string path = dir / "a.png";
  write_png(path, image);
  write_png(path, image);
  EXPECT_EQ(decode_png(testing::read_file_bytes(path)).rgba, image.rgba);
  EXPECT_THROW(write_png((dir / "missing") + "/a.png", image), Error);
}

TEST_F(RenderTest, SphereSilhouetteHasTheProjectedArea) {
  const double radius = 0.1, distance = 0.4;
  const DensityFields f = sphere_fields(&DensityFields::solid, float(radius), 128);
  const OrbitCamera camera = centred_camera(distance, 640, 480);
  const Image bg = background(camera);
  const Image image = renderer().render(f, camera);
  const long count = silhouette(image, bg);
  const double area = projected_disc(camera, radius, distance);
  std::printf("[ info ] silhouette %ld px, projected disc %.0f px\n", count, area);
  EXPECT_NEAR(double(count), area, 0.03 * area);
  // The centre is covered, the corners are background.
  EXPECT_TRUE(differs(image, bg, 320, 240, 2));
  EXPECT_FALSE(differs(image, bg, 2, 2, 2));
}

// The same from particles: an ice sphere sampled on a lattice (radius 12 spacings), through the
// metaball fields the runs use. Its surface sits at the sampled radius, so the silhouette matches that
// sphere's projected disc, and picking the centre finds its front point facing the camera.
TEST_F(RenderTest, ParticleSampledSphereHasTheProjectedAreaAndPicksItsFront) {
  const float spacing = 0.1f / 12.0f;
  RenderSnapshot s;
  s.spacing = spacing;
  testing::add_lattice_sphere(s, Vector3f::Zero(), spacing, 12.0f, Phase::Ice);
  const DensityFields f = build_density_fields(s);
  const double radius = 0.1, distance = 0.4;
  const OrbitCamera camera = centred_camera(distance, 640, 480);
  const Image bg = background(camera);
  const Image image = renderer().render(f, camera);
  const long count = silhouette(image, bg);
  const double area = projected_disc(camera, radius, distance);
  std::printf("[ info ] particle sphere (%zu particles): silhouette %ld px, projected disc %.0f px\n",
              s.position.size(), count, area);
  EXPECT_NEAR(double(count), area, 0.04 * area);

  Vector3d hit, normal, eye, dir;
  const double cx = camera.width / 2.0 - 0.5, cy = camera.height / 2.0 - 0.5;
  camera.ray(cx, cy, eye, dir);
  ASSERT_TRUE(pick(f, camera, cx, cy, hit, normal));
  const Vector3d expected = eye + (distance - radius) * dir;
  EXPECT_LT((hit - expected).norm(), 0.5 * spacing) << hit.transpose() << " vs " << expected.transpose();
  // The lattice's steps survive faintly in the blurred field: the normal is the sphere's within about 20
  // degrees (measured 15 at this point), not exactly.
  EXPECT_GT(normal.dot(-dir), std::cos(20.0 * M_PI / 180.0));
}

// The mean colour of the pixels where `image` differs from `reference`.
Eigen::Vector3d mean_where_changed(const Image& image, const Image& reference) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  long n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (differs(image, reference, x, y, 2)) {
        for (int ch = 0; ch < 3; ++ch) sum[ch] += image.pixel(x, y)[ch];
        ++n;
      }
  return sum / double(std::max(n, 1L));
}

TEST_F(RenderTest, IceAndWaterLookDifferent) {
  const OrbitCamera camera = centred_camera(0.4, 160, 120);
  const Image bg = background(camera);
  auto mean_colour = [&](std::vector<float> DensityFields::*phase) {
    const Image image = renderer().render(sphere_fields(phase, 0.1f, 64), camera);
    EXPECT_GT(changed_pixels(image, bg, 2), 1000);
    return mean_where_changed(image, bg);
  };
  const Eigen::Vector3d ice = mean_colour(&DensityFields::ice), water = mean_colour(&DensityFields::water),
                        solid = mean_colour(&DensityFields::solid);
  std::printf("[ info ] mean RGB  ice %.0f %.0f %.0f  water %.0f %.0f %.0f  solid %.0f %.0f %.0f\n", ice[0],
              ice[1], ice[2], water[0], water[1], water[2], solid[0], solid[1], solid[2]);
  EXPECT_GT(ice[2], ice[0] + 10) << "ice should be blue-ish";
  EXPECT_GT(water[2], water[0] + 10) << "water should be blue-ish";
  EXPECT_GT((ice - water).norm(), 40.0);
  EXPECT_LT(std::abs(solid[2] - solid[0]), 10.0) << "solids should be neutral";
}

TEST_F(RenderTest, MatchesTheGoldenImage) {
  const fs::path golden = fs::path(THAW_SOURCE_DIR) / "tests/render/golden/surface_160x120.png";
  const Image image = renderer().render(scene_fields(96), scene_camera(160, 120));
  const char* update = std::getenv("THAW_UPDATE_GOLDEN");
  if (!fs::exists(golden) || (update && std::string(update) == "1")) {
    const bool missing = !fs::exists(golden);
    write_png(golden.string(), image);
    if (missing)
      FAIL() << "wrote the missing golden image " << golden << "; look at it, commit it, run again";
    std::printf("[ info ] rewrote %s (THAW_UPDATE_GOLDEN=1)\n", golden.c_str());
    return;
  }
  const Image expected = decode_png(testing::read_file_bytes(golden));
  ASSERT_EQ(expected.width, image.width);
  ASSERT_EQ(expected.height, image.height);
  const double p = psnr(image, expected);
  EXPECT_GE(p, 30.0) << "PSNR " << p << " dB against " << golden
                     << " (THAW_UPDATE_GOLDEN=1 rewrites it after a deliberate change)";
}

TEST_F(RenderTest, EmptyFieldsGiveTheBackground) {
  const OrbitCamera camera = centred_camera(0.4, 64, 48);
  const Image image = background(camera);
  // Brighter above than below, neutral grey.
  EXPECT_GT(image.pixel(32, 0)[1], image.pixel(32, 47)[1]);
  EXPECT_LT(std::abs(int(image.pixel(32, 24)[0]) - int(image.pixel(32, 24)[2])), 12);
}

// Fast quality drops only what shows through ice and water: a solid alone renders the same, while the
// slab seen through the water block changes.
TEST_F(RenderTest, FastQualityDiffersOnlyBehindIceAndWater) {
  DensityFields solid_only =
      empty_fields(Vector3f(-0.40f, -0.30f, -0.12f), Vector3f(0.40f, 0.30f, 0.30f), 64);
  add_body(solid_only, solid_only.solid, box({-0.36f, -0.26f, -0.08f}, {0.36f, 0.26f, 0.0f}),
           2.0f * solid_only.grid.cell);
  const DensityFields scene = scene_fields(64);
  const OrbitCamera camera = scene_camera(160, 120);
  const Image full_solid = renderer().render(solid_only, camera),
              full_scene = renderer().render(scene, camera);
  renderer().set_quality(SurfaceRenderer::Quality::Fast);
  const Image fast_solid = renderer().render(solid_only, camera),
              fast_scene = renderer().render(scene, camera);
  renderer().set_quality(SurfaceRenderer::Quality::Full);
  EXPECT_EQ(full_solid.rgba, fast_solid.rgba);
  int changed = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) changed += differs(full_scene, fast_scene, x, y, 2);
  EXPECT_GT(changed, 50) << "the water block and the ice sphere show the slab behind them in full quality";
  EXPECT_GT(psnr(full_scene, fast_scene), 20.0) << "and nothing else changes much";
}

// A reduced march stretched to the image: the frame keeps the camera's size and shows the same picture,
// softer (its silhouette within a few percent of the full march's, the PSNR high), but not the same
// pixels; scale 1 is the full march exactly, and a scale outside kMinScale..1 is refused.
TEST_F(RenderTest, AReducedMarchIsStretchedToTheImageAndShowsTheSamePicture) {
  const DensityFields scene = scene_fields(64);
  const OrbitCamera camera = scene_camera(320, 240);
  const Image bg = background(camera);
  const Image full = renderer().render(scene, camera);
  renderer().set_scale(0.5);
  const Image half = renderer().render(scene, camera);
  const Image half_bg = background(camera);
  renderer().set_scale(1.0);
  const Image again = renderer().render(scene, camera);
  ASSERT_EQ(half.width, 320);
  ASSERT_EQ(half.height, 240);
  EXPECT_EQ(again.rgba, full.rgba);
  const long full_area = silhouette(full, bg), half_area = silhouette(half, half_bg);
  const double quality = psnr(full, half);
  std::printf(
      "[ info ] silhouette %ld px marched in full, %ld at half scale; PSNR %.1f dB; %ld pixels differ\n",
      full_area, half_area, quality, changed_pixels(full, half, 2));
  EXPECT_GT(full_area, 5000);
  EXPECT_NEAR(double(half_area), double(full_area), 0.04 * double(full_area));
  EXPECT_GT(quality, 24.0);
  EXPECT_GT(changed_pixels(full, half, 2), 100) << "the half-scale march must not be the full one";
  EXPECT_THROW(renderer().set_scale(0.2), Error);
  EXPECT_THROW(renderer().set_scale(1.5), Error);
  EXPECT_EQ(renderer().scale(), 1.0);
}

// A cup: an open-topped box shell of `wall` thickness into `phase`, its inside [lo, hi] without the top.
void add_cup(DensityFields& f, std::vector<float>& phase, const Vector3f& lo, const Vector3f& hi,
             float wall) {
  const auto outer = box(lo - Vector3f(wall, wall, wall), hi + Vector3f(wall, wall, 0));
  const auto inner = box(lo, hi + Vector3f(0, 0, 2 * wall));
  add_body(
      f, phase, [=](const Vector3f& p) { return std::max(outer(p), -inner(p)); }, 2.0f * f.grid.cell);
}

// Glass shows what it holds: an ice sphere in a glass cup, seen from the side through the wall, changes
// nearly as many pixels against the empty cup as the sphere alone covers against the background, in full
// and in fast quality; in a cup of an opaque solid the same sphere changes none (the wall hides it). The
// glass itself is visible: the empty cup differs from the background. Water in the cup shows the same way
// (the glass box's interior is visible with and without water in it), and an opaque cup hides it.
TEST_F(RenderTest, IceInAGlassCupShowsThroughItsWalls) {
  const Vector3f lo(-0.08f, -0.08f, -0.06f), hi(0.08f, 0.08f, 0.10f);
  const OrbitCamera camera = centred_camera(0.7, 160, 120);  // 15 degrees up: the rim hides the inside
  const Image bg = background(camera);
  auto render_cup = [&](bool glass, bool ice, bool water = false) {
    DensityFields f = empty_fields(Vector3f(-0.12f, -0.12f, -0.10f), Vector3f(0.12f, 0.12f, 0.12f), 64);
    f.glass.assign(f.grid.size(), 0.0f);
    add_cup(f, glass ? f.glass : f.solid, lo, hi, 0.015f);
    if (ice) add_body(f, f.ice, sphere({0.0f, 0.0f, -0.01f}, 0.05f), 2.0f * f.grid.cell);
    if (water) add_body(f, f.water, box(lo, Vector3f(hi.x(), hi.y(), 0.02f)), 2.0f * f.grid.cell);
    return renderer().render(f, camera);
  };
  const auto changed = [](const Image& a, const Image& b) { return changed_pixels(a, b, 6); };
  DensityFields alone = empty_fields(Vector3f(-0.12f, -0.12f, -0.10f), Vector3f(0.12f, 0.12f, 0.12f), 64);
  add_body(alone, alone.ice, sphere({0.0f, 0.0f, -0.01f}, 0.05f), 2.0f * alone.grid.cell);
  const long sphere_pixels = changed(bg, renderer().render(alone, camera));
  for (const auto quality : {SurfaceRenderer::Quality::Full, SurfaceRenderer::Quality::Fast}) {
    renderer().set_quality(quality);
    const Image glass_empty = render_cup(true, false), glass_ice = render_cup(true, true);
    const Image solid_empty = render_cup(false, false), solid_ice = render_cup(false, true);
    const long through_glass = changed(glass_empty, glass_ice),
               through_solid = changed(solid_empty, solid_ice);
    std::printf(
        "[ info ] %s: pixels the ice changes: in glass %ld, in an opaque cup %ld (the sphere alone "
        "covers %ld); glass cup against the background %ld\n",
        quality == SurfaceRenderer::Quality::Full ? "full" : "fast", through_glass, through_solid,
        sphere_pixels, changed(bg, glass_empty));
    EXPECT_GT(through_glass, 0.8 * double(sphere_pixels)) << "the sphere shows through the glass";
    EXPECT_LT(through_solid, 50) << "an opaque wall hides it";
    EXPECT_GT(changed(bg, glass_empty), 1000) << "the glass itself shows";
    const long water_in_glass = changed(glass_empty, render_cup(true, false, true)),
               water_in_solid = changed(solid_empty, render_cup(false, false, true));
    std::printf("[ info ] pixels water in the cup changes: in glass %ld, in an opaque cup %ld\n",
                water_in_glass, water_in_solid);
    EXPECT_GT(water_in_glass, sphere_pixels) << "the water in the glass shows";
    EXPECT_LT(water_in_solid, 50) << "an opaque wall hides it";
  }
  renderer().set_quality(SurfaceRenderer::Quality::Full);
}

// Ice under water shows: an ice sphere wholly inside a water block changes, against the block alone, at
// least half as many pixels as the sphere alone covers, in full and in fast quality.
TEST_F(RenderTest, IceUnderWaterShowsThroughIt) {
  const OrbitCamera camera = centred_camera(0.7, 160, 120);
  const Image bg = background(camera);
  auto render_water = [&](bool ice, bool water) {
    DensityFields f = empty_fields(Vector3f(-0.12f, -0.12f, -0.10f), Vector3f(0.12f, 0.12f, 0.12f), 64);
    // The water's particles make way for the ice's, as in a melt: its field is carved where the ice is.
    const auto block = box({-0.09f, -0.09f, -0.08f}, {0.09f, 0.09f, 0.08f});
    const auto hole = sphere({0.0f, 0.0f, 0.0f}, ice ? 0.05f : 0.0f);
    if (water)
      add_body(
          f, f.water, [=](const Vector3f& p) { return ice ? std::max(block(p), -hole(p)) : block(p); },
          2.0f * f.grid.cell);
    if (ice) add_body(f, f.ice, sphere({0.0f, 0.0f, 0.0f}, 0.05f), 2.0f * f.grid.cell);
    return renderer().render(f, camera);
  };
  const auto changed = [](const Image& a, const Image& b) { return changed_pixels(a, b, 6); };
  const long sphere_pixels = changed(bg, render_water(true, false));
  for (const auto quality : {SurfaceRenderer::Quality::Full, SurfaceRenderer::Quality::Fast}) {
    renderer().set_quality(quality);
    const long under_water = changed(render_water(false, true), render_water(true, true));
    std::printf("[ info ] %s: the ice under water changes %ld pixels (the sphere alone covers %ld)\n",
                quality == SurfaceRenderer::Quality::Full ? "full" : "fast", under_water, sphere_pixels);
    EXPECT_GT(under_water, sphere_pixels / 2);
  }
  renderer().set_quality(SurfaceRenderer::Quality::Full);
}

// Coloured by a dye, water takes the dye's colour, the more the more dye it holds; none leaves it as it was.
TEST_F(RenderTest, DyedWaterTakesTheDyesColourByItsConcentration) {
  const OrbitCamera camera = centred_camera(0.4, 160, 120);
  const Image bg = background(camera);
  const DensityFields clear = sphere_fields(&DensityFields::water, 0.1f, 64);
  const Image plain = renderer().render(clear, camera);
  auto dyed = [&](float share) {
    DensityFields f = clear;
    f.dye = f.water;
    for (float& v : f.dye) v *= share;
    f.tint_colour = {0.78f, 0.08f, 0.30f};
    return renderer().render(f, camera);
  };
  const Image none = dyed(0.0f);
  EXPECT_LT(changed_pixels(none, plain, 2), 20) << "a dye field of zeros changes nothing";
  double last_red_excess = -1e9;
  for (const float share : {0.1f, 0.4f, 1.0f}) {
    const Image image = dyed(share);
    const Eigen::Vector3d m = mean_where_changed(image, bg);
    const double red_excess = m[0] - m[2];
    std::printf("[ info ] dye at %.1f of its reference: mean RGB %.0f %.0f %.0f\n", share, m[0], m[1], m[2]);
    EXPECT_GT(red_excess, last_red_excess + 5) << "more dye, redder";
    last_red_excess = red_excess;
  }
  const Eigen::Vector3d full = mean_where_changed(dyed(1.0f), bg);
  EXPECT_GT(full[0], full[2] + 20) << "water full of a red dye reads red";
  EXPECT_GT(full[0], full[1] + 20);
}

// A coating's stain colours the solid where it sticks, and only there.
TEST_F(RenderTest, AStainColoursTheSolidWhereItSticks) {
  const OrbitCamera camera = scene_camera(160, 120);
  const DensityFields f = scene_fields(64);
  const Image plain = renderer().render(f, camera);
  DensityFields stained = f;
  stained.stain.assign(f.grid.size(), 0.0f);
  const FieldGrid& g = f.grid;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Vector3f p = g.origin + g.cell * Vector3f(float(i), float(j), float(k));
        if (p.x() < -0.28f)
          stained.stain[g.index(i, j, k)] = f.solid[g.index(i, j, k)];  // the slab's end, clear of the ice
      }
  stained.tint_colour = {0.85f, 0.55f, 0.10f};
  const Image image = renderer().render(stained, camera);
  const long changed = changed_pixels(image, plain, 6);
  const Eigen::Vector3d m = mean_where_changed(image, plain);
  std::printf("[ info ] the stain changes %ld pixels, mean RGB %.0f %.0f %.0f\n", changed, m[0], m[1], m[2]);
  if (std::getenv("THAW_TEST_SCREENSHOTS")) write_png("/tmp/stain-test.png", image);
  EXPECT_GT(changed, 80);
  EXPECT_GT(m[0], m[2] + 30) << "stained amber";
  // Only that end, which this camera sees on the right: the left half of the image is untouched.
  long left = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width / 2; ++x) left += differs(image, plain, x, y, 6);
  EXPECT_LT(left, 10);
}

// A tap (an emitter) is drawn as a dryer's nozzle that never blows: the snapshot carries it after the
// dryers, with the nozzle's radius and direction, and it changes the pixels where it is, closed or open.
TEST_F(RenderTest, ATapIsDrawnAsItsNozzle) {
  const Scene scene = load_scene("pour-into-glass");
  ASSERT_EQ(scene.emitters.size(), 1u);
  const Emitter& e = scene.emitters[0];
  const RenderSnapshot s = make_snapshot(HostParticles{}, {}, scene, 0.0, 0);
  ASSERT_EQ(s.dryers.size(), scene.dryers.size() + 1);
  const DryerMarker& tap = s.dryers.back();
  EXPECT_EQ(tap.position, e.position.cast<float>());
  EXPECT_NEAR((tap.direction - e.direction.normalized().cast<float>()).norm(), 0.0f, 1e-6f);
  EXPECT_FLOAT_EQ(tap.nozzle_radius, static_cast<float>(e.radius));
  EXPECT_FALSE(tap.on) << "a tap has no cone";
  const OrbitCamera camera = centred_camera(0.7, 160, 120);
  const DensityFields f = sphere_fields(&DensityFields::ice, 0.05f, 48);
  DryerMarker drawn = tap;
  drawn.position = Vector3f(0.0f, 0.0f, 0.12f);
  drawn.nozzle_radius = 0.015f;
  renderer().set_sources({}, {});
  const Image none = renderer().render(f, camera);
  renderer().set_sources({drawn}, {});
  const Image with_tap = renderer().render(f, camera);
  renderer().set_sources({}, {});
  const long pixels = changed_pixels(none, with_tap, 6);
  std::printf("[ info ] the tap's nozzle changes %ld pixels\n", pixels);
  EXPECT_GT(pixels, 30);
}

// A dryer is drawn where it is and where it points: its nozzle changes pixels against no dryer; blowing,
// its cone changes more; aimed elsewhere, the picture changes (the cone moved); switched off, the cone
// goes and the nozzle stays.
TEST_F(RenderTest, ADryerIsDrawnAndItsAimShows) {
  const OrbitCamera camera = centred_camera(0.7, 160, 120);
  const DensityFields f = sphere_fields(&DensityFields::ice, 0.05f, 48);
  auto with = [&](std::vector<DryerMarker> dryers) {
    renderer().set_sources(std::move(dryers), {});
    return renderer().render(f, camera);
  };
  DryerMarker dryer;
  dryer.position = Vector3f(0.0f, 0.0f, 0.12f);
  dryer.direction = -Vector3f::UnitZ();
  dryer.nozzle_radius = 0.015f;
  dryer.half_angle = 20.0f;
  dryer.reach = 0.2f;
  const Image none = with({}), on = with({dryer});
  DryerMarker aside = dryer, off = dryer;
  aside.direction = Vector3f(0.7f, 0.0f, -0.7f).normalized();
  off.on = false;
  const Image aimed = with({aside}), switched_off = with({off});
  renderer().set_sources({}, {});
  const long nozzle = changed_pixels(none, switched_off, 6), blowing = changed_pixels(none, on, 6);
  const long moved = changed_pixels(on, aimed, 6);
  std::printf("[ info ] pixels changed: the nozzle %ld, nozzle and cone %ld, aimed aside %ld\n", nozzle,
              blowing, moved);
  EXPECT_GT(nozzle, 30) << "a nozzle 3 cm across at 0.7 m covers about 50 pixels here";
  EXPECT_GT(blowing, nozzle + 200);
  EXPECT_GT(moved, 200);
}

// A lamp is drawn as its rectangle: glowing warm on its emitting side while on, a dark panel when off
// or seen from behind.
TEST_F(RenderTest, ALampGlowsOnItsEmittingSide) {
  const OrbitCamera camera = centred_camera(0.7, 160, 120);  // looks from +x (azimuth 20) at the origin
  const DensityFields f = sphere_fields(&DensityFields::ice, 0.05f, 48);
  LampMarker lamp;
  lamp.centre = Vector3f(0.0f, 0.0f, 0.12f);
  lamp.half_u = Vector3f(0.0f, 0.06f, 0.0f);  // cross(u, v) = +x: it faces the camera
  lamp.half_v = Vector3f(0.0f, 0.0f, 0.03f);
  lamp.temperature = 900.0f;
  auto mean_rgb = [&](const LampMarker& l) {
    renderer().set_sources({}, {l});
    const Image image = renderer().render(f, camera);
    const Image none = (renderer().set_sources({}, {}), renderer().render(f, camera));
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    long n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (differs(image, none, x, y, 6)) {
          for (int c = 0; c < 3; ++c) sum[c] += image.pixel(x, y)[c];
          ++n;
        }
    EXPECT_GT(n, 100) << "the lamp covers pixels";
    return Eigen::Vector3d(sum / double(std::max(n, 1L)));
  };
  LampMarker off = lamp, behind = lamp;
  off.on = false;
  behind.half_u = -lamp.half_u;  // now it faces away
  const Eigen::Vector3d glowing = mean_rgb(lamp), dark = mean_rgb(off), back = mean_rgb(behind);
  std::printf("[ info ] lamp mean RGB: on %.0f %.0f %.0f, off %.0f %.0f %.0f, from behind %.0f %.0f %.0f\n",
              glowing[0], glowing[1], glowing[2], dark[0], dark[1], dark[2], back[0], back[1], back[2]);
  EXPECT_GT(glowing[0], glowing[2] + 60) << "warm";
  EXPECT_GT(glowing[0], dark[0] + 100);
  EXPECT_LT(back.norm(), 80.0) << "the back of a lamp is its dark housing";
}

TEST_F(RenderTest, StageTimes) {
  const DensityFields f = scene_fields(128, true);
  std::printf("[ info ] golden scene in a %dx%dx%d field\n", f.grid.nx, f.grid.ny, f.grid.nz);
  for (const auto& [w, h] : {std::pair{320, 240}, std::pair{640, 480}, std::pair{1280, 720}}) {
    renderer().render(f, scene_camera(w, h));  // first use of a size: framebuffer allocation, warm-up
    const Image image = renderer().render(f, scene_camera(w, h));
    const auto t = renderer().last_times();
    std::printf("[ info ] %4dx%-4d upload %6.1f ms  march %7.1f ms  readback %5.1f ms\n", w, h, t.upload_ms,
                t.march_ms, t.readback_ms);
    EXPECT_EQ(image.width, w);
  }
}

TEST(PickingTest, CentreHitsTheSphereFacingTheCamera) {
  const double radius = 0.1, distance = 0.4;
  const DensityFields f = sphere_fields(&DensityFields::ice, float(radius), 128);
  const OrbitCamera camera = centred_camera(distance, 640, 480);
  Vector3d hit, normal, eye, dir;
  camera.ray(camera.width / 2.0 - 0.5, camera.height / 2.0 - 0.5, eye, dir);
  ASSERT_TRUE(pick(f, camera, camera.width / 2.0 - 0.5, camera.height / 2.0 - 0.5, hit, normal));
  const Vector3d expected = eye + (distance - radius) * dir;
  EXPECT_LT((hit - expected).norm(), 0.01 * radius) << hit.transpose() << " vs " << expected.transpose();
  EXPECT_GT(normal.dot(-dir), 0.999);
}

TEST(PickingTest, MissReturnsFalse) {
  const DensityFields f = sphere_fields(&DensityFields::water, 0.1f, 64);
  const OrbitCamera camera = centred_camera(0.4, 640, 480);
  Vector3d hit(7, 7, 7), normal;
  EXPECT_FALSE(pick(f, camera, 0, 0, hit, normal));
  EXPECT_EQ(hit, Vector3d(7, 7, 7));
  EXPECT_FALSE(pick(DensityFields{}, camera, 320, 240, hit, normal));
}

}  // namespace
}  // namespace thaw

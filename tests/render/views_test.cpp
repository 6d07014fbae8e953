// The particle and slice views: colours by phase, temperature and speed, and their colour bar.
#include <gtest/gtest.h>

#include <cmath>

#include "render/colour_map.h"
#include "render/particle_view.h"
#include "sim/error.h"
#include "sim/particles.h"

namespace thaw {
namespace {

RenderSnapshot two_particles(float cold, float hot) {
  RenderSnapshot s;
  s.position = {{-0.05f, 0.0f, 0.0f}, {0.05f, 0.0f, 0.0f}};
  s.phase = {static_cast<std::uint8_t>(Phase::Ice), static_cast<std::uint8_t>(Phase::Water)};
  s.temperature = {cold, hot};
  s.spacing = 0.02f;
  s.domain_min = {-0.1f, -0.1f, -0.1f};
  s.domain_max = {0.1f, 0.1f, 0.1f};
  return s;
}

OrbitCamera front_camera() {
  OrbitCamera c;
  c.azimuth = -90;  // looking along +y: x runs left to right
  c.elevation = 0;
  c.distance = 0.4;
  c.width = 320;
  c.height = 240;
  return c;
}

// Direction of a colour, so shading (a common factor) drops out.
Eigen::Vector3d chroma(const std::uint8_t* p) { return Eigen::Vector3d(p[0], p[1], p[2]).normalized(); }
Eigen::Vector3d chroma(const Rgb& c) { return Eigen::Vector3d(c[0], c[1], c[2]).normalized(); }

// The pixel a world point projects to.
void project(const OrbitCamera& c, const Eigen::Vector3f& x, int& px, int& py) {
  const Eigen::Vector4f v = c.view() * Eigen::Vector4f(x.x(), x.y(), x.z(), 1.0f);
  const double f = 0.5 * c.height / std::tan(0.5 * c.fov * M_PI / 180.0);
  px = static_cast<int>(std::lround(0.5 * c.width + f * v.x() / -v.z() - 0.5));
  py = static_cast<int>(std::lround(0.5 * c.height - f * v.y() / -v.z() - 0.5));
}

TEST(ParticleView, TemperatureColoursMapAKnownHotAndColdParticleToTheColourBarEnds) {
  const RenderSnapshot s = two_particles(-10.0f, 50.0f);
  const OrbitCamera cam = front_camera();
  ParticleViewOptions o;
  o.colour_by = "temperature";
  const ViewImage v = render_particles(s, cam, o);
  EXPECT_DOUBLE_EQ(v.t_min, -10.0);
  EXPECT_DOUBLE_EQ(v.t_max, 50.0);
  ASSERT_GT(v.bar.y1, v.bar.y0);
  const std::uint8_t* bottom = v.image.pixel((v.bar.x0 + v.bar.x1) / 2, v.bar.y1 - 1);
  const std::uint8_t* top = v.image.pixel((v.bar.x0 + v.bar.x1) / 2, v.bar.y0);
  int x = 0, y = 0;
  project(cam, s.position[0], x, y);
  const std::uint8_t* cold = v.image.pixel(x, y);
  project(cam, s.position[1], x, y);
  const std::uint8_t* hot = v.image.pixel(x, y);
  EXPECT_GT(chroma(cold).dot(chroma(bottom)), 0.999) << "cold particle has the bar's bottom colour";
  EXPECT_GT(chroma(hot).dot(chroma(top)), 0.999) << "hot particle has the bar's top colour";
  EXPECT_GT(chroma(bottom).dot(chroma(cool_warm(0.0))), 0.9999);
  EXPECT_GT(chroma(top).dot(chroma(cool_warm(1.0))), 0.9999);
  EXPECT_LT(chroma(cold).dot(chroma(hot)), 0.9) << "the two ends differ";
}

// The scale spans the air too (issue 18: the views show the warm jet), not the solids: ice at -5 °C, a
// dryer's air at 70 °C and a heater at 300 °C give -5 to 70 °C.
TEST(ParticleView, TheTemperatureScaleSpansIceWaterAndAirButNotSolids) {
  RenderSnapshot s = two_particles(-5.0f, 0.0f);
  s.position.push_back({0.0f, 0.0f, 0.05f});
  s.phase.push_back(static_cast<std::uint8_t>(Phase::Air));
  s.temperature.push_back(70.0f);
  s.position.push_back({0.0f, 0.0f, -0.05f});
  s.phase.push_back(static_cast<std::uint8_t>(Phase::Solid));
  s.temperature.push_back(300.0f);
  ParticleViewOptions o;
  o.colour_by = "temperature";
  const ViewImage v = render_particles(s, front_camera(), o);
  EXPECT_DOUBLE_EQ(v.t_min, -5.0);
  EXPECT_DOUBLE_EQ(v.t_max, 70.0);
}

TEST(ParticleView, PhaseColoursTellIceFromWater) {
  const RenderSnapshot s = two_particles(0.0f, 0.0f);
  const OrbitCamera cam = front_camera();
  const ViewImage v = render_particles(s, cam, {});
  int x = 0, y = 0;
  project(cam, s.position[0], x, y);
  const Eigen::Vector3d ice = chroma(v.image.pixel(x, y));
  project(cam, s.position[1], x, y);
  const Eigen::Vector3d water = chroma(v.image.pixel(x, y));
  EXPECT_GT(ice.dot(chroma(phase_rgb(static_cast<std::uint8_t>(Phase::Ice)))), 0.999);
  EXPECT_GT(water.dot(chroma(phase_rgb(static_cast<std::uint8_t>(Phase::Water)))), 0.999);
  EXPECT_LT(ice.dot(water), 0.97);
}

// By speed (air or water; issue 18's views): a still particle takes the bar's bottom colour, the fastest
// its top, the scale running from 0 to the fastest, labelled in m/s.
TEST(ParticleView, SpeedColoursRunFromStillToTheFastest) {
  RenderSnapshot s = two_particles(20.0f, 20.0f);
  s.phase = {static_cast<std::uint8_t>(Phase::Air), static_cast<std::uint8_t>(Phase::Air)};
  s.speed = {0.0f, 2.5f};
  const OrbitCamera cam = front_camera();
  ParticleViewOptions o;
  o.colour_by = "speed";
  const ViewImage v = render_particles(s, cam, o);
  EXPECT_DOUBLE_EQ(v.t_min, 0.0);
  EXPECT_DOUBLE_EQ(v.t_max, 2.5);
  int x = 0, y = 0;
  project(cam, s.position[0], x, y);
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(cool_warm(0.0))), 0.999);
  project(cam, s.position[1], x, y);
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(cool_warm(1.0))), 0.999);
  EXPECT_EQ(colour_bar_labels(0, 2.5, BarUnit::MetresPerSecond),
            (std::array<std::string, 3>{"2.50 m/s", "1.25 m/s", "0.00 m/s"}));
  // Glass in front of them hides them by phase, not by speed: a field view sees through glass.
  s.position.push_back(s.position[1] + Eigen::Vector3f(0.0f, -0.05f, 0.0f));  // nearer the camera
  s.phase.push_back(static_cast<std::uint8_t>(Phase::Solid));
  s.temperature.push_back(20.0f);
  s.speed.push_back(0.0f);
  s.glass = {0, 0, 1};
  project(cam, s.position[1], x, y);
  EXPECT_GT(chroma(render_particles(s, cam, o).image.pixel(x, y)).dot(chroma(cool_warm(1.0))), 0.999);
  ParticleViewOptions by_phase;
  EXPECT_GT(chroma(render_particles(s, cam, by_phase).image.pixel(x, y))
                .dot(chroma(phase_rgb(static_cast<std::uint8_t>(Phase::Solid)))),
            0.999);
  // Without velocities there is nothing to colour by.
  s.speed.clear();
  EXPECT_THROW(render_particles(s, cam, o), Error);
}

// By a substance (issue 20): its concentration from 0 to the most any particle holds, labelled in g/L; a
// substance the snapshot lacks falls back to temperature; the name must follow "substance:".
TEST(ParticleView, SubstanceColoursRunFromNoneToTheMost) {
  RenderSnapshot s = two_particles(-5.0f, 20.0f);
  s.substances = {{"salt", {0.0f, 0.0f}}, {"dye", {0.0f, 2.0f}}};
  const OrbitCamera cam = front_camera();
  ParticleViewOptions o;
  o.colour_by = "substance:dye";
  const ViewImage v = render_particles(s, cam, o);
  EXPECT_DOUBLE_EQ(v.t_min, 0.0);
  EXPECT_DOUBLE_EQ(v.t_max, 2.0);
  int x = 0, y = 0;
  project(cam, s.position[0], x, y);
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(cool_warm(0.0))), 0.999);
  project(cam, s.position[1], x, y);
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(cool_warm(1.0))), 0.999);
  EXPECT_EQ(colour_bar_labels(0, 2.0, BarUnit::GramsPerLitre),
            (std::array<std::string, 3>{"2 g/L", "1 g/L", "0 g/L"}));
  o.colour_by = "substance:ink";
  const ViewImage t = render_particles(s, cam, o);
  EXPECT_DOUBLE_EQ(t.t_min, -5.0);
  EXPECT_DOUBLE_EQ(t.t_max, 20.0);
  EXPECT_NO_THROW(check_colouring("substance:salt", "colour_by"));
  EXPECT_THROW(check_colouring("substance:", "colour_by"), Error);
  EXPECT_THROW(check_colouring("salt", "colour_by"), Error);
}

// Coloured by a coating, ice and solids show what sticks to them as a stain over their phase's colour, the
// most any holds at the stain's full depth; by anything else, no stain.
TEST(ParticleView, ACoatingStainsTheSolidsAndIceItSticksTo) {
  RenderSnapshot s = two_particles(-5.0f, 20.0f);
  s.position.push_back({0.0f, 0.0f, 0.05f});
  s.phase.push_back(static_cast<std::uint8_t>(Phase::Solid));
  s.temperature.push_back(20.0f);
  s.substances = {{"grease", {0.0f, 1.0f, 0.0f}}};
  s.deposits = {{"grease", {2e-5f, 0.0f, 1e-4f}}};  // ice a fifth of the solid's
  const OrbitCamera cam = front_camera();
  ParticleViewOptions o;
  o.colour_by = "substance:grease";
  const ViewImage v = render_particles(s, cam, o);
  int x = 0, y = 0;
  project(cam, s.position[2], x, y);
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(stained(phase_rgb(std::uint8_t(Phase::Solid)), 1.0))),
            0.999);
  project(cam, s.position[0], x, y);
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(stained(phase_rgb(std::uint8_t(Phase::Ice)), 0.2))),
            0.999);
  project(cam, s.position[1], x, y);  // the water by its concentration
  EXPECT_GT(chroma(v.image.pixel(x, y)).dot(chroma(cool_warm(1.0))), 0.999);
  o.colour_by = "phase";
  const ViewImage plain = render_particles(s, cam, o);
  project(cam, s.position[2], x, y);
  EXPECT_GT(chroma(plain.image.pixel(x, y)).dot(chroma(phase_rgb(std::uint8_t(Phase::Solid)))), 0.999);
  EXPECT_LT(chroma(plain.image.pixel(x, y)).dot(chroma(stained(phase_rgb(std::uint8_t(Phase::Solid)), 1.0))),
            0.99);
}

TEST(ParticleView, UnknownColouringAndMissingTemperaturesAreErrors) {
  RenderSnapshot s = two_particles(0.0f, 1.0f);
  ParticleViewOptions o;
  o.colour_by = "velocity";
  EXPECT_THROW(render_particles(s, front_camera(), o), Error);
  s.temperature.clear();
  o.colour_by = "temperature";
  EXPECT_THROW(render_particles(s, front_camera(), o), Error);
}

// T = 100 x on a lattice: the slice through it runs from the bar's bottom colour on the left to the
// top colour on the right, through the middle of the scale at x = 0.
TEST(SliceView, LinearTemperatureRunsAcrossTheColourBar) {
  RenderSnapshot s;
  s.spacing = 0.01f;
  s.domain_min = {-0.1f, -0.05f, -0.05f};
  s.domain_max = {0.1f, 0.05f, 0.05f};
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) {
        const Eigen::Vector3f x(-0.095f + 0.01f * float(i), -0.045f + 0.01f * float(j),
                                -0.045f + 0.01f * float(k));
        s.position.push_back(x);
        s.phase.push_back(static_cast<std::uint8_t>(Phase::Water));
        s.temperature.push_back(100.0f * x.x());
      }
  SliceOptions o;
  o.axis = 1;
  o.t_min = -10;
  o.t_max = 10;
  o.width = 400;
  o.height = 200;
  const ViewImage v = render_slice(s, o);
  // The plane spans x in [-0.1, 0.1] across the image, scaled by 1.05 around its centre.
  auto column_of = [&](double x) {
    return static_cast<int>(std::lround(0.5 * o.width + x / (0.2 * 1.05 / o.width)));
  };
  const int y = o.height / 2 + 20;  // below the bar's middle label
  EXPECT_GT(chroma(v.image.pixel(column_of(-0.09), y)).dot(chroma(cool_warm(0.05))), 0.995);
  EXPECT_GT(chroma(v.image.pixel(column_of(0.0), y)).dot(chroma(cool_warm(0.5))), 0.995);
  EXPECT_GT(chroma(v.image.pixel(column_of(0.09), y)).dot(chroma(cool_warm(0.95))), 0.995);

  // The same lattice moving at |v| = 10 |x| (a jet's two sides): by speed, the slice is at the bar's
  // bottom in the middle and near its top at both ends, whatever the temperatures say.
  for (const Eigen::Vector3f& x : s.position) s.speed.push_back(10.0f * std::abs(x.x()));
  o.colour_by = "speed";
  o.t_min = 0;
  o.t_max = 1;
  const ViewImage w = render_slice(s, o);
  EXPECT_GT(chroma(w.image.pixel(column_of(0.0), y)).dot(chroma(cool_warm(0.0))), 0.995);
  EXPECT_GT(chroma(w.image.pixel(column_of(-0.09), y)).dot(chroma(cool_warm(0.9))), 0.995);
  EXPECT_GT(chroma(w.image.pixel(column_of(0.09), y)).dot(chroma(cool_warm(0.9))), 0.995);
}

// Light pixels (the labels' text) in a box of the image.
int light_pixels(const Image& image, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += image.pixel(x, y)[0] > 200 && image.pixel(x, y)[2] > 200;
  return n;
}

// The colour bar says what its colours mean: its top, middle and bottom in °C, left of the strip, in
// every temperature view (a PNG of `thaw render` as much as a streamed frame).
TEST(ColourBar, LabelsSayTheRangeInDegreesBesideTheStrip) {
  EXPECT_EQ(colour_bar_labels(-5, 35), (std::array<std::string, 3>{"35.0 °C", "15.0 °C", "-5.0 °C"}));
  EXPECT_EQ(colour_bar_labels(-0.04, 0.04)[1], "0.0 °C");
  EXPECT_EQ(text_width("8", 2), 10);
  EXPECT_EQ(text_width("12", 1), 11);
  EXPECT_EQ(text_width("", 3), 0);

  Image a(640, 480), b(640, 480);
  for (Image* im : {&a, &b})
    for (std::size_t i = 0; i < im->rgba.size(); ++i) im->rgba[i] = 90;
  const ColourBar bar = draw_colour_bar(a);
  draw_colour_bar(b);
  const Image bare = a;
  label_colour_bar(a, bar, 0, 10);
  label_colour_bar(b, bar, 0, 20);
  // Text at the top, middle and bottom, within 60 px left of the strip; nothing right of it or far left.
  for (const int y : {bar.y0, (bar.y0 + bar.y1) / 2, bar.y1 - 1})
    EXPECT_GT(light_pixels(a, bar.x0 - 120, y - 8, bar.x0, y + 8), 60) << "row " << y;
  EXPECT_EQ(light_pixels(a, bar.x1 + 1, 0, a.width, a.height), 0);
  EXPECT_EQ(light_pixels(a, 0, 0, bar.x0 - 130, a.height), 0);
  EXPECT_EQ(light_pixels(bare, 0, 0, bar.x0 - 1, a.height), 0);  // the strip itself has near-white
  // Another range, other numbers: the top and middle labels change, the bottom one (0.0) does not.
  auto differs = [&](int y) {
    for (int yy = y - 8; yy < y + 8; ++yy)
      for (int x = bar.x0 - 120; x < bar.x0; ++x)
        if (a.pixel(x, yy)[0] != b.pixel(x, yy)[0]) return true;
    return false;
  };
  EXPECT_TRUE(differs(bar.y0));
  EXPECT_TRUE(differs((bar.y0 + bar.y1) / 2));
  EXPECT_FALSE(differs(bar.y1 - 1));

  // The slice view draws them.
  RenderSnapshot s = two_particles(-2.0f, 8.0f);
  SliceOptions o;
  o.width = 320;
  o.height = 240;
  const ViewImage v = render_slice(s, o);
  EXPECT_GT(light_pixels(v.image, v.bar.x0 - 60, v.bar.y0 - 5, v.bar.x0, v.bar.y0 + 5), 20);
}

}  // namespace
}  // namespace thaw

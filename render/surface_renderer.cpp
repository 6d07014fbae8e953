#include "render/surface_renderer.h"

#include <algorithm>
#include <cmath>

#include "sim/error.h"
#include "sim/stage_timers.h"

namespace thaw {
namespace {

double ms_since(Clock::time_point t0) { return 1e3 * seconds_since(t0); }

void check_gl(const char* what) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  const char* name = e == GL_OUT_OF_MEMORY                   ? "GL_OUT_OF_MEMORY"
                     : e == GL_INVALID_ENUM                  ? "GL_INVALID_ENUM"
                     : e == GL_INVALID_VALUE                 ? "GL_INVALID_VALUE"
                     : e == GL_INVALID_OPERATION             ? "GL_INVALID_OPERATION"
                     : e == GL_INVALID_FRAMEBUFFER_OPERATION ? "GL_INVALID_FRAMEBUFFER_OPERATION"
                                                             : "unknown GL error";
  throw Error(std::string("surface renderer: ") + what + " failed (" + name + ")");
}

GLuint make_texture_3d(GLenum internal_format, int nx, int ny, int nz, GLenum filter) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_3D, t);
  glTexStorage3D(GL_TEXTURE_3D, 1, internal_format, nx, ny, nz);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
    glTexParameteri(GL_TEXTURE_3D, wrap, GL_CLAMP_TO_EDGE);
  return t;
}

// The key light, fixed in the world so that orbiting the camera shows one consistently lit scene: high
// (about 67 degrees) so shadows stay short and read as contact, and from the side of the default camera
// (azimuth 30 degrees) so they fall behind the bodies it sees.
Eigen::Vector3f light_direction() { return Eigen::Vector3f(0.35f, 0.25f, 1.0f).normalized(); }

std::uint8_t unit_byte(float v) {
  return static_cast<std::uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}

// In place: every entry becomes the Chebyshev (L-infinity) distance, in blocks, to the nearest entry that
// was 0, capped at the initial value of the others. Separable (the max of per-axis distances
// distributes over the min): one 1-D pass per axis, each taking the min over the axis of
// max(offset, distance so far).
void chebyshev_distance(std::vector<std::uint8_t>& d, int nx, int ny, int nz) {
  const int n[3] = {nx, ny, nz};
  const std::size_t stride[3] = {1, std::size_t(nx), std::size_t(nx) * ny};
  for (int axis = 0; axis < 3; ++axis) {
    const int len = n[axis];
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
#pragma omp parallel
    {
      std::vector<std::uint8_t> line(static_cast<std::size_t>(len));
#pragma omp for schedule(static) collapse(2)
      for (int a = 0; a < n[u]; ++a)
        for (int b = 0; b < n[v]; ++b) {
          const std::size_t base = a * stride[u] + b * stride[v];
          for (int i = 0; i < len; ++i) line[i] = d[base + i * stride[axis]];
          for (int i = 0; i < len; ++i) {
            int best = line[i];
            for (int j = std::max(0, i - best + 1); j < std::min(len, i + best); ++j)
              best = std::min(best, std::max(std::abs(i - j), int(line[j])));
            d[base + i * stride[axis]] = static_cast<std::uint8_t>(best);
          }
        }
    }
  }
}

}  // namespace

SurfaceRenderer::SurfaceRenderer(EglContext& context) : context_(context) {
  glGenVertexArrays(1, &vao_);
  program_ = program_for(quality_, false, false, false);
}

GLuint SurfaceRenderer::program_for(Quality q, bool glass, bool sources, bool tint) {
  GLuint& p = programs_[(q == Quality::Full ? 0 : 1) + (glass ? 2 : 0) + (sources ? 4 : 0) + (tint ? 8 : 0)];
  if (p) return p;
  // A variant per quality: a uniform switch left the fast frame as slow as the full one on llvmpipe.
  p = build_program("fullscreen.vert", "surface.frag",
                    std::string("#define THAW_SEE_BEHIND ") + (q == Quality::Full ? "1" : "0") +
                        "\n#define THAW_GLASS " + (glass ? "1" : "0") + "\n#define THAW_SOURCES " +
                        (sources ? "1" : "0") + "\n#define THAW_TINT " + (tint ? "1" : "0") + "\n");
  glUseProgram(p);
  glUniform1i(glGetUniformLocation(p, "u_field"), 0);
  glUniform1i(glGetUniformLocation(p, "u_phases"), 1);
  glUniform1i(glGetUniformLocation(p, "u_blocks"), 2);
  if (tint) glUniform1i(glGetUniformLocation(p, "u_tint"), 3);
  check_gl("setting up the surface shader");
  return p;
}

GLuint SurfaceRenderer::current_program() {
  return program_for(quality_, has_glass_, !dryers_.empty() || !lamps_.empty(), has_tint_);
}

void SurfaceRenderer::set_quality(Quality q) {
  quality_ = q;
  program_ = current_program();
}

SurfaceRenderer::~SurfaceRenderer() {
  for (GLuint t : {field_, phases_, blocks_, tint_})
    if (t) glDeleteTextures(1, &t);
  for (GLuint r : {colour_, marched_colour_})
    if (r) glDeleteRenderbuffers(1, &r);
  for (GLuint f : {fbo_, marched_fbo_})
    if (f) glDeleteFramebuffers(1, &f);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  for (GLuint p : programs_)
    if (p) glDeleteProgram(p);
}

void SurfaceRenderer::resize_volume(int nx, int ny, int nz) {
  if (nodes_[0] == nx && nodes_[1] == ny && nodes_[2] == nz) return;
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max_size);
  if (std::max({nx, ny, nz}) > max_size)
    throw Error("surface renderer: a field grid of " + std::to_string(nx) + "x" + std::to_string(ny) + "x" +
                std::to_string(nz) + " nodes exceeds GL_MAX_3D_TEXTURE_SIZE " + std::to_string(max_size));
  for (GLuint* t : {&field_, &phases_, &blocks_, &tint_})
    if (*t) {
      glDeleteTextures(1, t);
      *t = 0;
    }
  const bool f32 = context_.float_linear();
  const int n[3] = {nx, ny, nz};
  for (int a = 0; a < 3; ++a) {
    nodes_[a] = n[a];
    block_count_[a] = std::max(1, (n[a] - 1 + kBlock - 1) / kBlock);
  }
  field_ = make_texture_3d(f32 ? GL_R32F : GL_R16F, nx, ny, nz, GL_LINEAR);
  phases_ = make_texture_3d(GL_RGBA8, nx, ny, nz, GL_LINEAR);
  blocks_ = make_texture_3d(f32 ? GL_RGBA32F : GL_RGBA16F, block_count_[0], block_count_[1], block_count_[2],
                            GL_LINEAR);
  check_gl("allocating the field textures");
}

void SurfaceRenderer::upload(const DensityFields& f) {
  const auto t0 = Clock::now();
  const FieldGrid& g = f.grid;
  for (const auto* v : {&f.ice, &f.water, &f.solid, &f.glass})
    if (!v->empty() && v->size() != g.size())
      throw Error("surface renderer: a phase field holds " + std::to_string(v->size()) +
                  " values for a grid of " + std::to_string(g.size()) + " nodes");
  has_glass_ = !f.glass.empty();
  has_tint_ = !f.dye.empty() || !f.stain.empty();
  for (const auto* v : {&f.dye, &f.stain})
    if (!v->empty() && v->size() != g.size())
      throw Error("surface renderer: a tint field holds " + std::to_string(v->size()) +
                  " values for a grid of " + std::to_string(g.size()) + " nodes");
  has_volume_ = g.nx >= 2 && g.ny >= 2 && g.nz >= 2 && g.cell > 0 &&
                !(f.ice.empty() && f.water.empty() && f.solid.empty() && f.glass.empty());
  grid_ = g;
  iso_ = f.iso;
  if (!has_volume_) {
    times_.upload_ms = ms_since(t0);
    return;
  }
  resize_volume(g.nx, g.ny, g.nz);

  const auto n = static_cast<std::ptrdiff_t>(g.size());
  max_field_.resize(g.size());
  phase_bytes_.resize(4 * g.size());
  const float* ice = f.ice.empty() ? nullptr : f.ice.data();
  const float* water = f.water.empty() ? nullptr : f.water.data();
  const float* solid = f.solid.empty() ? nullptr : f.solid.data();
  const float* glass = f.glass.empty() ? nullptr : f.glass.data();
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const float a = ice ? ice[i] : 0.0f, b = water ? water[i] : 0.0f, c = solid ? solid[i] : 0.0f;
    const float e = glass ? glass[i] : 0.0f;
    max_field_[i] = std::max({a, b, c, e});
    std::uint8_t* p = &phase_bytes_[4 * i];
    p[0] = unit_byte(a);
    p[1] = unit_byte(b);
    p[2] = unit_byte(c);
    p[3] = unit_byte(e);
  }

  // Blocks span nodes [b * kBlock, b * kBlock + kBlock] inclusive: the trilinear field anywhere inside the
  // block's cells is bounded by those nodes, so a block whose nodes all lie below iso holds no surface.
  const int bx = block_count_[0], by = block_count_[1], bz = block_count_[2];
  const std::size_t blocks = std::size_t(bx) * by * bz;
  block_data_.resize(4 * blocks);
  extinction_.resize(blocks);
  std::vector<std::uint8_t>& skip = skip_distance_;
  skip.resize(blocks);
  const float iso = f.iso;
#pragma omp parallel for schedule(static) collapse(2)
  for (int kb = 0; kb < bz; ++kb)
    for (int jb = 0; jb < by; ++jb)
      for (int ib = 0; ib < bx; ++ib) {
        float m = 0.0f;
        int inside[4] = {0, 0, 0, 0}, count = 0;
        for (int k = kb * kBlock; k <= std::min(kb * kBlock + kBlock, g.nz - 1); ++k)
          for (int j = jb * kBlock; j <= std::min(jb * kBlock + kBlock, g.ny - 1); ++j) {
            const std::size_t row = g.index(0, j, k);
            for (int i = ib * kBlock; i <= std::min(ib * kBlock + kBlock, g.nx - 1); ++i) {
              m = std::max(m, max_field_[row + i]);
              inside[0] += ice && ice[row + i] >= iso;
              inside[1] += water && water[row + i] >= iso;
              inside[2] += solid && solid[row + i] >= iso;
              inside[3] += glass && glass[row + i] >= iso;
              ++count;
            }
          }
        const std::size_t b = (std::size_t(kb) * by + jb) * bx + ib;
        skip[b] = m >= iso ? 0 : kMaxSkip;
        float frac[4];
        for (int q = 0; q < 4; ++q) frac[q] = float(inside[q]) / float(count);
        // Glass occludes the ambient light a little (it is a thin wall) and casts a faint shadow.
        block_data_[4 * b + 1] = frac[0] + frac[1] + frac[2] + 0.3f * frac[3];
        extinction_[b] = kShadowExtinction[0] * frac[0] + kShadowExtinction[1] * frac[1] +
                         kShadowExtinction[2] * frac[2] + kShadowExtinction[3] * frac[3];
      }
  chebyshev_distance(skip, bx, by, bz);

  // Light transmittance from each block centre toward the (fixed) key light, through the blocks'
  // extinction, sampled trilinearly one block at a time: the shader's soft shadows cost one fetch.
  const Eigen::Vector3f light = light_direction();
  auto extinction_at = [&](const Eigen::Vector3f& q) {  // q in block units, block centres at integers
    Eigen::Vector3i c;
    Eigen::Vector3f w;
    const int count[3] = {bx, by, bz};
    for (int a = 0; a < 3; ++a) {
      const float x = std::clamp(q[a], 0.0f, float(count[a] - 1));
      c[a] = std::min(int(x), std::max(count[a] - 2, 0));
      w[a] = count[a] > 1 ? x - float(c[a]) : 0.0f;
    }
    float e = 0.0f;
    for (int corner = 0; corner < 8; ++corner) {
      const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
      const int i = std::min(c[0] + dx, bx - 1), j = std::min(c[1] + dy, by - 1),
                k = std::min(c[2] + dz, bz - 1);
      e += (dx ? w[0] : 1 - w[0]) * (dy ? w[1] : 1 - w[1]) * (dz ? w[2] : 1 - w[2]) *
           extinction_[(std::size_t(k) * by + j) * bx + i];
    }
    return e;
  };
#pragma omp parallel for schedule(static) collapse(2)
  for (int kb = 0; kb < bz; ++kb)
    for (int jb = 0; jb < by; ++jb)
      for (int ib = 0; ib < bx; ++ib) {
        const Eigen::Vector3f c(static_cast<float>(ib), static_cast<float>(jb), static_cast<float>(kb));
        float tau = 0.0f;
        for (int step = 1; step <= kShadowSteps; ++step) {
          const Eigen::Vector3f q = c + float(step) * light;
          if (q.x() < -0.5f || q.y() < -0.5f || q.z() < -0.5f || q.x() > float(bx) - 0.5f ||
              q.y() > float(by) - 0.5f || q.z() > float(bz) - 0.5f)
            break;
          tau += extinction_at(q) * float(kBlock);
        }
        const std::size_t b = (std::size_t(kb) * by + jb) * bx + ib;
        block_data_[4 * b] = float(skip[b]);
        block_data_[4 * b + 2] = std::exp(-tau);
        block_data_[4 * b + 3] = 0.0f;
      }

  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glBindTexture(GL_TEXTURE_3D, field_);
  glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, g.nx, g.ny, g.nz, GL_RED, GL_FLOAT, max_field_.data());
  glBindTexture(GL_TEXTURE_3D, phases_);
  glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, g.nx, g.ny, g.nz, GL_RGBA, GL_UNSIGNED_BYTE,
                  phase_bytes_.data());
  glBindTexture(GL_TEXTURE_3D, blocks_);
  glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, bx, by, bz, GL_RGBA, GL_FLOAT, block_data_.data());
  if (has_tint_) upload_tint(f);
  glFinish();
  check_gl("uploading the field textures");
  times_.upload_ms = ms_since(t0);
}

void SurfaceRenderer::upload_tint(const DensityFields& f) {
  const FieldGrid& g = f.grid;
  if (!tint_) tint_ = make_texture_3d(GL_RG16F, g.nx, g.ny, g.nz, GL_LINEAR);
  tint_data_.resize(2 * g.size());
  const auto n = static_cast<std::ptrdiff_t>(g.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    tint_data_[2 * i] = f.dye.empty() ? 0.0f : f.dye[i];
    tint_data_[2 * i + 1] = f.stain.empty() ? 0.0f : f.stain[i];
  }
  glBindTexture(GL_TEXTURE_3D, tint_);
  glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, g.nx, g.ny, g.nz, GL_RG, GL_FLOAT, tint_data_.data());
  // Beer-Lambert: a thick layer passes the colour, so each channel's absorption is -ln of it, scaled so the
  // most absorbed channel has kDyeStrength (a white substance: none).
  const Eigen::Vector3f colour(f.tint_colour[0], f.tint_colour[1], f.tint_colour[2]);
  const Eigen::Vector3f a = -colour.cwiseMax(0.02f).cwiseMin(1.0f).array().log().matrix();
  dye_absorption_ =
      a.maxCoeff() > 0 ? Eigen::Vector3f(a * (kDyeStrength / a.maxCoeff())) : Eigen::Vector3f::Zero();
  stain_colour_ = colour;
}

namespace {

// An RGBA8 renderbuffer of width x height attached to `fbo` (both made when 0), replacing `colour`.
void make_target(GLuint& fbo, GLuint& colour, int width, int height) {
  if (!fbo) glGenFramebuffers(1, &fbo);
  if (colour) glDeleteRenderbuffers(1, &colour);
  glGenRenderbuffers(1, &colour);
  glBindRenderbuffer(GL_RENDERBUFFER, colour);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error("surface renderer: the " + std::to_string(width) + "x" + std::to_string(height) +
                " RGBA8 framebuffer is incomplete (glCheckFramebufferStatus " + std::to_string(status) + ")");
  check_gl("allocating the framebuffer");
}

}  // namespace

void SurfaceRenderer::resize_target(int width, int height) {
  if (width == width_ && height == height_) return;
  make_target(fbo_, colour_, width, height);
  width_ = width;
  height_ = height;
}

void SurfaceRenderer::resize_marched(int width, int height) {
  if (width == marched_width_ && height == marched_height_) return;
  make_target(marched_fbo_, marched_colour_, width, height);
  marched_width_ = width;
  marched_height_ = height;
}

void SurfaceRenderer::set_scale(double scale) {
  if (!(scale >= kMinScale && scale <= 1.0))
    throw Error("surface renderer: scale " + std::to_string(scale) + " is outside " +
                std::to_string(kMinScale) + "..1");
  scale_ = scale;
}

int SurfaceRenderer::marched(int pixels, double scale) {
  return std::clamp(static_cast<int>(std::lround(pixels * scale)), 1, pixels);
}

Image SurfaceRenderer::render(const DensityFields& fields, const OrbitCamera& camera) {
  upload(fields);
  return render(camera);
}

Image SurfaceRenderer::render(const OrbitCamera& camera) {
  if (camera.width <= 0 || camera.height <= 0)
    throw Error("surface renderer: camera size " + std::to_string(camera.width) + "x" +
                std::to_string(camera.height) + " is empty");
  const auto t0 = Clock::now();
  resize_target(camera.width, camera.height);
  const int mw = marched(camera.width, scale_), mh = marched(camera.height, scale_);
  const bool reduced = mw < camera.width || mh < camera.height;
  if (reduced) resize_marched(mw, mh);
  glBindFramebuffer(GL_FRAMEBUFFER, reduced ? marched_fbo_ : fbo_);
  glViewport(0, 0, mw, mh);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  program_ = current_program();
  glUseProgram(program_);

  // The camera basis from the view matrix (rows: right, up, -forward), scaled so that
  // forward + ndc.x * right + ndc.y * up is the ray through a pixel, as in OrbitCamera::ray.
  const Eigen::Matrix4f view = camera.view();
  const Eigen::Vector3f right = view.block<1, 3>(0, 0).transpose(), up = view.block<1, 3>(1, 0).transpose(),
                        forward = -view.block<1, 3>(2, 0).transpose();
  const float tan_half = static_cast<float>(std::tan(0.5 * camera.fov * M_PI / 180.0));
  const float aspect = float(camera.width) / float(camera.height);
  const Eigen::Vector3f light = light_direction();
  const float cell = grid_.cell > 0 ? grid_.cell : 1.0f;
  const Eigen::Vector3f eye = (camera.eye().cast<float>() - grid_.origin) / cell;

  auto loc = [&](const char* name) { return glGetUniformLocation(program_, name); };
  glUniform1i(loc("u_has_volume"), has_volume_ ? 1 : 0);
  glUniform3f(loc("u_nodes"), float(nodes_[0]), float(nodes_[1]), float(nodes_[2]));
  glUniform3f(loc("u_block_count"), float(block_count_[0]), float(block_count_[1]), float(block_count_[2]));
  glUniform1f(loc("u_block"), float(kBlock));
  glUniform1f(loc("u_iso"), iso_);
  glUniform1f(loc("u_scale"), 1.0f / float(std::max({nodes_[0], nodes_[1], nodes_[2], 2}) - 1));
  glUniform3fv(loc("u_eye"), 1, eye.data());
  glUniform3fv(loc("u_forward"), 1, forward.data());
  const Eigen::Vector3f r = right * (tan_half * aspect), u = up * tan_half;
  glUniform3fv(loc("u_right"), 1, r.data());
  glUniform3fv(loc("u_up"), 1, u.data());
  glUniform2f(loc("u_viewport"), float(mw), float(mh));
  glUniform3fv(loc("u_light"), 1, light.data());
  // Dryers in grid units, as the shader's rays are.
  const int dryers = std::min<int>(int(dryers_.size()), kMaxDryers);
  std::vector<float> pos(3 * kMaxDryers, 0.0f), dir(3 * kMaxDryers, 0.0f), shape(4 * kMaxDryers, 0.0f);
  for (int k = 0; k < dryers; ++k) {
    const DryerMarker& m = dryers_[std::size_t(k)];
    const Eigen::Vector3f p = (m.position - grid_.origin) / cell;
    for (int a = 0; a < 3; ++a) {
      pos[3 * k + a] = p[a];
      dir[3 * k + a] = m.direction[a];
    }
    shape[4 * k + 0] = m.nozzle_radius / cell;
    shape[4 * k + 1] = float(std::tan(double(m.half_angle) * M_PI / 180.0));
    shape[4 * k + 2] = m.reach / cell;
    shape[4 * k + 3] = m.on ? 1.0f : 0.0f;
  }
  glUniform1i(loc("u_dryers"), dryers);
  glUniform3fv(loc("u_dryer_pos"), kMaxDryers, pos.data());
  glUniform3fv(loc("u_dryer_dir"), kMaxDryers, dir.data());
  glUniform4fv(loc("u_dryer_shape"), kMaxDryers, shape.data());
  // Lamps in grid units, glowing from dull red (400 °C) to yellow-white (1600 °C) while on.
  const int lamps = std::min<int>(int(lamps_.size()), kMaxLamps);
  std::vector<float> centre(3 * kMaxLamps, 0.0f), hu(3 * kMaxLamps, 0.0f), hv(3 * kMaxLamps, 0.0f),
      glow(3 * kMaxLamps, 0.0f);
  for (int k = 0; k < lamps; ++k) {
    const LampMarker& m = lamps_[std::size_t(k)];
    const Eigen::Vector3f c = (m.centre - grid_.origin) / cell, a = m.half_u / cell, b = m.half_v / cell;
    const float f = std::clamp((m.temperature - 400.0f) / 1200.0f, 0.0f, 1.0f);
    const Eigen::Vector3f g = m.on ? Eigen::Vector3f(0.6f + 0.4f * f, 0.12f + 0.73f * f, 0.05f + 0.55f * f)
                                   : Eigen::Vector3f::Zero();
    for (int i = 0; i < 3; ++i) {
      centre[3 * k + i] = c[i];
      hu[3 * k + i] = a[i];
      hv[3 * k + i] = b[i];
      glow[3 * k + i] = g[i];
    }
  }
  glUniform1i(loc("u_lamps"), lamps);
  glUniform3fv(loc("u_lamp_centre"), kMaxLamps, centre.data());
  glUniform3fv(loc("u_lamp_u"), kMaxLamps, hu.data());
  glUniform3fv(loc("u_lamp_v"), kMaxLamps, hv.data());
  glUniform3fv(loc("u_lamp_glow"), kMaxLamps, glow.data());
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_3D, field_);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_3D, phases_);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_3D, blocks_);
  if (has_tint_) {
    glUniform3fv(loc("u_dye_absorption"), 1, dye_absorption_.data());
    glUniform3fv(loc("u_stain_colour"), 1, stain_colour_.data());
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_3D, tint_);
  }
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glFinish();
  check_gl("drawing the surfaces");
  times_.march_ms = ms_since(t0);

  const auto t1 = Clock::now();
  if (reduced) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, marched_fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
    glBlitFramebuffer(0, 0, mw, mh, 0, 0, camera.width, camera.height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    check_gl("stretching the reduced frame");
  }
  Image image(camera.width, camera.height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, camera.width, camera.height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  check_gl("reading the frame back");
  // GL's row 0 is the bottom; Image's is the top.
  const std::size_t row = std::size_t(camera.width) * 4;
  for (int y = 0; y < camera.height / 2; ++y)
    std::swap_ranges(image.rgba.begin() + std::ptrdiff_t(y * row),
                     image.rgba.begin() + std::ptrdiff_t((y + 1) * row),
                     image.rgba.begin() + std::ptrdiff_t((camera.height - 1 - y) * row));
  times_.readback_ms = ms_since(t1);
  return image;
}

}  // namespace thaw

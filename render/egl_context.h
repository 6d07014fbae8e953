#pragma once
// The renderer's OpenGL ES context, with no window and no display server (docs/ARCHITECTURE.md, Renderer): an
// EGL display from a GPU through EGL_EXT_platform_device (NVIDIA), else Mesa's surfaceless platform (llvmpipe
// here), and a context current on the thread that created it. The server's render thread owns one; GL calls
// from any other thread are errors.
//
// Needs OpenGL ES 3.0 (3D textures, R32F textures, GLSL ES 3.00 loops); asks for 3.2, then 3.1, then
// 3.0. Float textures are filtered linearly only with OES_texture_float_linear (see float_linear()).
#include <EGL/egl.h>
#include <GLES3/gl3.h>

#include <string>

namespace thaw {

class EglContext {
 public:
  // Throws thaw::Error naming what failed: no EGL implementation, no display on any platform tried, no
  // ES 3 context, or a GL version below 3.0 (with the version found).
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Binds the context to the calling thread (it is bound to the creating thread already).
  void make_current();

  // "EGL <platform> <vendor> <version>; GL_RENDERER; GL_VERSION", e.g. for `thaw info` and logs.
  std::string description() const;
  const std::string& platform() const { return platform_; }  // "device" or "surfaceless"
  const std::string& renderer() const { return renderer_; }  // GL_RENDERER
  const std::string& gl_version() const { return gl_version_; }
  int gl_major() const { return major_; }
  int gl_minor() const { return minor_; }
  bool has_gl_extension(const std::string& name) const;
  // Whether R32F/RGBA32F textures may use GL_LINEAR (OES_texture_float_linear); if not, the renderer
  // falls back to the half-float formats, which ES 3.0 filters in core.
  bool float_linear() const { return float_linear_; }

 private:
  void release();  // the EGL objects, in the destructor and when the constructor gives up

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;  // a 1x1 pbuffer, only where surfaceless contexts are missing
  std::string platform_, egl_vendor_, egl_version_, renderer_, gl_version_, gl_extensions_;
  int major_ = 0, minor_ = 0;
  bool float_linear_ = false;
};

// Compiles and links a program from files of render/shaders/ (embedded at build time). Each file is
// compiled on its own; a failure throws thaw::Error with the file name and the driver's info log.
// The caller owns the returned program (glDeleteProgram).
// `defines` ("#define NAME VALUE\n" lines) are inserted into the fragment shader after its #version line:
// variants that differ in code, not in uniforms, which llvmpipe pays for even when a branch is not taken.
GLuint build_program(const std::string& vertex_file, const std::string& fragment_file,
                     const std::string& defines = "");

}  // namespace thaw

#include "render/egl_context.h"

#include <EGL/eglext.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <sstream>
#include <vector>

#include "render/embedded_shaders.h"
#include "sim/error.h"

namespace thaw {
namespace {

bool has_word(const char* list, const std::string& word) {
  if (!list) return false;
  std::istringstream in(list);
  for (std::string w; in >> w;)
    if (w == word) return true;
  return false;
}

std::string egl_error_name(EGLint e) {
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE:
      return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP:
      return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW:
      return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST:
      return "EGL_CONTEXT_LOST";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "EGL error 0x%04x", static_cast<unsigned>(e));
      return buf;
    }
  }
}

// eglGetPlatformDisplayEXT returns the same handle for the same arguments, and eglTerminate ends it for
// everyone in the process, so two EglContexts on one display must not terminate it under each other.
std::mutex display_mutex;
std::map<EGLDisplay, int> display_users;

void release_display(EGLDisplay d) {
  std::lock_guard<std::mutex> lock(display_mutex);
  if (--display_users[d] == 0) {
    display_users.erase(d);
    eglTerminate(d);
  }
}

// A display that initialised, and how it was reached.
struct Candidate {
  EGLDisplay display;
  std::string platform;
};

// Opens displays in order of preference: hardware devices (EGL_EXT_platform_device, skipping Mesa's
// software device), Mesa's surfaceless platform, then software devices. Every failure is noted in
// `tried` for the error message.
std::vector<Candidate> open_displays(std::vector<std::string>& tried) {
  std::vector<Candidate> out;
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!client)
    throw Error(
        "EGL: no EGL implementation answered (eglQueryString(EGL_NO_DISPLAY) returned nothing: "
        "libEGL found no vendor library; install Mesa's libegl-mesa0 or the NVIDIA driver)");
  auto get_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!has_word(client, "EGL_EXT_platform_base") || !get_display)
    throw Error(std::string("EGL: EGL_EXT_platform_base is missing, so no display without a window system "
                            "can be opened (client extensions: ") +
                client + ")");

  auto try_open = [&](EGLenum platform, void* native, const std::string& name) {
    EGLDisplay d = get_display(platform, native, nullptr);
    if (d == EGL_NO_DISPLAY) {
      tried.push_back(name + ": no display (" + egl_error_name(eglGetError()) + ")");
      return;
    }
    std::lock_guard<std::mutex> lock(display_mutex);
    EGLint major = 0, minor = 0;
    if (display_users[d] == 0 && !eglInitialize(d, &major, &minor)) {
      tried.push_back(name + ": eglInitialize failed (" + egl_error_name(eglGetError()) + ")");
      display_users.erase(d);
      return;
    }
    ++display_users[d];
    out.push_back({d, name});
  };

  std::vector<EGLDeviceEXT> software;
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_device_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  const bool device_platform = has_word(client, "EGL_EXT_platform_device") && query_devices;
  if (device_platform) {
    EGLint count = 0;
    std::vector<EGLDeviceEXT> devices;
    if (query_devices(0, nullptr, &count) && count > 0) {
      devices.resize(static_cast<std::size_t>(count));
      query_devices(count, devices.data(), &count);
      devices.resize(static_cast<std::size_t>(count));
    }
    for (std::size_t i = 0; i < devices.size(); ++i) {
      const char* ext = query_device_string ? query_device_string(devices[i], EGL_EXTENSIONS) : nullptr;
      if (has_word(ext, "EGL_MESA_device_software"))
        software.push_back(devices[i]);
      else
        try_open(EGL_PLATFORM_DEVICE_EXT, devices[i], "device " + std::to_string(i));
    }
    if (devices.empty()) tried.push_back("device: no EGL devices");
  } else {
    tried.push_back("device: EGL_EXT_platform_device not offered");
  }
  if (has_word(client, "EGL_MESA_platform_surfaceless"))
    try_open(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, "surfaceless");
  else
    tried.push_back("surfaceless: EGL_MESA_platform_surfaceless not offered");
  for (EGLDeviceEXT d : software) try_open(EGL_PLATFORM_DEVICE_EXT, d, "device (software)");
  return out;
}

std::string gl_string(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "";
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : "; ") + x;
  return s;
}

GLuint compile(GLenum type, const std::string& file, const std::string& defines) {
  const auto& files = embedded_shader_files();
  const auto it = files.find(file);
  if (it == files.end()) {
    std::string have;
    for (const auto& [name, text] : files) have += " " + name;
    throw Error("shader " + file + ": no such file in render/shaders/ (embedded:" + have + ")");
  }
  // Defines go after the #version line, which must come first; #line keeps the log's line numbers.
  std::string source(it->second);
  if (!defines.empty()) {
    const std::size_t eol = source.find('\n');
    source = eol == std::string::npos
                 ? source + "\n" + defines
                 : source.substr(0, eol + 1) + defines + "#line 2\n" + source.substr(eol + 1);
  }
  const GLuint shader = glCreateShader(type);
  const GLchar* text = source.data();
  const auto length = static_cast<GLint>(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint size = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &size);
    std::string log(static_cast<std::size_t>(std::max(size, 1)), '\0');
    glGetShaderInfoLog(shader, size, nullptr, log.data());
    glDeleteShader(shader);
    throw Error("shader " + file + " failed to compile:\n" + log.c_str());
  }
  return shader;
}

}  // namespace

EglContext::EglContext() {
  std::vector<std::string> tried;
  std::vector<Candidate> displays = open_displays(tried);
  if (displays.empty()) throw Error("EGL: no display could be opened (" + join(tried) + ")");

  // The first display that gives an ES 3 context wins; the rest are released.
  for (const Candidate& c : displays) {
    if (context_ != EGL_NO_CONTEXT) {
      release_display(c.display);
      continue;
    }
    if (!eglBindAPI(EGL_OPENGL_ES_API)) {
      tried.push_back(c.platform + ": eglBindAPI(EGL_OPENGL_ES_API) failed");
      release_display(c.display);
      continue;
    }
    const char* ext = eglQueryString(c.display, EGL_EXTENSIONS);
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE,
                                        EGL_PBUFFER_BIT,
                                        EGL_RENDERABLE_TYPE,
                                        EGL_OPENGL_ES3_BIT,
                                        EGL_RED_SIZE,
                                        8,
                                        EGL_GREEN_SIZE,
                                        8,
                                        EGL_BLUE_SIZE,
                                        8,
                                        EGL_ALPHA_SIZE,
                                        8,
                                        EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglChooseConfig(c.display, config_attributes, &config, 1, &configs) || configs == 0) {
      if (!has_word(ext, "EGL_KHR_no_config_context")) {
        tried.push_back(c.platform + ": no RGBA8 pbuffer config for ES 3 and no EGL_KHR_no_config_context");
        release_display(c.display);
        continue;
      }
      config = EGL_NO_CONFIG_KHR;
    }
    // Newest first: ES 3.1/3.2 add compute shaders and image load/store that later views may use.
    for (const auto& [major, minor] : {std::pair{3, 2}, std::pair{3, 1}, std::pair{3, 0}}) {
      const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, major, EGL_CONTEXT_MINOR_VERSION, minor,
                                   EGL_NONE};
      context_ = eglCreateContext(c.display, config, EGL_NO_CONTEXT, attributes);
      if (context_ != EGL_NO_CONTEXT) break;
    }
    if (context_ == EGL_NO_CONTEXT) {
      tried.push_back(c.platform + ": eglCreateContext for ES 3.2/3.1/3.0 failed (" +
                      egl_error_name(eglGetError()) + ")");
      release_display(c.display);
      continue;
    }
    display_ = c.display;
    platform_ = c.platform;
    if (!has_word(ext, "EGL_KHR_surfaceless_context")) {
      const EGLint pbuffer[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
      if (config != EGL_NO_CONFIG_KHR) surface_ = eglCreatePbufferSurface(display_, config, pbuffer);
    }
  }
  if (context_ == EGL_NO_CONTEXT)
    throw Error("EGL: no OpenGL ES 3 context on any display (" + join(tried) + ")");

  egl_vendor_ = eglQueryString(display_, EGL_VENDOR) ? eglQueryString(display_, EGL_VENDOR) : "";
  egl_version_ = eglQueryString(display_, EGL_VERSION) ? eglQueryString(display_, EGL_VERSION) : "";
  try {
    make_current();
  } catch (...) {
    release();
    throw;
  }
  renderer_ = gl_string(GL_RENDERER);
  gl_version_ = gl_string(GL_VERSION);
  gl_extensions_ = gl_string(GL_EXTENSIONS);
  if (std::sscanf(gl_version_.c_str(), "OpenGL ES %d.%d", &major_, &minor_) != 2 || major_ < 3) {
    const std::string found = gl_version_.empty() ? "(no GL_VERSION)" : gl_version_;
    release();
    throw Error("EGL: the " + platform_ + " display gave \"" + found + "\" (" + renderer_ +
                "); the renderer needs OpenGL ES 3.0 or newer");
  }
  float_linear_ = has_gl_extension("GL_OES_texture_float_linear");
}

EglContext::~EglContext() { release(); }

void EglContext::release() {
  if (display_ == EGL_NO_DISPLAY) return;
  if (eglGetCurrentContext() == context_)
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
  if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
  release_display(display_);
  display_ = EGL_NO_DISPLAY;
  context_ = EGL_NO_CONTEXT;
  surface_ = EGL_NO_SURFACE;
}

void EglContext::make_current() {
  if (!eglMakeCurrent(display_, surface_, surface_, context_))
    throw Error("EGL: eglMakeCurrent failed on the " + platform_ + " display (" +
                egl_error_name(eglGetError()) + ")");
}

std::string EglContext::description() const {
  return "EGL " + platform_ + " " + egl_vendor_ + " " + egl_version_ + "; " + renderer_ + "; " + gl_version_;
}

bool EglContext::has_gl_extension(const std::string& name) const {
  return has_word(gl_extensions_.c_str(), name);
}

GLuint build_program(const std::string& vertex_file, const std::string& fragment_file,
                     const std::string& defines) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_file, "");
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_file, defines);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint size = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &size);
    std::string log(static_cast<std::size_t>(std::max(size, 1)), '\0');
    glGetProgramInfoLog(program, size, nullptr, log.data());
    glDeleteProgram(program);
    throw Error("shader program " + vertex_file + " + " + fragment_file + " failed to link:\n" + log.c_str());
  }
  return program;
}

}  // namespace thaw

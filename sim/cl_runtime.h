#pragma once
// The OpenCL device, context and queue, and building programs from the embedded kernel files.
#include <CL/opencl.hpp>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace thaw {

struct DeviceInfo {
  int platform = 0;
  int device = 0;
  std::string platform_name;
  std::string name;
  std::string type;  // "GPU", "CPU", "accelerator", "other"
  std::string version;
  unsigned compute_units = 0;
  unsigned long long global_memory = 0;
};

// Every device the ICD loader reports, in platform/device order.
std::vector<DeviceInfo> list_devices();

// Picks a device: spec "" (default: the first GPU, else the first CPU), "gpu", "cpu", "P:D" (indices),
// or a case-insensitive substring of the device name. An empty spec falls back to $THAW_DEVICE.
// Throws Error saying what was looked for and what exists.
DeviceInfo choose_device(const std::string& spec);

class ClRuntime {
 public:
  explicit ClRuntime(const std::string& device_spec = "");

  // Builds a program from embedded files (sim/kernels/*), each preceded by a #line directive so the
  // build log names the file and line. Throws Error with the log, naming the files, on failure.
  cl::Program build(const std::vector<std::string>& files, const std::string& options = "") const;

  // The same from (file name, source text) pairs; build() passes the embedded files here.
  using Source = std::pair<std::string, std::string_view>;
  cl::Program build_sources(const std::vector<Source>& sources, const std::string& options = "") const;

  // Called with each program's whole source and options just before it is built: the tests pass every
  // program a scene builds through a strict OpenCL C compiler (tests/sim/cl_runtime_test.cpp), since a
  // vendor's compiler may refuse what pocl accepts.
  using BuildObserver = std::function<void(const std::string& source, const std::string& options)>;
  void set_build_observer(BuildObserver f) { observer_ = std::move(f); }

  const DeviceInfo& info() const { return info_; }

  // How many tiles the particles are cut into for the per-tile passes (layout_for in sim/stage.h): 32
  // on a CPU, 32 per compute unit on a GPU; $THAW_TILES, when set and not empty, overrides it (for `thaw
  // bench`).
  std::size_t layout_tiles() const;
  std::string description() const;
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }
  const cl::Device& device() const { return device_; }

 private:
  DeviceInfo info_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  BuildObserver observer_;
};

// A build log with the compiler's positions in the concatenated source ("<kernel>:12:5:", as NVIDIA's
// compiler writes them, which ignores #line) turned into the embedded file's own ("sim/kernels/grid.cl:
// 3:5:"); `sources` are the (name, text) pairs in the order build_sources() joined them.
std::string annotate_build_log(const std::string& log, const std::vector<ClRuntime::Source>& sources);

// OpenCL error codes as names ("CL_OUT_OF_RESOURCES") for messages.
const char* cl_error_name(cl_int code);

}  // namespace thaw

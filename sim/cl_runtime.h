#pragma once
// The OpenCL device, context and queue, and building programs from the embedded kernel files.
#include <CL/opencl.hpp>
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

  const DeviceInfo& info() const { return info_; }
  std::string description() const;
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }
  const cl::Device& device() const { return device_; }

 private:
  DeviceInfo info_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
};

// OpenCL error codes as names ("CL_OUT_OF_RESOURCES") for messages.
const char* cl_error_name(cl_int code);

}  // namespace thaw

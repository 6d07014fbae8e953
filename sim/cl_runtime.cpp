#include "sim/cl_runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "sim/embedded_kernels.h"
#include "sim/error.h"

namespace thaw {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

std::vector<cl::Platform> platforms() {
  std::vector<cl::Platform> ps;
  cl_uint count = 0;
  // clGetPlatformIDs returns CL_PLATFORM_NOT_FOUND_KHR when the ICD loader finds nothing.
  if (clGetPlatformIDs(0, nullptr, &count) != CL_SUCCESS || count == 0) return ps;
  cl::Platform::get(&ps);
  return ps;
}

cl::Device device_at(const DeviceInfo& d) {
  std::vector<cl::Device> devs;
  platforms().at(static_cast<std::size_t>(d.platform)).getDevices(CL_DEVICE_TYPE_ALL, &devs);
  return devs.at(static_cast<std::size_t>(d.device));
}

std::string describe_all(const std::vector<DeviceInfo>& all) {
  if (all.empty()) return "no OpenCL devices at all";
  std::ostringstream os;
  for (const auto& d : all) os << "\n  " << d.platform << ":" << d.device << "  " << d.type << "  " << d.name;
  return os.str();
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  const auto ps = platforms();
  for (std::size_t p = 0; p < ps.size(); ++p) {
    std::vector<cl::Device> devs;
    try {
      ps[p].getDevices(CL_DEVICE_TYPE_ALL, &devs);
    } catch (const cl::Error&) {
      continue;  // a platform with no devices
    }
    for (std::size_t i = 0; i < devs.size(); ++i) {
      DeviceInfo d;
      d.platform = static_cast<int>(p);
      d.device = static_cast<int>(i);
      d.platform_name = ps[p].getInfo<CL_PLATFORM_NAME>();
      d.name = devs[i].getInfo<CL_DEVICE_NAME>();
      d.type = type_name(devs[i].getInfo<CL_DEVICE_TYPE>());
      d.version = devs[i].getInfo<CL_DEVICE_VERSION>();
      d.compute_units = devs[i].getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      d.global_memory = devs[i].getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      out.push_back(d);
    }
  }
  return out;
}

DeviceInfo choose_device(const std::string& requested) {
  std::string spec = requested;
  if (spec.empty()) {
    if (const char* env = std::getenv("THAW_DEVICE")) spec = env;
  }
  const auto all = list_devices();
  if (all.empty())
    throw Error(
        "no OpenCL platform or device found: the ICD loader (libOpenCL) found no driver in "
        "/etc/OpenCL/vendors (install pocl-opencl-icd for the CPU, or a GPU vendor's driver)");
  const std::string s = lower(spec);
  auto first_of = [&](const std::string& type) -> const DeviceInfo* {
    for (const auto& d : all)
      if (d.type == type) return &d;
    return nullptr;
  };
  if (s.empty()) {
    if (auto* d = first_of("GPU")) return *d;
    if (auto* d = first_of("CPU")) return *d;
    return all.front();
  }
  if (s == "gpu" || s == "cpu") {
    if (auto* d = first_of(s == "gpu" ? "GPU" : "CPU")) return *d;
    throw Error("no OpenCL " + s + " device found (--device / THAW_DEVICE='" + spec +
                "'); devices present:" + describe_all(all));
  }
  if (auto colon = s.find(':'); colon != std::string::npos && std::isdigit((unsigned char)s[0])) {
    const int p = std::atoi(s.substr(0, colon).c_str());
    const int i = std::atoi(s.substr(colon + 1).c_str());
    for (const auto& d : all)
      if (d.platform == p && d.device == i) return d;
    throw Error("no OpenCL device " + spec + " (platform:device); devices present:" + describe_all(all));
  }
  for (const auto& d : all)
    if (lower(d.name).find(s) != std::string::npos) return d;
  throw Error(
      "no OpenCL device whose name contains '" + spec +
      "' (--device / THAW_DEVICE; also accepted: gpu, cpu, P:D); devices present:" + describe_all(all));
}

std::size_t ClRuntime::layout_tiles() const {
  if (const char* env = std::getenv("THAW_TILES"); env && *env) {  // set and not empty
    char* end = nullptr;
    const long v = std::strtol(env, &end, 10);
    if (end == env || *end != '\0' || v < 1 || v > (1 << 24))
      throw Error("THAW_TILES='" + std::string(env) +
                  "': must be a whole number of tiles from 1 to 16777216");
    return static_cast<std::size_t>(v);
  }
  if (info_.type == "GPU") return 32 * std::max(1u, info_.compute_units);
  return 32;
}

ClRuntime::ClRuntime(const std::string& device_spec) : info_(choose_device(device_spec)) {
  device_ = device_at(info_);
  context_ = cl::Context(device_);
  queue_ = cl::CommandQueue(context_, device_);
}

std::string ClRuntime::description() const {
  std::ostringstream os;
  os << info_.name << " (" << info_.type << ", " << info_.platform_name << ", " << info_.compute_units
     << " compute units)";
  return os.str();
}

cl::Program ClRuntime::build(const std::vector<std::string>& files, const std::string& options) const {
  const auto& embedded = embedded_kernel_files();
  std::vector<Source> sources;
  for (const auto& f : files) {
    auto it = embedded.find(f);
    if (it == embedded.end()) throw Error("kernel file sim/kernels/" + f + " is not embedded in this build");
    sources.emplace_back("sim/kernels/" + f, it->second);
  }
  return build_sources(sources, options);
}

cl::Program ClRuntime::build_sources(const std::vector<Source>& sources, const std::string& options) const {
  std::string source;
  std::string names;
  for (const auto& [name, text] : sources) {
    source += "#line 1 \"" + name + "\"\n";
    source += text;
    source += "\n";
    names += (names.empty() ? "" : ", ") + name;
  }
  const std::string opts = "-cl-std=CL1.2 -cl-mad-enable " + options;
  if (observer_) observer_(source, opts);
  cl::Program program(context_, source);
  cl_int status = CL_SUCCESS;
  try {
    program.build({device_}, opts.c_str());
  } catch (const cl::BuildError& e) {
    status = e.err();
  } catch (const cl::Error& e) {
    status = e.err();
  }
  if (status != CL_SUCCESS) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
      log = "(no build log)";
    }
    throw Error("OpenCL build of " + names + " failed on " + info_.name + " (" + cl_error_name(status) +
                ", options '" + opts + "'):\n" + annotate_build_log(log, sources));
  }
  // A vendor's compiler warnings (pocl prints none) are shown on request: THAW_CL_BUILD_LOG=1.
  if (const char* env = std::getenv("THAW_CL_BUILD_LOG"); env && *env && std::string(env) != "0") {
    const std::string log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    if (log.find_first_not_of(" \t\r\n") != std::string::npos)
      std::fprintf(stderr, "OpenCL build log of %s on %s:\n%s\n", names.c_str(), info_.name.c_str(),
                   annotate_build_log(log, sources).c_str());
  }
  return program;
}

std::string annotate_build_log(const std::string& log, const std::vector<ClRuntime::Source>& sources) {
  // build_sources() puts "#line 1 \"name\"" before each file and a newline after it: file k's first
  // line is line first[k] + 1 of the whole.
  std::vector<std::pair<long, std::string>> first;  // (whole-source line of the #line directive, name)
  long line = 1;
  for (const auto& [name, text] : sources) {
    first.emplace_back(line, name);
    line += 1 + static_cast<long>(std::count(text.begin(), text.end(), '\n')) + 1;
  }
  static const std::string tag = "<kernel>:";
  std::string out;
  std::size_t at = 0;
  for (std::size_t k; (k = log.find(tag, at)) != std::string::npos;) {
    out.append(log, at, k - at);
    std::size_t e = k + tag.size();
    long whole = 0;
    while (e < log.size() && std::isdigit(static_cast<unsigned char>(log[e])))
      whole = whole * 10 + (log[e++] - '0');
    auto it = std::upper_bound(first.begin(), first.end(), whole,
                               [](long v, const std::pair<long, std::string>& f) { return v < f.first; });
    if (e == k + tag.size() || it == first.begin()) {
      out.append(log, k, e - k);  // no number, or before the first file: as it was
    } else {
      --it;
      out += it->second + ":" + std::to_string(whole - it->first);
    }
    at = e;
  }
  out.append(log, at, std::string::npos);
  return out;
}

const char* cl_error_name(cl_int code) {
  switch (code) {
#define THAW_CASE(x) \
  case x:            \
    return #x;
    THAW_CASE(CL_SUCCESS)
    THAW_CASE(CL_DEVICE_NOT_FOUND)
    THAW_CASE(CL_DEVICE_NOT_AVAILABLE)
    THAW_CASE(CL_COMPILER_NOT_AVAILABLE)
    THAW_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    THAW_CASE(CL_OUT_OF_RESOURCES)
    THAW_CASE(CL_OUT_OF_HOST_MEMORY)
    THAW_CASE(CL_BUILD_PROGRAM_FAILURE)
    THAW_CASE(CL_INVALID_VALUE)
    THAW_CASE(CL_INVALID_DEVICE)
    THAW_CASE(CL_INVALID_CONTEXT)
    THAW_CASE(CL_INVALID_COMMAND_QUEUE)
    THAW_CASE(CL_INVALID_MEM_OBJECT)
    THAW_CASE(CL_INVALID_BUILD_OPTIONS)
    THAW_CASE(CL_INVALID_PROGRAM)
    THAW_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    THAW_CASE(CL_INVALID_KERNEL_NAME)
    THAW_CASE(CL_INVALID_KERNEL)
    THAW_CASE(CL_INVALID_ARG_INDEX)
    THAW_CASE(CL_INVALID_ARG_VALUE)
    THAW_CASE(CL_INVALID_ARG_SIZE)
    THAW_CASE(CL_INVALID_KERNEL_ARGS)
    THAW_CASE(CL_INVALID_WORK_GROUP_SIZE)
    THAW_CASE(CL_INVALID_WORK_ITEM_SIZE)
    THAW_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    THAW_CASE(CL_INVALID_BUFFER_SIZE)
#undef THAW_CASE
    default:
      return "CL error";
  }
}

}  // namespace thaw

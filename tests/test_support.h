#pragma once
// Helpers shared by the tests: one OpenCL runtime per test suite (pocl start-up and kernel builds
// are the slow part of a test), self-removing temporary directories, whole-file reads, and running
// the built `thaw` executable with its output and exit status captured.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "sim/cl_runtime.h"
#include "sim/error.h"
#include "sim/scene.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/validation/case.h"

namespace thaw::testing {

namespace fs = std::filesystem;

// Base fixture: `cl()` is one ClRuntime (default device) created when the suite starts.
class ClSuite : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    if (!runtime_) runtime_ = std::make_unique<ClRuntime>();
  }
  static void TearDownTestSuite() { runtime_.reset(); }

 protected:
  static ClRuntime& cl() { return *runtime_; }

 private:
  static inline std::unique_ptr<ClRuntime> runtime_;
};

// A fresh directory under the system temp directory, removed with everything in it on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    static std::atomic<int> counter{0};
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() / ("thaw-" + tag + "-" + std::to_string(::getpid()) + "-" +
                                         std::to_string(counter++) + "-" + std::to_string(now));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// Puts an environment variable back as it was (set to its old value, or unset) when it goes out of scope.
class RestoreEnv {
 public:
  explicit RestoreEnv(std::string name) : name_(std::move(name)) {
    if (const char* v = std::getenv(name_.c_str())) old_ = v;
  }
  ~RestoreEnv() { old_ ? ::setenv(name_.c_str(), old_->c_str(), 1) : ::unsetenv(name_.c_str()); }
  RestoreEnv(const RestoreEnv&) = delete;
  RestoreEnv& operator=(const RestoreEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

inline std::string read_file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The bytes of `state` as a state file (written to dir / name): two runs compared bit for bit.
inline std::string state_file_bytes(const SimState& state, const TempDir& dir, const std::string& name) {
  write_state_file(dir / name, state);
  return read_file_bytes(dir / name);
}

// Steps a run of `scene` from `start` `first` times, saves its state, and steps it `then` more; a run resumed
// from the saved state to the same step must leave the same state file, byte for byte. `name` names the
// temporary folder.
inline bool resumes_bitwise(ClRuntime& cl, const Scene& scene, const SimState& start, int first, int then,
                            const std::string& name) {
  TempDir dir(name);
  Solver straight(cl, scene, start);
  for (int i = 0; i < first; ++i) straight.step();
  write_state_file(dir / "half.state", straight.state());
  for (int i = 0; i < then; ++i) straight.step();
  const std::string expected = state_file_bytes(straight.state(), dir, "straight.state");
  Solver resumed(cl, scene, read_state_file(dir / "half.state"));
  while (resumed.steps() < straight.steps()) resumed.step();
  return state_file_bytes(resumed.state(), dir, "resumed.state") == expected;
}

inline void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// Single-quotes an argument for /bin/sh.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct CommandResult {
  bool exited = false;   // ended by exit(), not by a signal
  int exit_code = -1;    // exit status when `exited`
  int signal = 0;        // terminating signal otherwise
  std::string out, err;  // captured stdout and stderr
};

// Runs THAW_BINARY with `args` (already shell-quoted where needed) in `dir`, capturing both streams.
inline CommandResult run_thaw(const std::string& args, const TempDir& dir) {
  const std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = "cd " + shell_quote(dir.path().string()) + " && " + shell_quote(THAW_BINARY) + " " +
                          args + " >" + shell_quote(out) + " 2>" + shell_quote(err) + " </dev/null";
  const int status = std::system(cmd.c_str());
  CommandResult r;
  // sh reports a child killed by signal N as exit status 128 + N.
  if (status != -1 && WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code > 128 && code < 128 + 64) {
      r.signal = code - 128;
    } else {
      r.exited = true;
      r.exit_code = code;
    }
  } else if (status != -1 && WIFSIGNALED(status)) {
    r.signal = WTERMSIG(status);
  }
  r.out = read_file_bytes(out);
  r.err = read_file_bytes(err);
  return r;
}

// The JSON path of the SceneError a scene document raises, or "(no error)".
inline std::string scene_error_path(Json doc) {
  try {
    scene_from_json(std::move(doc));
  } catch (const SceneError& e) {
    return e.path();
  }
  return "(no error)";
}

// An 8 mm cube of ice at -5 °C on a 1 mm lattice, held in place (flow off), with no gravity and no heat from
// the air, and one substance "salt" as `salt` declares it: the salted-ice tests' scene.
inline Json held_ice_cube(const std::string& name, const Json& salt) {
  Json doc = Json::parse(R"({
    "domain": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.008]}, "spacing": 0.001,
    "gravity": [0, 0, 0], "solver": {"flow": false, "max_dt": 1},
    "ambient": {"heat_transfer_coefficient": 0},
    "materials": {
      "water": {"kind": "fluid", "density": 1000, "conductivity": 0.56, "specific_heat": 4217},
      "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"}},
    "ice": [{"material": "ice", "box": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.008]}, "temperature": -5}]
  })");
  doc["name"] = name;
  doc["substances"]["salt"] = salt;
  return doc;
}

// Prints a validation case's metrics and expects every one within its gate, naming any that is not.
inline void expect_case_passes(const CaseResult& r) {
  for (const auto& [key, m] : r.metrics) {
    std::printf("[ info ] %s %.5g (reference %.5g, error %.4g, gate %.3g)\n", key.c_str(), m.value,
                m.reference, m.error, m.gate);
    EXPECT_TRUE(m.passed()) << key << ": error " << m.error << " against the gate " << m.gate;
  }
}

}  // namespace thaw::testing

#pragma once
// Errors are values that say what was wrong and where; the CLI prints them and exits non-zero.
#include <stdexcept>
#include <string>

namespace thaw {

// A user-facing error: a bad scene (with its JSON path), a missing file, a failed kernel build.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A scene or parameter error located at a JSON path such as "solids[2].box.min".
class SceneError : public Error {
 public:
  SceneError(std::string path, const std::string& message)
      : Error((path.empty() ? std::string("(root)") : path) + ": " + message), path_(std::move(path)) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The simulation refused to go on (NaN, runaway speed); names the step and the particle.
class BlowUpError : public Error {
 public:
  using Error::Error;
};

}  // namespace thaw

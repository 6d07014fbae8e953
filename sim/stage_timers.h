#pragma once
// Per-stage wall-clock timers, printed by every run (like DualSPHysics' Run.csv) so any run is a
// benchmark. A stage's time includes waiting for its kernels (the queue is drained at its end).
#include <array>
#include <chrono>
#include <string>

namespace thaw {

// One timer per stage; the passes that add to each, and when each is built, are sim/step_plan.h's.
enum class Stage {
  Grid,
  Density,
  Forces,
  Tension,
  Pressure,
  IceForces,
  TimeStep,
  Photons,
  Surface,
  Heat,
  Substances,
  Bodies,
  Integrate,
  Emit,
  Count
};
inline constexpr std::array<const char*, static_cast<int>(Stage::Count)> kStageNames = {
    "grid",    "density", "forces", "tension",    "pressure", "ice_forces", "time_step",
    "photons", "surface", "heat",   "substances", "bodies",   "integrate",  "emit"};

class StageTimers {
 public:
  void add(Stage s, double seconds) { total_[static_cast<int>(s)] += seconds; }
  double seconds(Stage s) const { return total_[static_cast<int>(s)]; }
  double total() const {
    double t = 0;
    for (double x : total_) t += x;
    return t;
  }
  void reset() { total_.fill(0.0); }

 private:
  std::array<double, static_cast<int>(Stage::Count)> total_{};
};

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace thaw

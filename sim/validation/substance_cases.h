#pragma once
// What the substance cases share (sim/validation/surface_transport.cpp, deposits.cpp, marangoni.cpp):
// stepping with samples between, the substance's closure as a metric, the small fits they take, and a
// surface coverage set by hand with the forces it makes.
#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {

// A held-particle case's parameters: the size of its water (`size`), water's density, the case's own fields,
// the solver (flow off, dt up to an hour) and the gate on the substance's closure.
Field held_case_params(Field size, std::vector<Field> own);
// The held cases' check that the solver's flow is off (--set solver.flow=true is refused at its path).
void require_held(const Json& params, const std::string& cases);

// A compensated pair's amount (hi + lo) [kg].
inline double pair_amount(const Float2& q) { return double(q[0]) + double(q[1]); }

// What `field` (a compensated pair per particle) holds over all of the solver's particles [kg]; 0 where it
// has no such field.
double field_total(const Solver& solver, const std::string& field);

// The least-squares slope through the origin of y against t.
double slope_through_origin(const std::vector<double>& t, const std::vector<double>& y);

// Steps `solver` to t_end, stopping at `samples` even times to call at(time); returns the wall seconds spent
// stepping (the measurements between are not the model's cost).
template <class F>
double run_sampled(Solver& solver, double t_end, int samples, F at) {
  double wall = 0;
  for (int n = 1; n <= samples; ++n) {
    const auto w0 = std::chrono::steady_clock::now();
    while (solver.time() < t_end * n / samples * (1.0 - 1e-12)) solver.step();
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    at(solver.time());
  }
  return wall;
}

// A surface-active substance "soap" under the tension law `law` with E = `tension_scale` [N/m] and
// Gamma_max 1e-6 kg/m^2 that stays where it is put (no diffusion, no exchange with the bulk), as a scene's
// `substances` block: for cases that set a coverage by hand (with_surface_coverage) and measure its forces.
Json still_detergent(const Json& law, const Json& tension_scale);

// The state `scene` starts from with its first substance (surface-active) on the water's free surface at
// Gamma = theta Gamma_max shape(x, y, z), on each particle with a surface area (after a warm-up that measures
// the areas); the books start from these amounts.
SimState with_surface_coverage(ClRuntime& cl, const Scene& scene, double theta,
                               const std::function<double(double, double, double)>& shape);

// Each particle's position and the force on it over a solver's second step from `st` [N] (its mass times
// its velocity change over the step), by particle id: the first step renews what the substance stage
// derives from the start (the tension ratios).
struct StepForce {
  Eigen::Vector3d x, f;
};
std::map<std::uint32_t, StepForce> second_step_forces(ClRuntime& cl, const Scene& scene, const SimState& st);

// The case's result: the run's size, steps and wall time, its own metrics, then substance `substance`'s
// closure (its total now against the start's) relative to the start's, gated by `gate`.
CaseResult substance_case_result(const Solver& solver, double wall,
                                 std::vector<std::pair<std::string, MetricResult>> metrics, double gate,
                                 std::size_t substance = 0);

}  // namespace thaw

#pragma once
// What the substance cases on held particles share (sim/validation/surface_transport.cpp, deposits.cpp):
// stepping with samples between, the substance's closure as a metric, and the small fits they take.
#include <chrono>
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

// The case's result: the run's size, steps and wall time, its own metrics, then substance `substance`'s
// closure (its total now against the start's) relative to the start's, gated by `gate`.
CaseResult substance_case_result(const Solver& solver, double wall,
                                 std::vector<std::pair<std::string, MetricResult>> metrics, double gate,
                                 std::size_t substance = 0);

}  // namespace thaw

#pragma once
// The one list of a step's passes. Solver::build() makes it from the stages it built; Solver::step() walks
// it; Solver::stages() names the stages from it and `thaw run` prints the stage timers in its order; and
// docs/ARCHITECTURE.md's step table is this list for a scene with every stage (a test compares them). The
// two pressure solvers share it and differ only in the passes that differ: DFSPH (Bender & Koschier 2017,
// Algorithm 1) adds its two solves, and its ice takes its forces after the density solve.
#include <string>
#include <vector>

#include "sim/stage_timers.h"

namespace thaw {

// Which stages a run built (Solver::build decides from the scene; docs/ARCHITECTURE.md says when).
struct BuiltStages {
  bool flow = false;        // FluidStage: density, forces, integration (solver.flow)
  bool dfsph = false;       // DfsphStage (solver.pressure dfsph)
  bool tension = false;     // TensionStage (tension.model other than none)
  bool rigid = false;       // RigidIce (free ice and flow)
  bool heat = false;        // HeatStage (plan_heat)
  bool photons = false;     // its photons: heat and lamps (on or off; they may be switched on live)
  bool surface = false;     // SurfaceStage (heat or substances take their areas from it)
  bool substances = false;  // SubstanceStage (the scene declares substances)
  bool emitters = false;    // EmitterStage (taps, air dryers or open sides with air)
};

// One pass of a step; what each does is in kPasses (sim/step_plan.cpp) and docs/ARCHITECTURE.md.
enum class Pass {
  Grid,
  Labels,
  Density,
  DivergenceSolve,
  Forces,
  Tension,
  IceForces,
  TimeStep,
  Surface,
  SubstanceState,
  Photons,
  Heat,
  SubstanceDiffusion,
  DensitySolve,
  Bodies,
  Integrate,
  Advance,
  Emit,
};

// The passes of one step, in order.
std::vector<Pass> step_plan(const BuiltStages& built);
// Every stage built, under DFSPH or WCSPH (the doc's table, tests).
BuiltStages every_stage(bool dfsph);

// The timer a pass adds to; Advance has none (false).
bool pass_timer(Pass p, Stage& timer);
// A pass's name as docs/ARCHITECTURE.md's table gives it ("divergence solve").
const char* pass_name(Pass p);
// The stage a pass belongs to ("pressure (dfsph)" for both solves), as Solver::stages() lists it.
const char* pass_stage(Pass p);

// docs/ARCHITECTURE.md's step table: one row per pass of a scene with every stage, under each solver.
std::string step_table();

}  // namespace thaw

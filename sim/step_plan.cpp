#include "sim/step_plan.h"

#include <algorithm>
#include <array>
#include <cstddef>

namespace thaw {
namespace {

struct PassInfo {
  Pass pass;
  const char* name;   // the pass
  const char* stage;  // the stage it belongs to ("" for the clock)
  Stage timer;        // the timer it adds to (Stage::Count: none)
  const char* what;
};

constexpr std::array<PassInfo, 18> kPasses = {{
    {Pass::Grid, "grid", "grid", Stage::Grid,
     "cell keys, radix sort, cell ranges; water past an open side is booked and dropped"},
    {Pass::Labels, "labels", "rigid ice", Stage::Bodies, "ice labelled into bodies, when due"},
    {Pass::Density, "density", "density", Stage::Density,
     "density; WCSPH's pressure from its equation of state, DFSPH's factor alpha"},
    {Pass::DivergenceSolve, "divergence solve", "pressure", Stage::Pressure,
     "velocities made divergence-free, with the last step's dt (Bender & Koschier 2017, eq 14)"},
    {Pass::Forces, "forces", "forces", Stage::Forces,
     "viscosity, gravity, boundaries, buoyancy, and WCSPH's pressure"},
    {Pass::Tension, "tension", "tension", Stage::Tension, "cohesion, curvature and adhesion"},
    {Pass::IceForces, "ice forces", "rigid ice", Stage::IceForces, "the water's forces on the ice particles"},
    {Pass::TimeStep, "time step", "time step", Stage::TimeStep,
     "the step's dt from every stage's limit; a blow-up stops here"},
    {Pass::Surface, "surface", "surface", Stage::Surface, "each particle's area and normal, when due"},
    {Pass::SubstanceState, "substance state", "substances", Stage::Substances,
     "what each particle's melt holds, the melting point it lowers"},
    {Pass::Photons, "photons", "photons", Stage::Photons, "lamps' photons traced and absorbed"},
    {Pass::Heat, "heat", "heat", Stage::Heat, "conduction, sources, phase change, the energy budget"},
    {Pass::SubstanceDiffusion, "substance diffusion", "substances", Stage::Substances,
     "diffusion, adsorption, coatings"},
    {Pass::DensitySolve, "density solve", "pressure", Stage::Pressure,
     "predicted velocities, the constant-density solve, pressures (Bender & Koschier 2017, eq 12)"},
    {Pass::Bodies, "bodies", "rigid ice", Stage::Bodies, "per-body sums, rigid integration, ice placed"},
    {Pass::Integrate, "integrate", "integrate", Stage::Integrate,
     "velocities and positions (DFSPH: positions; its solves set the velocities)"},
    {Pass::Advance, "advance", "", Stage::Count, "the clock: t += dt"},
    {Pass::Emit, "emit", "emit", Stage::Emit, "taps, air dryers and room air add particles, growing the run"},
}};

constexpr bool in_enum_order() {
  for (std::size_t k = 0; k < kPasses.size(); ++k)
    if (static_cast<std::size_t>(kPasses[k].pass) != k) return false;
  return true;
}
static_assert(in_enum_order(), "kPasses is indexed by Pass: one row per pass, in the enum's order");

const PassInfo& info(Pass p) { return kPasses[static_cast<std::size_t>(p)]; }

}  // namespace

std::vector<Pass> step_plan(const BuiltStages& b) {
  std::vector<Pass> plan;
  auto add = [&](Pass p, bool built) {
    if (built) plan.push_back(p);
  };
  // A scene without flow still sorts once (Solver::run_pass).
  add(Pass::Grid, true);
  add(Pass::Labels, b.rigid);
  add(Pass::Density, b.flow);
  add(Pass::DivergenceSolve, b.dfsph);
  add(Pass::Forces, b.flow);
  add(Pass::Tension, b.tension);
  // WCSPH's ice takes the forces the water's pressure and viscosity give it now; DFSPH's after its density
  // solve, which gives the pressure.
  add(Pass::IceForces, b.rigid && !b.dfsph);
  add(Pass::TimeStep, true);
  add(Pass::Surface, b.surface);
  add(Pass::SubstanceState, b.substances);
  add(Pass::Photons, b.photons);
  add(Pass::Heat, b.heat);
  add(Pass::SubstanceDiffusion, b.substances);
  add(Pass::DensitySolve, b.dfsph);
  add(Pass::IceForces, b.rigid && b.dfsph);
  add(Pass::Bodies, b.rigid);
  add(Pass::Integrate, b.flow);
  add(Pass::Advance, true);
  add(Pass::Emit, b.emitters);
  return plan;
}

bool pass_timer(Pass p, Stage& timer) {
  timer = info(p).timer;
  return timer != Stage::Count;
}

const char* pass_name(Pass p) { return info(p).name; }
const char* pass_stage(Pass p) { return info(p).stage; }

BuiltStages every_stage(bool dfsph) {
  return {.flow = true,
          .dfsph = dfsph,
          .tension = true,
          .rigid = true,
          .heat = true,
          .photons = true,
          .surface = true,
          .substances = true,
          .emitters = true};
}

std::string step_table() {
  const std::vector<Pass> wcsph = step_plan(every_stage(false)), dfsph = step_plan(every_stage(true));
  std::string out = "| pass | what it does | stage | timer | WCSPH | DFSPH |\n|---|---|---|---|:-:|:-:|\n";
  auto row = [&](Pass p, bool w, bool d) {
    Stage t;
    out += std::string("| ") + pass_name(p) + " | " + info(p).what + " | " +
           (*pass_stage(p) ? pass_stage(p) : "—") + " | " + (pass_timer(p, t) ? kStageNames[int(t)] : "—") +
           " | " + (w ? "✓" : "") + " | " + (d ? "✓" : "") + " |\n";
  };
  // The two orders merged along their longest common run of passes: a pass in both is one row, one that only
  // a solver has (or has elsewhere) is a row of its own where it runs.
  const std::size_t n = wcsph.size(), m = dfsph.size();
  std::vector<std::vector<std::size_t>> common(n + 1, std::vector<std::size_t>(m + 1, 0));
  for (std::size_t i = n; i-- > 0;)
    for (std::size_t j = m; j-- > 0;)
      common[i][j] =
          wcsph[i] == dfsph[j] ? common[i + 1][j + 1] + 1 : std::max(common[i + 1][j], common[i][j + 1]);
  std::size_t i = 0, j = 0;
  while (i < n || j < m) {
    if (i < n && j < m && wcsph[i] == dfsph[j]) {
      row(wcsph[i++], true, true);
      ++j;
    } else if (j == m || (i < n && common[i + 1][j] >= common[i][j + 1])) {
      row(wcsph[i++], true, false);
    } else {
      row(dfsph[j++], false, true);
    }
  }
  return out;
}

}  // namespace thaw

// `thaw run`: a headless run of a scene, with metrics, particle exports and state files.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "render/image_io.h"
#include "render/mesh_export.h"
#include "render/snapshot.h"
#include "server/cli_args.h"
#include "server/commands.h"
#include "server/progress.h"
#include "server/render_options.h"
#include "sim/error.h"
#include "sim/json_text.h"
#include "sim/metrics.h"
#include "sim/particle_export.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/thermal.h"

namespace thaw {
namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

Json stage_ms(const StageTimers& t, std::uint64_t steps) {
  Json j;
  for (int s = 0; s < static_cast<int>(Stage::Count); ++s)
    j[kStageNames[s]] = steps ? 1e3 * t.seconds(static_cast<Stage>(s)) / double(steps) : 0.0;
  return j;
}

}  // namespace

int cmd_run(int argc, char** argv) {
  std::vector<std::string> with_value = {"--until",  "--steps",       "--metrics",    "--export",
                                         "--every",  "--state-out",   "--state-in",   "--device",
                                         "--frames", "--export-mesh", "--mesh-format"};
  for (const char* o : kRenderValueOptions) with_value.emplace_back(o);
  CliArgs args(argc, argv, 2, with_value, {"--quiet", "--no-progress"});
  if (args.positional().size() > 1)
    throw Error("run takes one scene, got " + std::to_string(args.positional().size()));
  const bool has_scene = !args.positional().empty();
  const auto state_in = args.value("--state-in");
  if (!has_scene && !state_in)
    throw Error("run needs a SCENE (a name in configs/ or a file), or --state-in FILE");
  if (!args.value("--until") && !args.value("--steps")) throw Error("run needs --until SECONDS or --steps N");
  if (args.value("--until") && args.value("--steps")) throw Error("give either --until or --steps, not both");

  Scene scene;
  SimState start;
  if (state_in) {
    start = read_state_file(*state_in);
    if (has_scene) {
      scene = load_scene(args.positional()[0], args.sets());
      if (scene.source.dump() != start.scene_json)
        std::fprintf(stderr, "note: scene differs from the one stored in %s; continuing with %s\n",
                     state_in->c_str(), args.positional()[0].c_str());
    } else {
      scene = scene_from_json(parse_json(start.scene_json), args.sets());
    }
  } else {
    scene = load_scene(args.positional()[0], args.sets());
    start = initial_state(scene);
  }
  if (state_in) check_state(start, scene, *state_in);

  const double until = args.number("--until", 0.0);
  const long long steps_wanted = args.integer("--steps", 0);
  if (args.value("--steps") && steps_wanted < 0) throw Error("--steps: must be >= 0");
  const long long every = args.integer("--every", 10);
  if (every < 1) throw Error("--every: must be >= 1");
  const bool quiet = args.flag("--quiet");

  ClRuntime cl(args.value("--device").value_or(""));
  Solver solver(cl, scene, start);
  solver.warm_up();
  solver.timers().reset();

  std::unique_ptr<std::ofstream> metrics;
  if (auto f = args.value("--metrics")) {
    metrics = std::make_unique<std::ofstream>(*f);
    if (!*metrics) throw Error("cannot write metrics file " + *f);
  }
  std::unique_ptr<ParticleExporter> exporter;
  if (auto d = args.value("--export")) exporter = std::make_unique<ParticleExporter>(*d);
  // Frames (PNG, off-screen) and meshes share the snapshot of a step.
  const RenderOptions render = render_options(args, scene.camera);
  const auto frames_dir = args.value("--frames");
  std::unique_ptr<FrameRenderer> renderer;
  if (frames_dir) {
    std::error_code ec;
    std::filesystem::create_directories(*frames_dir, ec);
    if (ec) throw Error("cannot create frames directory '" + *frames_dir + "': " + ec.message());
    renderer = std::make_unique<FrameRenderer>(render);
  }
  std::unique_ptr<MeshExporter> meshes;
  if (auto d = args.value("--export-mesh"))
    meshes = std::make_unique<MeshExporter>(*d, args.value("--mesh-format").value_or("obj"));
  std::uint64_t frame = 0;
  // Particle exports, frames and meshes of one step share one read of the device.
  auto outputs = [&] {
    if (!exporter && !renderer && !meshes) return;
    const HostParticles p = solver.particles();
    const std::vector<float> temperature = temperatures_of(p, solver.scene());
    if (exporter) exporter->write(p, solver.time(), temperature);
    if (!renderer && !meshes) return;
    const RenderSnapshot snap = make_snapshot(p, temperature, solver.scene(), solver.time(), solver.steps());
    if (renderer) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(frame));
      write_png((std::filesystem::path(*frames_dir) / name).string(), renderer->render(snap));
    }
    if (meshes) meshes->write(snap, render.field);
    ++frame;
  };

  const auto counts = solver.particles();
  if (!quiet)
    std::printf("thaw run: scene '%s', %zu particles (water %zu, ice %zu, solid %zu, air %zu) on %s\n",
                scene.name.c_str(), solver.size(), counts.count(Phase::Water), counts.count(Phase::Ice),
                counts.count(Phase::Solid), counts.count(Phase::Air), cl.description().c_str());
  if (!quiet) {
    const std::vector<std::string> built = solver.stages();
    std::string stages;
    for (const std::string& s : built) stages += (stages.empty() ? "" : ", ") + s;
    std::printf("thaw run: stages built: %s\n", stages.c_str());
    if (std::none_of(built.begin(), built.end(), [](const std::string& s) { return s.starts_with("heat"); }))
      std::printf("thaw run: %s\n", solver.heat_reason().c_str());
  }
  std::fflush(stdout);

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  const std::uint64_t first_step = solver.steps();
  const std::uint64_t last_step = first_step + static_cast<std::uint64_t>(std::max(0LL, steps_wanted));
  const bool by_time = args.value("--until").has_value();
  auto done = [&] { return by_time ? solver.time() >= until : solver.steps() >= last_step; };
  Progress progress(by_time ? until : double(last_step), by_time ? "s" : "steps",
                    !quiet && !args.flag("--no-progress"));

  const double interval = scene.solver.output_interval;
  double next_output = (std::floor(solver.time() / interval + 1e-9) + 1.0) * interval;
  std::uint64_t interval_steps = 0;
  auto interval_start = Clock::now();
  StageTimers interval_timers;
  auto write_metrics = [&] {
    if (!metrics) return;
    const double wall_ms =
        interval_steps ? 1e3 * seconds_since(interval_start) / double(interval_steps) : 0.0;
    StageTimers diff;
    for (int s = 0; s < static_cast<int>(Stage::Count); ++s)
      diff.add(static_cast<Stage>(s), solver.timers().seconds(static_cast<Stage>(s)) -
                                          interval_timers.seconds(static_cast<Stage>(s)));
    *metrics << metrics_json(measure(solver), wall_ms, stage_ms(diff, interval_steps)).dump() << '\n';
    metrics->flush();
    interval_steps = 0;
    interval_start = Clock::now();
    interval_timers = solver.timers();
  };
  write_metrics();
  outputs();

  const auto t0 = Clock::now();
  while (!done() && !g_stop) {
    solver.step();
    ++interval_steps;
    if ((solver.steps() - first_step) % std::uint64_t(every) == 0) {
      outputs();
    }
    if (solver.time() >= next_output - 1e-12) {
      write_metrics();
      next_output = (std::floor(solver.time() / interval + 1e-9) + 1.0) * interval;
    }
    progress.update(by_time ? solver.time() : double(solver.steps()), solver.steps() - first_step);
  }
  const double wall = seconds_since(t0);
  progress.finish();
  if (interval_steps) write_metrics();
  if (g_stop)
    std::fprintf(stderr, "thaw run: interrupted at step %llu; finishing outputs\n",
                 (unsigned long long)solver.steps());
  if (auto f = args.value("--state-out")) write_state_file(*f, solver.state());

  if (!quiet) {
    const auto m = measure(solver);
    const std::uint64_t steps = solver.steps() - first_step;
    const double sim = solver.time() - start.time;
    std::printf("steps %llu, sim time %.6g s -> %.6g s, wall %.3f s", (unsigned long long)steps, start.time,
                solver.time(), wall);
    if (steps) {
      std::printf(" (%.3g wall s per sim s; %.3f wall us per particle-step)\n", sim > 0 ? wall / sim : 0.0,
                  1e6 * wall / double(steps) / double(std::max<std::size_t>(solver.size(), 1)));
      std::printf("stages, ms per step:");
      const auto& t = solver.timers();
      // The stages this scene built, in step order.
      for (const Stage s : solver.timed_stages())
        std::printf("  %s %.3f (%.0f%%)", kStageNames[int(s)], 1e3 * t.seconds(s) / double(steps),
                    100.0 * t.seconds(s) / std::max(t.total(), 1e-12));
    }
    std::printf(
        "\nfinal: dt %.3g s, max speed %.4g m/s, density error max %.3g %% mean %.3g %%, fluid mass %.9g kg, "
        "clamped %llu, kinetic %.4g J\n",
        m.dt, m.max_speed, 100 * m.max_density_error, 100 * m.mean_density_error, m.fluid_mass,
        (unsigned long long)m.clamped, m.kinetic);
    if (m.outflow.particles)
      std::printf("outflow: %llu particles, %.9g kg, momentum (%.4g, %.4g, %.4g) kg m/s, enthalpy %.6g J\n",
                  (unsigned long long)m.outflow.particles, m.outflow.mass, m.outflow.momentum.x(),
                  m.outflow.momentum.y(), m.outflow.momentum.z(), m.budget.outflow);
    if (m.inflow.particles)
      std::printf("inflow: %llu particles, %.9g kg, momentum (%.4g, %.4g, %.4g) kg m/s, enthalpy %.6g J\n",
                  (unsigned long long)m.inflow.particles, m.inflow.mass, m.inflow.momentum.x(),
                  m.inflow.momentum.y(), m.inflow.momentum.z(), m.budget.inflow);
    if (m.heat) {
      const EnergyBudget& b = m.budget;
      // The ice and water's temperatures where there are any (a scene of air alone has none).
      char range[96] = "";
      if (m.count[static_cast<int>(Phase::Water)] || m.count[static_cast<int>(Phase::Ice)])
        std::snprintf(range, sizeof range, ", temperature %.4g..%.4g °C (mean %.4g)", m.min_temperature,
                      m.max_temperature, m.mean_temperature);
      std::printf(
          "heat: ice %.6g kg, water %.6g kg%s; heat in %.6g J (ambient %.4g, lamps %.4g, dryers %.4g, walls "
          "%.4g, held %.4g, outflow %.4g, inflow %.4g), energy closure %.3g J\n",
          m.ice_mass, m.water_mass, range, b.heat_in(), b.ambient, b.lamps, b.dryers, b.walls, b.held,
          -b.outflow, b.inflow, m.closure());
      if (m.count[static_cast<int>(Phase::Air)]) {
        // Ideal-gas air that fills a closed domain: the pressure its warming or cooling gave the domain.
        char pressure[80] = "";
        if (m.pressure_solve.contains("closed_air_pressure_ratio"))
          std::snprintf(pressure, sizeof pressure, ", pressure %.5g of the room's (closed domain)",
                        m.pressure_solve["closed_air_pressure_ratio"].get<double>());
        std::printf("air: %.6g kg, temperature %.4g..%.4g °C (mean %.4g)%s\n", m.air_mass,
                    m.air_min_temperature, m.air_max_temperature, m.air_mean_temperature, pressure);
      }
    }
    if (!m.substances.is_null())
      for (const auto& [name, v] : m.substances.items()) {
        // Where it is, where it can be anywhere but in the water.
        char where[160] = "";
        if (v["on_surface"].get<double>() != 0 || v["on_solids"].get<double>() != 0)
          std::snprintf(
              where, sizeof where, "; dissolved %.4g kg, on the surface %.4g kg, on solids and ice %.4g kg",
              v["dissolved"].get<double>(), v["on_surface"].get<double>(), v["on_solids"].get<double>());
        std::printf(
            "substance %s: %.9g kg (outflow %.4g kg, inflow %.4g kg), closure %.3g kg (%.3g relative)%s\n",
            name.c_str(), v["total"].get<double>(), v["outflow"].get<double>(), v["inflow"].get<double>(),
            v["closure"].get<double>(), v["closure_relative"].get<double>(), where);
      }
    if (!m.pressure_solve.is_null()) {
      const Json& d = m.pressure_solve;
      std::printf(
          "dfsph: %.2f density and %.2f divergence iterations per step (mean); last step's errors %.3g "
          "(tolerance %.3g) and %.3g (tolerance %.3g)\n",
          d["mean_density_iterations"].get<double>(), d["mean_divergence_iterations"].get<double>(),
          d["density"]["error"].get<double>(), d["density"]["tolerance"].get<double>(),
          d["divergence"]["error"].get<double>(), d["divergence"]["tolerance"].get<double>());
    }
    if (!m.bodies.is_null()) {
      int free = 0, fixed = 0;
      for (const auto& b : m.bodies["list"]) (b["fixed"].get<bool>() ? fixed : free)++;
      std::printf("ice bodies: %d free, %d fixed; %llu labellings (last %d sweeps)\n", free, fixed,
                  (unsigned long long)m.bodies["labellings"].get<std::uint64_t>(),
                  m.bodies["last_sweeps"].get<int>());
    }
  }
  if (const DfsphStage* d = solver.dfsph()) {
    const PressureSolveTotals& t = d->totals();
    if (t.density_unconverged || t.divergence_unconverged)
      std::fprintf(
          stderr,
          "thaw run: warning: the DFSPH density solve stopped at solver.max_pressure_iterations = %d "
          "before its tolerance in %llu of %llu steps (worst mean density error %.3g against %.3g), "
          "the divergence solve in %llu; raise max_pressure_iterations or the tolerances, or lower "
          "solver.max_dt\n",
          solver.scene().solver.max_pressure_iterations, (unsigned long long)t.density_unconverged,
          (unsigned long long)t.steps, t.worst_density_error, solver.scene().solver.density_tolerance,
          (unsigned long long)t.divergence_unconverged);
  }
  return g_stop ? 130 : 0;
}

}  // namespace thaw

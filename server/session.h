#pragma once
// The simulation thread of `thaw serve` (docs/ARCHITECTURE.md, Server): it owns the Solver, applies the
// commands the network loop queues between two steps, and publishes what the other threads read — a render
// snapshot and a stats event — by swapping shared pointers under a mutex. It never waits on a consumer: a
// reader takes the newest value when it likes, and a slow one simply misses intermediate ones.
//
// Threads: the constructor and start() run on the owner's thread; everything that touches the Solver
// (stepping, commands, snapshots, state files) runs on the session's own thread once started. The
// accessors and submit() may be called from any thread.
#include <Eigen/Core>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "render/snapshot.h"
#include "server/protocol.h"
#include "sim/cl_runtime.h"
#include "sim/scene.h"
#include "sim/schema.h"
#include "sim/state_file.h"

namespace thaw {

class Solver;

class Session {
 public:
  // How a command ended: no code on success (`result` then holds what changed, for the ack), else the
  // protocol's error code and a message naming what was wrong. Called on the session's thread, after
  // the stats and snapshot that show the command's effect have been published.
  using Done = std::function<void(std::optional<protocol::ErrorCode> code, std::string message, Json result)>;

  // Loads `scene_name` (a name in configs/ or a file) with `overrides` ("path=value"), builds and warms
  // up the solver, creates `state_dir` and publishes the first snapshot. The overrides apply to every
  // scene this session loads later too (scene.load), so an operator's e.g. "spacing=0.006" for a slow
  // machine holds for the whole service. Throws SceneError / Error like load_scene and the Solver.
  Session(ClRuntime& cl, std::string scene_name, std::vector<std::string> overrides, std::string state_dir);
  ~Session();  // stops
  // Before start(): the simulation thread lowers its own priority by this many nice steps.
  void set_thread_nice(int steps) { thread_nice_ = steps; }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  void start();  // launches the simulation thread; it runs (not paused) from the start
  // Finishes the step or command under way, fails the commands still queued (also those of a batch
  // being applied), joins. Bounded by one step or one rebuild, whatever is queued.
  void stop();
  static constexpr std::size_t kMaxQueued = 512;

  // Thread-safe; applied on the session's thread before its next step. A `done` may be empty.
  // Commands that rebuild the solver (sim.reset, scene.load, state.load, param.set) cost a rebuild each
  // (about 0.25 s for the default scene on 2 cores), so a backlog of them once froze the stream for a
  // minute: while one waits, a newer one takes its place and the older is answered Failed
  // ("superseded"). Resets, scene and state loads share one place; a param.set shares it with those of
  // the same path. And the queue holds at most kMaxQueued commands from all clients together; beyond
  // that a command is answered RateLimited at once.
  // Presentation commands (hello, camera, view, quality, frame.ack) are the render side's business and
  // end in Failed; dryer.aim and substance.drop too, since they need a pick: the render side picks, then
  // calls aim_dryer() or drop_substance().
  void submit(protocol::Command command, Done done = {});
  // Points dryer `dryer` from where it is toward `hit` [m] (a picked surface point).
  void aim_dryer(int dryer, const Eigen::Vector3d& hit, Done done = {});
  // Puts `amount` kg of `substance` into the water and ice around `hit` [m] (a picked surface point):
  // substance.drop, after the render side's pick.
  void drop_substance(const std::string& substance, double amount, const Eigen::Vector3d& hit,
                      Done done = {});

  // Writes the current state to `path` (for --state-out at shutdown). On the session's thread while it
  // runs (blocking the caller until written), directly when it does not; throws Error on failure.
  void save_state(const std::string& path);

  // Simulated seconds per wall second; 0: as fast as the device allows (the default, since real time
  // is far too slow for a melt). Also settable with sim.speed; values in (0, 1000] there.
  static constexpr double kUnlimited = 0.0;

  // ---- what the session publishes (thread-safe) ------------------------------------------------------
  std::shared_ptr<const RenderSnapshot> latest_snapshot() const;
  // The protocol's stats event: {"type": "stats", scene, time [s], steps, dt [s], steps_per_second and
  // step_ms (wall, over the last publish interval), speed (0: unlimited), particles {water, ice, solid,
  // air}, ice_mass and water_mass [kg], ice_fraction (of the scene's start; null without ice), with heat
  // temperature {min, mean, max} [°C] over ice and water and energy {heat_in, closure [J],
  // closure_relative}, heat_time_scale, generation (bumped when the scene is loaded, reset or replaced by a
  // saved state: what a client shows must be rebuilt), paused, and error (the step failure that paused the
  // run) while there is one}.
  std::shared_ptr<const Json> latest_stats() const;
  std::shared_ptr<const Scene> scene() const;  // the scene as it runs now, live changes included
  std::uint64_t sequence() const;              // bumped by every publish
  // Waits until sequence() > after or `timeout` passes; returns sequence().
  std::uint64_t wait_for_sequence(std::uint64_t after, std::chrono::milliseconds timeout) const;

  // Called on the session's thread after every publish, e.g. to wake the network loop or the render
  // thread. Must be quick and must not call back into subscribe/unsubscribe.
  int subscribe(std::function<void()> on_publish);
  void unsubscribe(int id);  // after it returns, that callback is not running and never runs again

  // How often the session publishes at most while it steps [Hz].
  int thread_nice_ = 0;
  static constexpr double kPublishRate = 60.0;

 private:
  struct Aim {
    int dryer = 0;
    Eigen::Vector3d hit = Eigen::Vector3d::Zero();
  };
  struct Drop {
    std::string substance;
    double amount = 0;
    Eigen::Vector3d hit = Eigen::Vector3d::Zero();
  };
  using Task = std::function<void()>;  // internal work on the session's thread (save_state)
  struct Pending {
    std::variant<protocol::Command, Aim, Drop, Task> what;
    Done done;
  };
  struct Outcome {
    std::optional<protocol::ErrorCode> code;
    std::string message;
    Json result = Json::object();
  };
  struct StepRequest {
    int remaining = 0, requested = 0;
    Done done;
  };

  void run();
  // Queues `pending` unless the queue is full, first replacing the waiting command of the same
  // rebuild slot (none when `slot` is empty); answers what was replaced, refused or too late.
  void enqueue(Pending pending, const std::string& slot, const std::string& type);
  bool stopping();  // stop() was called (the session's thread asks between commands)
  bool wait_for_work(std::optional<std::chrono::steady_clock::time_point> until);
  void apply_pending(std::deque<Pending>& batch);
  Outcome apply(const protocol::Command& command, Done& done, bool& deferred);
  Outcome apply(const protocol::DryerSet& c);
  Outcome apply(const protocol::LampSet& c);
  Outcome apply(const protocol::EmitterSet& c);
  Outcome apply(const protocol::SceneLoad& c);
  Outcome apply(const protocol::ParamSet& c);
  Outcome apply(const protocol::StateSave& c);
  Outcome apply(const protocol::StateLoad& c);
  Outcome aim(const Aim& a);
  Outcome drop(const Drop& d);
  // Into the running solver, the scene and its published copy (dryer.set, lamp.set, dryer.aim and
  // param.set of a field the schema marks live in place).
  Outcome set_dryer(int index, const Dryer& d);
  Outcome set_lamp(int index, const Lamp& l);
  // An emitter goes in place when the running solver can take it, else by a rebuild from the particles
  // as they are (a temperature the run has no heat stage for, a jet faster than its sound speed allows);
  // the result says which ("applied").
  Outcome set_emitter(int index, const Emitter& e);
  // After a live change to scene_.ARRAY[index] (dryers, lamps, emitters): its `fields` into the scene
  // document, the scene republished; returns the fields with the index under the singular ("dryer").
  Json adopt(const std::string& array, int index, const Json& fields);

  void step_once();
  void rebuild(Scene scene, const SimState& state, bool fresh_start);
  void fail_step_requests(const std::string& why);
  void reanchor();
  Json time_result() const;
  void publish();
  void maybe_publish();

  ClRuntime& cl_;
  std::vector<std::string> overrides_;
  std::string state_dir_;

  // Owned by the session's thread once started (the constructor's before).
  Scene scene_;  // source kept in step with live dryer/lamp/emitter changes, so state files and rebuilds keep
                 // them
  std::unique_ptr<Solver> solver_;
  bool running_ = true;
  bool paused_by_error_ = false;
  std::string error_;  // the last step failure, shown in stats until a step succeeds or the state is rebuilt
  double speed_ = kUnlimited;
  double start_ice_mass_ = 0;  // ice mass of the scene's initial state [kg], for ice_fraction
  std::deque<StepRequest> step_requests_;
  std::chrono::steady_clock::time_point anchor_wall_;
  double anchor_sim_ = 0;
  // The publish window: steps and step wall time since the last publish.
  std::chrono::steady_clock::time_point last_publish_;
  std::uint64_t window_start_steps_ = 0;
  double window_step_seconds_ = 0;
  double last_step_ms_ = 0;
  bool dirty_ = false;  // something changed that is not published yet

  // Command queue: the network loop (and the owner) -> the session's thread.
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Pending> queue_;
  bool stop_ = false;
  bool thread_running_ = false;
  std::thread thread_;

  // Published values.
  mutable std::mutex publish_mutex_;
  mutable std::condition_variable publish_cv_;
  std::shared_ptr<const RenderSnapshot> snapshot_;
  std::shared_ptr<const Json> stats_;
  std::shared_ptr<const Scene> scene_published_;
  std::uint64_t sequence_ = 0;
  std::uint64_t generation_ = 0;  // fresh starts: scene.load, state.load, sim.reset (session thread)

  std::mutex listeners_mutex_;
  std::vector<std::pair<int, std::function<void()>>> listeners_;
  int next_listener_ = 1;
};

}  // namespace thaw

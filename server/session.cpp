#include "server/session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>

#include "server/thread_priority.h"
#include "sim/error.h"
#include "sim/json_text.h"
#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/thermal.h"

namespace thaw {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using protocol::ErrorCode;

namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

// State names become file names in the state folder: nothing that could leave it (docs/ARCHITECTURE.md: the
// protocol checks this too; the session does not rely on its caller for what touches the disk).
bool valid_state_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

// Completions run on the simulation thread; one that throws must not take the thread down with it.
void answer(const Session::Done& done, std::optional<ErrorCode> code, const std::string& message,
            const Json& result) {
  if (!done) return;
  try {
    done(code, message, result);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "thaw serve: a command's completion failed: %s\n", e.what());
  }
}

// Why a dryer, lamp or emitter index is not one of the scene's; empty when it is.
std::string missing(const std::string& what, int index, std::size_t count) {
  if (index >= 0 && std::size_t(index) < count) return "";
  return what + " " + std::to_string(index) + " does not exist; the scene has " + std::to_string(count);
}

double ice_mass_of(const HostParticles& p, const Scene& scene, double rest_density) {
  return measure(p, scene, rest_density).ice_mass;
}

}  // namespace

Session::Session(ClRuntime& cl, std::string scene_name, std::vector<std::string> overrides,
                 std::string state_dir)
    : cl_(cl), overrides_(std::move(overrides)), state_dir_(std::move(state_dir)) {
  std::error_code ec;
  fs::create_directories(state_dir_, ec);
  if (ec) throw Error("cannot create the state folder '" + state_dir_ + "': " + ec.message());
  Scene scene = load_scene(scene_name, overrides_);
  const SimState start = initial_state(scene);
  rebuild(std::move(scene), start, true);
  last_publish_ = Clock::now();
  publish();
}

Session::~Session() { stop(); }

void Session::start() {
  std::lock_guard lock(queue_mutex_);
  if (thread_.joinable() || stop_) return;
  thread_running_ = true;
  thread_ = std::thread(&Session::run, this);
}

void Session::stop() {
  std::deque<Pending> never_run;
  {
    std::lock_guard lock(queue_mutex_);
    stop_ = true;
    // Without a thread nothing would ever answer what was queued before start().
    if (!thread_.joinable()) never_run.swap(queue_);
  }
  queue_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  for (Pending& p : never_run) {
    if (auto* task = std::get_if<Task>(&p.what))
      (*task)();
    else
      answer(p.done, ErrorCode::Failed, "the simulation has stopped", Json::object());
  }
}

namespace {

// Which waiting command a rebuilding command replaces: "" for commands that never replace another.
std::string rebuild_slot(const protocol::Command& c) {
  if (std::holds_alternative<protocol::SimReset>(c) || std::holds_alternative<protocol::SceneLoad>(c) ||
      std::holds_alternative<protocol::StateLoad>(c))
    return "rebuild";
  if (const auto* p = std::get_if<protocol::ParamSet>(&c)) return "param " + p->path;
  return "";
}

}  // namespace

void Session::submit(protocol::Command command, Done done) {
  const std::string slot = rebuild_slot(command);
  const std::string type = protocol::type_name(command);
  enqueue({std::move(command), std::move(done)}, slot, type);
}

void Session::aim_dryer(int dryer, const Eigen::Vector3d& hit, Done done) {
  enqueue({Aim{dryer, hit}, std::move(done)}, "", "dryer.aim");
}

void Session::drop_substance(const std::string& substance, double amount, const Eigen::Vector3d& hit,
                             Done done) {
  enqueue({Drop{substance, amount, hit}, std::move(done)}, "", "substance.drop");
}

void Session::enqueue(Pending pending, const std::string& slot, const std::string& type) {
  Done superseded, busy, stopped;
  std::size_t queued = 0;
  {
    std::lock_guard lock(queue_mutex_);
    if (stop_ && !thread_running_) {
      stopped = std::move(pending.done);
    } else {
      if (!slot.empty()) {
        const auto same = std::find_if(queue_.begin(), queue_.end(), [&](const Pending& p) {
          const auto* c = std::get_if<protocol::Command>(&p.what);
          return c != nullptr && rebuild_slot(*c) == slot;
        });
        if (same != queue_.end()) {
          superseded = std::move(same->done);
          queue_.erase(same);
        }
      }
      queued = queue_.size();
      if (queued >= kMaxQueued)
        busy = std::move(pending.done);
      else
        queue_.push_back(std::move(pending));
    }
  }
  queue_cv_.notify_all();
  if (superseded)
    answer(superseded, ErrorCode::Failed, "superseded: a newer " + type + " arrived before this one ran",
           Json::object());
  if (busy)
    answer(busy, ErrorCode::RateLimited,
           "the simulation has " + std::to_string(queued) +
               " commands waiting from all clients; try again shortly",
           Json::object());
  if (stopped) answer(stopped, ErrorCode::Failed, "the simulation has stopped", Json::object());
}

bool Session::stopping() {
  std::lock_guard lock(queue_mutex_);
  return stop_;
}

void Session::save_state(const std::string& path) {
  auto write = [this, path] {
    SimState st = solver_->state();
    st.scene_json = scene_.source.dump();  // with the live dryer and lamp changes
    write_state_file(path, st);
  };
  std::unique_lock lock(queue_mutex_);
  if (!thread_running_) {
    lock.unlock();
    write();
    return;
  }
  auto promise = std::make_shared<std::promise<void>>();
  std::future<void> written = promise->get_future();
  queue_.push_back({Task([write, promise] {
                      try {
                        write();
                        promise->set_value();
                      } catch (...) {
                        promise->set_exception(std::current_exception());
                      }
                    }),
                    {}});
  lock.unlock();
  queue_cv_.notify_all();
  written.get();
}

// ---- published values ---------------------------------------------------------------------------------

std::shared_ptr<const RenderSnapshot> Session::latest_snapshot() const {
  std::lock_guard lock(publish_mutex_);
  return snapshot_;
}

std::shared_ptr<const Json> Session::latest_stats() const {
  std::lock_guard lock(publish_mutex_);
  return stats_;
}

std::shared_ptr<const Scene> Session::scene() const {
  std::lock_guard lock(publish_mutex_);
  return scene_published_;
}

std::uint64_t Session::sequence() const {
  std::lock_guard lock(publish_mutex_);
  return sequence_;
}

std::uint64_t Session::wait_for_sequence(std::uint64_t after, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(publish_mutex_);
  publish_cv_.wait_for(lock, timeout, [&] { return sequence_ > after; });
  return sequence_;
}

int Session::subscribe(std::function<void()> on_publish) {
  std::lock_guard lock(listeners_mutex_);
  listeners_.emplace_back(next_listener_, std::move(on_publish));
  return next_listener_++;
}

void Session::unsubscribe(int id) {
  std::lock_guard lock(listeners_mutex_);
  std::erase_if(listeners_, [id](const auto& l) { return l.first == id; });
}

// ---- the simulation thread -----------------------------------------------------------------------------

void Session::run() {
  lower_this_thread_priority(thread_nice_);
  reanchor();
  last_publish_ = Clock::now();
  window_start_steps_ = solver_->steps();
  for (;;) {
    std::deque<Pending> batch;
    {
      std::lock_guard lock(queue_mutex_);
      if (stop_) break;
      batch.swap(queue_);
    }
    if (!batch.empty()) apply_pending(batch);

    // sim.step requests go first and ignore both pause and speed: the user asked for those steps now.
    if (!step_requests_.empty()) {
      step_once();
      if (step_requests_.empty()) continue;  // the step failed and answered them
      if (--step_requests_.front().remaining > 0) {
        maybe_publish();
        continue;
      }
      StepRequest finished = std::move(step_requests_.front());
      step_requests_.pop_front();
      publish();
      answer(finished.done, std::nullopt, "", time_result());
      continue;
    }

    if (running_) {
      if (speed_ > 0) {
        // Never run ahead of wall time * factor; when behind by more than a moment, start counting afresh
        // rather than sprint to catch up.
        // In double and bounded before it becomes a duration: a tiny factor made this overflow the
        // clock's integer ticks into the past, and the run went flat out.
        const double ahead_s = std::clamp((solver_->time() - anchor_sim_) / speed_, 0.0, 3600.0);
        const auto due =
            anchor_wall_ + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(std::isfinite(ahead_s) ? ahead_s : 0.0));
        const auto now = Clock::now();
        if (now < due) {
          if (dirty_) maybe_publish();
          wait_for_work(std::min(due, now + std::chrono::milliseconds(100)));
          continue;
        }
        if (now - due > std::chrono::milliseconds(100)) reanchor();
      }
      step_once();
      maybe_publish();
      continue;
    }

    if (dirty_) publish();
    wait_for_work(std::nullopt);
  }

  // Stopping: run what save_state() queued (a caller waits on it); the commands only learn they failed.
  // thread_running_ drops only once the queue is empty, so save_state() never runs beside this thread.
  for (;;) {
    std::deque<Pending> rest;
    {
      std::lock_guard lock(queue_mutex_);
      if (queue_.empty()) {
        thread_running_ = false;
        break;
      }
      rest.swap(queue_);
    }
    for (Pending& p : rest) {
      if (auto* task = std::get_if<Task>(&p.what))
        (*task)();
      else
        answer(p.done, ErrorCode::Failed, "the simulation has stopped", Json::object());
    }
  }
  fail_step_requests("the simulation has stopped");
}

bool Session::wait_for_work(std::optional<Clock::time_point> until) {
  std::unique_lock lock(queue_mutex_);
  auto ready = [&] { return stop_ || !queue_.empty(); };
  if (until) return queue_cv_.wait_until(lock, *until, ready);
  queue_cv_.wait(lock, ready);
  return true;
}

void Session::apply_pending(std::deque<Pending>& batch) {
  struct Answer {
    Done done;
    Outcome outcome;
  };
  std::vector<Answer> answers;
  for (Pending& p : batch) {
    if (auto* task = std::get_if<Task>(&p.what)) {
      (*task)();
      continue;
    }
    // Shutdown interrupts a batch: what is left of it only learns that it failed.
    if (stopping()) {
      answers.push_back({std::move(p.done), Outcome{ErrorCode::Failed, "the simulation has stopped", {}}});
      continue;
    }
    Outcome o;
    bool deferred = false;
    try {
      if (auto* a = std::get_if<Aim>(&p.what))
        o = aim(*a);
      else if (auto* d = std::get_if<Drop>(&p.what))
        o = drop(*d);
      else
        o = apply(std::get<protocol::Command>(p.what), p.done, deferred);
    } catch (const std::exception& e) {
      // Whatever a command throws past its own handling (a device error while rebuilding, say) is
      // the command's failure, not the service's.
      o = {ErrorCode::Failed, e.what(), Json::object()};
    }
    if (deferred) continue;
    // Every ack says at which simulated time and step the command took effect: a frame whose header
    // time is at or after it shows the change (the stream's latency is measured from there).
    if (!o.code && (o.result.is_object() || o.result.is_null()) && !o.result.contains("time")) {
      if (o.result.is_null()) o.result = Json::object();
      const Json when = time_result();
      for (const auto& [key, value] : when.items()) o.result[key] = value;
    }
    answers.push_back({std::move(p.done), std::move(o)});
  }
  // Answer after publishing, so a client that sees the ack and then reads the stats sees its change.
  if (dirty_) publish();
  for (Answer& a : answers) answer(a.done, a.outcome.code, a.outcome.message, a.outcome.result);
}

Session::Outcome Session::apply(const protocol::Command& command, Done& done, bool& deferred) {
  return std::visit(
      Overloaded{
          [&](const protocol::DryerSet& c) { return apply(c); },
          [&](const protocol::LampSet& c) { return apply(c); },
          [&](const protocol::EmitterSet& c) { return apply(c); },
          [&](const protocol::SceneLoad& c) { return apply(c); },
          [&](const protocol::ParamSet& c) { return apply(c); },
          [&](const protocol::StateSave& c) { return apply(c); },
          [&](const protocol::StateLoad& c) { return apply(c); },
          [&](const protocol::SimPause&) {
            running_ = false;
            paused_by_error_ = false;
            dirty_ = true;
            return Outcome{std::nullopt, "", time_result()};
          },
          [&](const protocol::SimResume&) {
            running_ = true;
            paused_by_error_ = false;
            reanchor();
            dirty_ = true;
            return Outcome{std::nullopt, "", time_result()};
          },
          [&](const protocol::SimStep& c) {
            if (c.n < 1 || c.n > 10000)
              return Outcome{ErrorCode::BadField, "n: " + std::to_string(c.n) + " is outside 1..10000", {}};
            // Answered when the last of the n steps is done.
            step_requests_.push_back({c.n, c.n, std::move(done)});
            deferred = true;
            return Outcome{};
          },
          [&](const protocol::SimReset&) {
            const SimState start = initial_state(scene_);
            rebuild(scene_, start, true);
            return Outcome{std::nullopt, "", time_result()};
          },
          [&](const protocol::SimSpeed& c) {
            if (!std::isfinite(c.factor) || !(c.factor == 0 || (c.factor >= 1e-3 && c.factor <= 1000)))
              return Outcome{
                  ErrorCode::BadField, "factor: must be in [0.001, 1000], or 0 for as fast as possible", {}};
            speed_ = c.factor;
            reanchor();
            dirty_ = true;
            return Outcome{std::nullopt, "", Json{{"factor", speed_}}};
          },
          [&](const protocol::DryerAim&) {
            return Outcome{ErrorCode::Failed,
                           "dryer.aim needs the picked surface point: the render side picks it, then calls "
                           "Session::aim_dryer",
                           {}};
          },
          [&](const protocol::SubstanceDrop&) {
            return Outcome{ErrorCode::Failed,
                           "substance.drop needs the picked surface point: the render side picks it, then "
                           "calls Session::drop_substance",
                           {}};
          },
          [&](const auto&) {
            return Outcome{ErrorCode::Failed, "not a simulation command", {}};
          },
      },
      command);
}

Json Session::adopt(const std::string& array, int index, const Json& fields) {
  Json& source = scene_.source[array][std::size_t(index)];
  for (const auto& [key, value] : fields.items()) source[key] = value;
  {
    std::lock_guard lock(publish_mutex_);
    scene_published_ = std::make_shared<const Scene>(scene_);
  }
  dirty_ = true;
  Json result = fields;
  result[array.substr(0, array.size() - 1)] = index;  // "dryer": 0
  return result;
}

Session::Outcome Session::set_dryer(int index, const Dryer& d) {
  try {
    solver_->set_dryer(std::size_t(index), d);
  } catch (const Error& e) {
    return {ErrorCode::BadField, e.what(), {}};
  }
  const Dryer& now = solver_->dryers()[std::size_t(index)];
  scene_.dryers[std::size_t(index)] = now;
  return {std::nullopt, "", adopt("dryers", index, to_json(now))};
}

Session::Outcome Session::apply(const protocol::DryerSet& c) {
  if (std::string m = missing("dryer", c.dryer, solver_->dryers().size()); !m.empty())
    return {ErrorCode::NotFound, m, {}};
  Dryer d = solver_->dryers()[std::size_t(c.dryer)];
  if (c.on) d.on = *c.on;
  if (c.position) d.position = *c.position;
  if (c.direction) d.direction = *c.direction;
  if (c.temperature) d.temperature = *c.temperature;
  if (c.speed) d.speed = *c.speed;
  if (c.half_angle) d.half_angle = *c.half_angle;
  if (c.reach) d.reach = *c.reach;
  return set_dryer(c.dryer, d);
}

Session::Outcome Session::aim(const Aim& a) {
  if (std::string m = missing("dryer", a.dryer, solver_->dryers().size()); !m.empty())
    return {ErrorCode::NotFound, m, {}};
  Dryer d = solver_->dryers()[std::size_t(a.dryer)];
  const Eigen::Vector3d toward = a.hit - d.position;
  if (!a.hit.allFinite() || toward.norm() < 1e-9)
    return {ErrorCode::BadField, "the picked point is not finite or lies at the nozzle", {}};
  d.direction = toward.normalized();
  return set_dryer(a.dryer, d);
}

Session::Outcome Session::drop(const Drop& d) {
  const std::vector<Substance>& subs = scene_.substances;
  const auto it =
      std::find_if(subs.begin(), subs.end(), [&](const Substance& s) { return s.name == d.substance; });
  if (it == subs.end()) {
    std::string names;
    for (const Substance& s : subs) names += (names.empty() ? "" : ", ") + s.name;
    return {ErrorCode::NotFound,
            "substance: the scene declares no substance '" + d.substance + "'" +
                (names.empty() ? " (it has none)" : " (it declares " + names + ")"),
            {}};
  }
  try {
    const std::size_t taken = solver_->drop_substance(std::size_t(it - subs.begin()), d.amount, d.hit);
    dirty_ = true;
    return {std::nullopt, "", {{"substance", d.substance}, {"amount", d.amount}, {"particles", taken}}};
  } catch (const Error& e) {
    return {ErrorCode::NotFound, e.what(), {}};
  }
}

Session::Outcome Session::apply(const protocol::LampSet& c) {
  if (std::string m = missing("lamp", c.lamp, solver_->lamps().size()); !m.empty())
    return {ErrorCode::NotFound, m, {}};
  Lamp l = solver_->lamps()[std::size_t(c.lamp)];
  if (c.on) l.on = *c.on;
  if (c.centre) l.centre = *c.centre;
  if (c.normal) l.normal = *c.normal;
  if (c.temperature) l.temperature = *c.temperature;
  if (c.emissivity) l.emissivity = *c.emissivity;
  return set_lamp(c.lamp, l);
}

Session::Outcome Session::set_lamp(int index, const Lamp& l) {
  try {
    solver_->set_lamp(std::size_t(index), l);
  } catch (const Error& e) {
    return {ErrorCode::BadField, e.what(), {}};
  }
  const Lamp& now = solver_->lamps()[std::size_t(index)];
  scene_.lamps[std::size_t(index)] = now;
  return {std::nullopt, "", adopt("lamps", index, to_json(now))};
}

Session::Outcome Session::apply(const protocol::EmitterSet& c) {
  if (std::string m = missing("emitter", c.emitter, solver_->emitters().size()); !m.empty())
    return {ErrorCode::NotFound, m, {}};
  Emitter e = solver_->emitters()[std::size_t(c.emitter)];
  if (c.open) e.open = *c.open;
  if (c.position) e.position = *c.position;
  if (c.direction) e.direction = *c.direction;
  if (c.radius) e.radius = *c.radius;
  if (c.speed) e.speed = *c.speed;
  // A volume flow is the nozzle's (new) area times the exit speed.
  if (c.rate) e.speed = *c.rate * 1e-3 / e.area();
  if (c.temperature) e.temperature = *c.temperature;
  if (c.start) e.start = *c.start;
  if (c.stop) e.stop = *c.stop;
  return set_emitter(c.emitter, e);
}

Session::Outcome Session::set_emitter(int index, const Emitter& e) {
  const std::size_t i = std::size_t(index);
  std::string applied = "in place";
  try {
    if (!solver_->set_emitter(i, e)) {
      Scene scene = scene_;
      scene.emitters[i] = e;
      rebuild(std::move(scene), solver_->state(), false);
      applied = "rebuild";
    }
  } catch (const Error& err) {
    return {ErrorCode::BadField, err.what(), {}};
  }
  const Emitter& now = solver_->emitters()[i];
  scene_.emitters[i] = now;
  scene_.source["emitters"][i].erase("rate");  // the exit speed says it now
  Json result = adopt("emitters", index, to_json(now, scene_.materials));
  result["rate"] = now.volume_flow() * 1e3;
  result["applied"] = applied;
  return {std::nullopt, "", result};
}

Session::Outcome Session::apply(const protocol::SceneLoad& c) {
  // Only scenes in configs/: a client names one, it never hands the server a path.
  const std::string& name = c.name;
  if (name.empty() || name.front() == '.' || name.find_first_of(std::string("/\\\0", 3)) != std::string::npos)
    return {ErrorCode::BadField,
            "name: a scene is named by its file in configs/, without a path: '" + name + "'",
            {}};
  const fs::path configs = fs::path(THAW_SOURCE_DIR) / "configs";
  std::string file;
  try {
    file = resolve_scene_path((configs / name).string());
  } catch (const Error&) {
    return {ErrorCode::NotFound, "no scene named '" + name + "' in configs/", {}};
  }
  Scene scene;
  try {
    scene = load_scene(file, overrides_);
  } catch (const Error& e) {
    return {ErrorCode::Failed, e.what(), {}};
  }
  const SimState start = initial_state(scene);
  rebuild(std::move(scene), start, true);
  Json result = time_result();
  result["scene"] = scene_.name;
  result["particles"] = solver_->size();
  return {std::nullopt, "", result};
}

Session::Outcome Session::apply(const protocol::ParamSet& c) {
  const Field* field = find_field(scene_schema(), c.path);
  if (!field || !field->settable)
    return {ErrorCode::BadField, "path: '" + c.path + "' is not a parameter a client may change", {}};
  Scene scene;
  try {
    Json doc = scene_.source;
    apply_override(doc, c.path + "=" + c.value.dump());
    // An emitter's flow is its exit speed or its volume rate: the one set replaces the other.
    std::size_t k = 0;
    char key[8] = {};
    if (std::sscanf(c.path.c_str(), "emitters[%zu].%7s", &k, key) == 2) {
      if (std::string(key) == "rate") doc["emitters"][k].erase("speed");
      if (std::string(key) == "speed") doc["emitters"][k].erase("rate");
    }
    scene = scene_from_json(std::move(doc));
  } catch (const IndexPastEndError& e) {
    return {ErrorCode::NotFound, e.what(), {}};  // "dryers[5]: index 5 is past the end (...)"
  } catch (const Error& e) {
    return {ErrorCode::BadField, e.what(), {}};
  }
  // A field the schema marks live in place (a dryer's, a lamp's or an emitter's) goes the way dryer.set,
  // lamp.set and emitter.set go: into the running solver between two steps. Any other change rebuilds the
  // solver from the particles as they are, so it takes effect mid-run.
  if (field->in_place) {
    // Only dryers', lamps' and emitters' fields are marked in place: whichever one the change touched
    // goes into the running solver, as dryer.set, lamp.set and emitter.set do.
    for (std::size_t i = 0; i < scene.dryers.size(); ++i)
      if (to_json(scene.dryers[i]) != to_json(scene_.dryers[i]))
        if (Outcome done = set_dryer(int(i), scene.dryers[i]); done.code) return done;
    for (std::size_t i = 0; i < scene.lamps.size(); ++i)
      if (to_json(scene.lamps[i]) != to_json(scene_.lamps[i]))
        if (Outcome done = set_lamp(int(i), scene.lamps[i]); done.code) return done;
    std::string applied = "in place";
    for (std::size_t i = 0; i < scene.emitters.size(); ++i)
      if (to_json(scene.emitters[i], scene.materials) != to_json(scene_.emitters[i], scene_.materials)) {
        Outcome done = set_emitter(int(i), scene.emitters[i]);
        if (done.code) return done;
        applied = done.result["applied"];
      }
    return {std::nullopt, "", Json{{"path", c.path}, {"value", c.value}, {"applied", applied}}};
  }
  rebuild(std::move(scene), solver_->state(), false);
  return {std::nullopt, "", Json{{"path", c.path}, {"value", c.value}, {"applied", "rebuild"}}};
}

Session::Outcome Session::apply(const protocol::StateSave& c) {
  if (!valid_state_name(c.name))
    return {ErrorCode::BadField, "name: 1 to 64 of A-Z, a-z, 0-9, '_' and '-', got '" + c.name + "'", {}};
  const std::string path = (fs::path(state_dir_) / (c.name + ".state")).string();
  SimState st = solver_->state();
  st.scene_json = scene_.source.dump();
  try {
    write_state_file(path, st);
  } catch (const Error& e) {
    return {ErrorCode::Failed, e.what(), {}};
  }
  Json result = time_result();
  result["name"] = c.name;
  return {std::nullopt, "", result};
}

Session::Outcome Session::apply(const protocol::StateLoad& c) {
  if (!valid_state_name(c.name))
    return {ErrorCode::BadField, "name: 1 to 64 of A-Z, a-z, 0-9, '_' and '-', got '" + c.name + "'", {}};
  const std::string path = (fs::path(state_dir_) / (c.name + ".state")).string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return {ErrorCode::NotFound, "no saved state named '" + c.name + "'", {}};
  SimState st;
  Scene scene;
  try {
    st = read_state_file(path);
    scene = scene_from_json(parse_json(st.scene_json));
    check_state(st, scene, c.name);
  } catch (const std::exception& e) {
    return {ErrorCode::Failed, "state '" + c.name + "': " + e.what(), {}};
  }
  rebuild(std::move(scene), st, true);
  // ice_fraction is of the scene's start, not of the moment the state was saved.
  start_ice_mass_ = ice_mass_of(initial_state(scene_).particles, scene_, solver_->constants().rest_density);
  Json result = time_result();
  result["name"] = c.name;
  return {std::nullopt, "", result};
}

void Session::rebuild(Scene scene, const SimState& state, bool fresh_start) {
  // Build the new solver before dropping the old one: a failure leaves the running simulation as it was.
  auto solver = std::make_unique<Solver>(cl_, scene, state);
  solver->warm_up();
  solver_ = std::move(solver);
  scene_ = std::move(scene);
  if (fresh_start) {
    ++generation_;
    fail_step_requests("interrupted: the simulation was reset or replaced");
    start_ice_mass_ = ice_mass_of(state.particles, scene_, solver_->constants().rest_density);
  }
  error_.clear();
  // A blow-up paused the run, not the user: a fresh state carries on where the user left it.
  if (paused_by_error_) running_ = true;
  paused_by_error_ = false;
  reanchor();
  window_start_steps_ = solver_->steps();
  window_step_seconds_ = 0;
  {
    std::lock_guard lock(publish_mutex_);
    scene_published_ = std::make_shared<const Scene>(scene_);
  }
  dirty_ = true;
}

void Session::step_once() {
  const auto t0 = Clock::now();
  try {
    solver_->step();
    error_.clear();
  } catch (const std::exception& e) {
    // A blow-up (or a device failure) pauses and reports; the service keeps serving, and reset,
    // scene.load or state.load recover.
    error_ = e.what();
    running_ = false;
    paused_by_error_ = true;
    std::fprintf(stderr, "thaw serve: simulation paused: %s\n", e.what());
    fail_step_requests(error_);
    publish();
    return;
  }
  window_step_seconds_ += std::chrono::duration<double>(Clock::now() - t0).count();
  dirty_ = true;
}

void Session::fail_step_requests(const std::string& why) {
  std::deque<StepRequest> failed;
  failed.swap(step_requests_);
  for (StepRequest& r : failed) {
    Json result = time_result();
    result["done"] = r.requested - r.remaining;
    answer(r.done, ErrorCode::Failed, why, result);
  }
}

void Session::reanchor() {
  anchor_wall_ = Clock::now();
  anchor_sim_ = solver_ ? solver_->time() : 0.0;
}

Json Session::time_result() const {
  return {{"time", solver_->time()}, {"steps", solver_->steps()}, {"paused", !running_}};
}

void Session::maybe_publish() {
  if (Clock::now() - last_publish_ >= std::chrono::duration<double>(1.0 / kPublishRate)) publish();
}

void Session::publish() {
  const auto now = Clock::now();
  const double wall = std::chrono::duration<double>(now - last_publish_).count();
  const std::uint64_t steps = solver_->steps();
  const std::uint64_t window_steps = steps - std::min(steps, window_start_steps_);
  if (window_steps > 0) last_step_ms_ = 1e3 * window_step_seconds_ / double(window_steps);

  std::shared_ptr<const RenderSnapshot> snapshot;
  Json stats = {{"type", "stats"},
                {"scene", scene_.name},
                {"time", solver_->time()},
                {"steps", steps},
                {"generation", generation_},
                {"heat_time_scale", scene_.heat.time_scale},
                {"tension", name(scene_.tension.model)}};
  try {
    // One read of the device serves the picture and the numbers.
    const HostParticles p = solver_->particles();
    const Scene& scene = solver_->scene();
    const std::vector<float> temperature = temperatures_of(p, scene);
    snapshot = std::make_shared<const RenderSnapshot>(
        make_snapshot(p, temperature.size() == p.size() ? temperature : std::vector<float>{}, scene,
                      solver_->time(), steps));
    Metrics m = measure(p, scene, solver_->constants().rest_density);
    m.budget = solver_->energy_budget();
    stats["dt"] = solver_->dt();
    stats["steps_per_second"] = wall > 0 ? double(window_steps) / wall : 0.0;
    stats["step_ms"] = last_step_ms_;
    stats["speed"] = speed_;
    Json counts = Json::object();
    for (int i = 0; i < kPhaseCount; ++i) counts[phase_name(static_cast<Phase>(i))] = m.count[i];
    stats["particles"] = counts;
    stats["ice_mass"] = m.ice_mass;
    stats["water_mass"] = m.water_mass;
    stats["ice_fraction"] = start_ice_mass_ > 0 ? Json(m.ice_mass / start_ice_mass_) : Json(nullptr);
    if (const OutflowBooks& out = solver_->outflow(); out.particles)
      stats["outflow"] = {{"particles", out.particles}, {"mass", out.mass}, {"enthalpy", m.budget.outflow}};
    if (const InflowBooks in = solver_->inflow(); in.particles)
      stats["inflow"] = {{"particles", in.particles}, {"mass", in.mass}, {"enthalpy", m.budget.inflow}};
    // DFSPH: the last step's solves and the run's counts, as the metrics carry them.
    if (Json d = pressure_solve_json(*solver_); !d.is_null()) stats["dfsph"] = std::move(d);
    if (Json d = substances_json(*solver_); !d.is_null()) stats["substances"] = std::move(d);
    if (m.heat) {
      const EnergyBudget& b = m.budget;
      const double gross =
          std::abs(b.ambient) + std::abs(b.lamps) + std::abs(b.dryers) + std::abs(b.walls) + std::abs(b.held);
      stats["temperature"] = {
          {"min", m.min_temperature}, {"mean", m.mean_temperature}, {"max", m.max_temperature}};
      if (m.count[static_cast<int>(Phase::Air)])
        stats["air_temperature"] = {
            {"min", m.air_min_temperature}, {"mean", m.air_mean_temperature}, {"max", m.air_max_temperature}};
      stats["energy"] = {{"heat_in", b.heat_in()},
                         {"closure", m.closure()},
                         {"closure_relative", m.closure() / std::max({m.enthalpy_scale, gross, 1e-300})}};
    }
  } catch (const std::exception& e) {
    // The device would not give the state back: report it and keep the last picture.
    error_ = std::string("reading the simulation state failed: ") + e.what();
    running_ = false;
    paused_by_error_ = true;
  }
  stats["paused"] = !running_;
  if (!error_.empty()) stats["error"] = error_;

  auto shared_stats = std::make_shared<const Json>(std::move(stats));
  {
    std::lock_guard lock(publish_mutex_);
    if (snapshot) snapshot_ = std::move(snapshot);
    stats_ = std::move(shared_stats);
    ++sequence_;
  }
  publish_cv_.notify_all();
  {
    std::lock_guard lock(listeners_mutex_);
    for (auto& [id, listener] : listeners_) listener();
  }
  last_publish_ = now;
  window_start_steps_ = steps;
  window_step_seconds_ = 0;
  dirty_ = false;
}

}  // namespace thaw

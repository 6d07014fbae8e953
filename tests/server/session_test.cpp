// The simulation thread (Session) and the render thread (RenderWorker) of `thaw serve`, driven the way the
// network loop drives them: commands in through submit(), answers through the completion, and the
// published stats, snapshots and frames read from other threads.
#include "server/session.h"

#include <turbojpeg.h>

#include <chrono>
#include <future>
#include <map>
#include <mutex>
#include <thread>

#include "server/render_worker.h"
#include "server/thread_priority.h"
#include "sim/error.h"
#include "sim/solver.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using namespace std::chrono_literals;
using protocol::ErrorCode;
using testing::TempDir;

struct Reply {
  bool answered = false;
  std::optional<ErrorCode> code;
  std::string message;
  Json result;
};

// Submits and waits for the completion, as the network loop would (it marshals the answer instead).
Reply call(Session& s, protocol::Command c, std::chrono::milliseconds timeout = 20s) {
  auto promise = std::make_shared<std::promise<Reply>>();
  std::future<Reply> answer = promise->get_future();
  s.submit(std::move(c), [promise](std::optional<ErrorCode> code, std::string message, Json result) {
    promise->set_value({true, code, std::move(message), std::move(result)});
  });
  if (answer.wait_for(timeout) != std::future_status::ready) return {};
  return answer.get();
}

// Waits until the published stats satisfy `ok`; returns them (or the last ones on timeout).
template <class F>
std::shared_ptr<const Json> wait_for_stats(const Session& s, F ok, std::chrono::milliseconds timeout = 10s) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const std::uint64_t seq = s.sequence();
    auto stats = s.latest_stats();
    if (ok(*stats) || std::chrono::steady_clock::now() > end) return stats;
    s.wait_for_sequence(seq, 100ms);
  }
}

class SessionTest : public testing::ClSuite {
 protected:
  std::unique_ptr<Session> make(const std::string& scene, std::vector<std::string> extra = {}) {
    std::vector<std::string> overrides = {"spacing=0.006"};
    overrides.insert(overrides.end(), extra.begin(), extra.end());
    return std::make_unique<Session>(cl(), scene, overrides, (dir_.path() / "states").string());
  }
  TempDir dir_{"session"};
};

TEST_F(SessionTest, PublishesSnapshotsAndStats) {
  auto s = make("ice-on-plate");
  // The constructor publishes the starting state, so a viewer has a picture before the first step.
  ASSERT_TRUE(s->latest_snapshot());
  EXPECT_EQ((*s->latest_stats())["type"], "stats");
  EXPECT_EQ((*s->latest_stats())["steps"], 0);
  const std::uint64_t first = s->sequence();
  s->start();
  auto stats = wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 3; });
  EXPECT_GT(s->sequence(), first);
  EXPECT_GE((*stats)["steps"].get<std::uint64_t>(), 3u);
  EXPECT_GT((*stats)["time"].get<double>(), 0.0);
  EXPECT_FALSE((*stats)["paused"].get<bool>());
  EXPECT_GT((*stats)["particles"]["ice"].get<std::size_t>(), 0u);
  EXPECT_NEAR((*stats)["ice_fraction"].get<double>(), 1.0, 0.05);
  EXPECT_TRUE(stats->contains("temperature"));
  EXPECT_TRUE((*stats)["energy"].contains("closure_relative"));
  EXPECT_FALSE(stats->contains("error"));
  const auto snapshot = s->latest_snapshot();
  std::size_t count = 0;
  for (const auto& [phase, n] : (*stats)["particles"].items()) count += n.get<std::size_t>();
  EXPECT_EQ(snapshot->position.size(), count);
  EXPECT_EQ(snapshot->temperature.size(), count);
  s->stop();
}

TEST_F(SessionTest, DryerSetMergesIntoTheDryerAndRefusesBadValues) {
  auto s = make("default");
  s->start();
  const double half_angle = s->scene()->dryers.at(0).half_angle;
  protocol::DryerSet set;
  set.dryer = 0;
  set.speed = 20.0;
  set.temperature = 80.0;
  Reply r = call(*s, set);
  ASSERT_TRUE(r.answered);
  EXPECT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["speed"], 20.0);
  EXPECT_EQ(s->scene()->dryers[0].speed, 20.0);
  EXPECT_EQ(s->scene()->dryers[0].temperature, 80.0);
  EXPECT_EQ(s->scene()->dryers[0].half_angle, half_angle);  // fields left out keep their value
  // The ack says when the change took effect: a frame drawn from that time on shows it.
  ASSERT_TRUE(r.result.contains("time") && r.result.contains("steps")) << r.result.dump();
  EXPECT_GE(r.result["time"].get<double>(), 0.0);
  EXPECT_LE(r.result["time"].get<double>(), (*s->latest_stats())["time"].get<double>());

  protocol::DryerSet fast;
  fast.speed = 250.0;
  r = call(*s, fast);
  ASSERT_TRUE(r.answered);
  EXPECT_EQ(r.code, ErrorCode::BadField);
  EXPECT_NE(r.message.find("speed"), std::string::npos) << r.message;
  EXPECT_EQ(s->scene()->dryers[0].speed, 20.0);

  protocol::DryerSet missing;
  missing.dryer = 3;
  missing.on = false;
  r = call(*s, missing);
  EXPECT_EQ(r.code, ErrorCode::NotFound);

  // Still stepping after the refusals.
  const auto steps = (*s->latest_stats())["steps"].get<std::uint64_t>();
  auto stats = wait_for_stats(*s, [&](const Json& j) { return j["steps"].get<std::uint64_t>() > steps; });
  EXPECT_GT((*stats)["steps"].get<std::uint64_t>(), steps);

  // Aiming points the dryer from its nozzle at the picked point.
  const Eigen::Vector3d nozzle = s->scene()->dryers[0].position;
  auto promise = std::make_shared<std::promise<std::optional<ErrorCode>>>();
  auto aimed = promise->get_future();
  s->aim_dryer(0, nozzle + Eigen::Vector3d(0.03, 0, -0.04),
               [promise](std::optional<ErrorCode> code, std::string, Json) { promise->set_value(code); });
  ASSERT_EQ(aimed.wait_for(20s), std::future_status::ready);
  EXPECT_FALSE(aimed.get());
  EXPECT_TRUE(s->scene()->dryers[0].direction.isApprox(Eigen::Vector3d(0.6, 0, -0.8), 1e-9));
}

// substance.drop after the pick: the dose goes into the ice and water around the point and into the books;
// a name the scene does not declare, or a point far from any water or ice, is not_found and changes nothing.
TEST_F(SessionTest, DropsASubstanceWhereThePickWasAndBooksIt) {
  auto s = make("salt-on-ice", {"spacing=0.004"});
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 1; });
  auto drop = [&](const std::string& name, double amount, const Eigen::Vector3d& at) {
    auto promise = std::make_shared<std::promise<Reply>>();
    auto answer = promise->get_future();
    s->drop_substance(name, amount, at,
                      [promise](std::optional<ErrorCode> code, std::string message, Json result) {
                        promise->set_value(Reply{true, code, std::move(message), std::move(result)});
                      });
    EXPECT_EQ(answer.wait_for(20s), std::future_status::ready);
    return answer.get();
  };
  Reply r = drop("salt", 1e-4, Eigen::Vector3d(0.05, 0.05, 0.01));  // on the dry ice's top
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_GT(r.result["particles"].get<int>(), 1);
  // The next stats carry the dose as the salt's inflow, and the books still close.
  auto stats = wait_for_stats(*s, [](const Json& j) {
    return j.contains("substances") && j["substances"]["salt"]["inflow"].get<double>() > 0;
  });
  ASSERT_TRUE(stats);
  const Json& salt = (*stats)["substances"]["salt"];
  EXPECT_NEAR(salt["inflow"].get<double>(), 1e-4, 1e-15);
  EXPECT_LT(std::abs(salt["closure_relative"].get<double>()), 1e-12) << salt.dump();

  r = drop("pepper", 1e-4, Eigen::Vector3d(0.05, 0.05, 0.01));
  EXPECT_EQ(r.code, ErrorCode::NotFound);
  EXPECT_NE(r.message.find("salt, dye"), std::string::npos) << r.message;
  r = drop("dye", 1e-4, Eigen::Vector3d(0.5, 0.5, 0.5));
  EXPECT_EQ(r.code, ErrorCode::NotFound);
  EXPECT_NE(r.message.find("no water or ice"), std::string::npos) << r.message;
}

TEST_F(SessionTest, PauseHoldsTimeAndStepAdvancesExactly) {
  auto s = make("ice-on-plate");
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 2; });
  Reply r = call(*s, protocol::SimPause{});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  const auto steps = r.result["steps"].get<std::uint64_t>();
  const double time = r.result["time"].get<double>();
  std::this_thread::sleep_for(150ms);
  EXPECT_EQ((*s->latest_stats())["steps"].get<std::uint64_t>(), steps);
  EXPECT_EQ((*s->latest_stats())["time"].get<double>(), time);
  EXPECT_TRUE((*s->latest_stats())["paused"].get<bool>());

  r = call(*s, protocol::SimStep{5});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["steps"].get<std::uint64_t>(), steps + 5);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ((*s->latest_stats())["steps"].get<std::uint64_t>(), steps + 5);
  EXPECT_GT((*s->latest_stats())["time"].get<double>(), time);

  EXPECT_EQ(call(*s, protocol::SimStep{0}).code, ErrorCode::BadField);
  r = call(*s, protocol::SimResume{});
  EXPECT_FALSE(r.code);
  wait_for_stats(*s, [&](const Json& j) { return j["steps"].get<std::uint64_t>() > steps + 5; });
  EXPECT_GT((*s->latest_stats())["steps"].get<std::uint64_t>(), steps + 5);
}

TEST_F(SessionTest, ResetGoesBackToTheStart) {
  auto s = make("ice-on-plate");
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 3; });
  Reply r = call(*s, protocol::SimReset{});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["time"].get<double>(), 0.0);
  EXPECT_EQ(r.result["steps"].get<std::uint64_t>(), 0u);
}

TEST_F(SessionTest, StateSaveAndLoadRoundTripInsideTheStateFolder) {
  auto s = make("ice-on-plate");
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 2; });
  ASSERT_FALSE(call(*s, protocol::SimPause{}).code);
  Reply saved = call(*s, protocol::StateSave{"snap_1"});
  ASSERT_TRUE(saved.answered);
  ASSERT_FALSE(saved.code) << saved.message;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_.path() / "states" / "snap_1.state"));

  ASSERT_FALSE(call(*s, protocol::SimStep{3}).code);
  Reply loaded = call(*s, protocol::StateLoad{"snap_1"});
  ASSERT_TRUE(loaded.answered);
  ASSERT_FALSE(loaded.code) << loaded.message;
  EXPECT_EQ(loaded.result["steps"], saved.result["steps"]);
  EXPECT_EQ(loaded.result["time"], saved.result["time"]);
  EXPECT_EQ((*s->latest_stats())["steps"], saved.result["steps"]);

  // Names never become paths: nothing is written beside (or above) the state folder.
  EXPECT_EQ(call(*s, protocol::StateSave{"../evil"}).code, ErrorCode::BadField);
  EXPECT_EQ(call(*s, protocol::StateSave{"a/b"}).code, ErrorCode::BadField);
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "evil.state"));
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "states" / "a"));
  EXPECT_EQ(call(*s, protocol::StateLoad{"../evil"}).code, ErrorCode::BadField);
  EXPECT_EQ(call(*s, protocol::StateLoad{"never_saved"}).code, ErrorCode::NotFound);

  // A damaged file is a Failed load, and the running simulation is left as it was.
  testing::write_text(dir_.path() / "states" / "broken.state", "not a state file");
  Reply broken = call(*s, protocol::StateLoad{"broken"});
  EXPECT_EQ(broken.code, ErrorCode::Failed);
  EXPECT_EQ((*s->latest_stats())["steps"], saved.result["steps"]);

  // A file with valid checksums and a particle far away crashed the service inside a kernel; it is now
  // refused before the solver is built, naming the section and the particle.
  SimState far = read_state_file((dir_.path() / "states" / "snap_1.state").string());
  far.particles.position[5][0] = 1e9f;
  write_state_file((dir_.path() / "states" / "far.state").string(), far);
  Reply refused = call(*s, protocol::StateLoad{"far"});
  EXPECT_EQ(refused.code, ErrorCode::Failed);
  EXPECT_NE(refused.message.find("section 'position', particle 5"), std::string::npos) << refused.message;
  EXPECT_EQ((*s->latest_stats())["steps"], saved.result["steps"]);

  // save_state() for shutdown, while the thread runs and after it stopped.
  s->save_state(dir_ / "running.state");
  s->stop();
  s->save_state(dir_ / "stopped.state");
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_.path() / "running.state"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_.path() / "stopped.state"));
  EXPECT_EQ(call(*s, protocol::SimResume{}).code, ErrorCode::Failed);  // answered, not left hanging
}

TEST_F(SessionTest, RebuildsCoalesceTheQueueIsBoundedAndStopInterruptsABacklog) {
  // One client's sim.reset at 19/s once queued 190 rebuilds: acks 31 s late and no frames meanwhile.
  auto s = make("ice-on-plate");
  struct Tally {
    std::mutex m;
    std::map<std::string, int> by;
    int answered = 0;
  };
  auto tally = std::make_shared<Tally>();
  auto count = [tally](std::optional<ErrorCode> code, std::string message, Json) {
    std::lock_guard lock(tally->m);
    ++tally->answered;
    ++tally->by[code ? std::string(protocol::error_code_name(*code)) + " " + message.substr(0, 10) : "ok"];
  };
  // Before start() nothing drains the queue: 200 resets leave one waiting, the other 199 superseded.
  for (int i = 0; i < 200; ++i) s->submit(protocol::SimReset{}, count);
  // A param.set replaces only the one of its own path.
  s->submit(protocol::ParamSet{"heat.time_scale", 10}, count);
  s->submit(protocol::ParamSet{"heat.time_scale", 20}, count);
  s->submit(protocol::ParamSet{"solver.cfl", 0.3}, count);
  {
    std::lock_guard lock(tally->m);
    EXPECT_EQ(tally->by["failed superseded"], 200);
  }
  // The queue is bounded across clients: what does not fit is refused at once.
  for (std::size_t i = 0; i < Session::kMaxQueued + 40; ++i) s->submit(protocol::DryerSet{}, count);
  {
    std::lock_guard lock(tally->m);
    EXPECT_EQ(tally->by["rate_limited the simula"], 43);  // 3 waited already
  }
  // Started, everything queued is answered; the newest param.set of a path is the one applied.
  s->start();
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline) {
    {
      std::lock_guard lock(tally->m);
      if (tally->answered == 203 + int(Session::kMaxQueued) + 40) break;
    }
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(s->scene()->heat.time_scale, 20.0);
  EXPECT_EQ(s->scene()->solver.cfl, 0.3);
  // stop() with a backlog: a batch being applied is cut short, whatever is left fails, quickly.
  for (int i = 0; i < 300; ++i) {
    s->submit(protocol::SimReset{}, count);
    s->submit(protocol::SimStep{50}, count);
  }
  const auto t0 = std::chrono::steady_clock::now();
  s->stop();
  const double stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(stop_s, 2.0);
  std::printf("[ info ] stop() with a backlog of 300 resets and step requests: %.3f s\n", stop_s);
  std::lock_guard lock(tally->m);
  EXPECT_EQ(tally->answered, 203 + int(Session::kMaxQueued) + 40 + 600);
}

TEST_F(SessionTest, SceneLoadOnlyFromConfigs) {
  auto s = make("ice-on-plate");
  s->start();
  Reply r = call(*s, protocol::SceneLoad{"no-such-scene"});
  ASSERT_TRUE(r.answered);
  EXPECT_EQ(r.code, ErrorCode::NotFound);
  EXPECT_EQ(call(*s, protocol::SceneLoad{"../configs/default"}).code, ErrorCode::BadField);
  EXPECT_EQ(call(*s, protocol::SceneLoad{"/etc/passwd"}).code, ErrorCode::BadField);
  EXPECT_EQ(s->scene()->name, "ice-on-plate");

  r = call(*s, protocol::SceneLoad{"default"});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(s->scene()->name, "default");
  EXPECT_EQ(s->scene()->spacing, 0.006);  // the session's overrides hold for every scene it loads
  EXPECT_EQ(s->scene()->dryers.size(), 1u);
}

TEST_F(SessionTest, ParamSetTakesEffectAndKeepsTheParticles) {
  auto s = make("ice-on-plate");
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 2; });
  ASSERT_FALSE(call(*s, protocol::SimPause{}).code);
  const auto steps = (*s->latest_stats())["steps"].get<std::uint64_t>();
  Reply r = call(*s, protocol::ParamSet{"heat.time_scale", 50});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(s->scene()->heat.time_scale, 50.0);
  EXPECT_EQ((*s->latest_stats())["steps"].get<std::uint64_t>(), steps);

  EXPECT_EQ(call(*s, protocol::ParamSet{"heat.time_scale", -1}).code, ErrorCode::BadField);
  EXPECT_EQ(call(*s, protocol::ParamSet{"spacing", 0.01}).code, ErrorCode::BadField);  // not live
  EXPECT_EQ(s->scene()->heat.time_scale, 50.0);
  // An index past the scene's array is not_found, as PROTOCOL.md says (it was bad_field).
  const Reply missing = call(*s, protocol::ParamSet{"dryers[5].speed", 5});
  EXPECT_EQ(missing.code, ErrorCode::NotFound) << missing.message;
  EXPECT_EQ(missing.message.rfind("dryers[5]: index 5 is past the end (the array has 0 elements)", 0), 0u)
      << missing.message;
  ASSERT_FALSE(call(*s, protocol::SimStep{2}).code);
}

// A dryer's and a lamp's fields are live in place (the schema says so): param.set of one takes the same
// path as dryer.set, into the running solver; other live fields rebuild it from the particles.
TEST_F(SessionTest, ParamSetOfADryerFieldAppliesInPlaceLikeDryerSet) {
  auto s = make("default");
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 1; });
  ASSERT_FALSE(call(*s, protocol::SimPause{}).code);
  Reply r = call(*s, protocol::ParamSet{"dryers[0].speed", 31.5});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "in place");
  EXPECT_EQ(s->scene()->dryers.at(0).speed, 31.5);
  EXPECT_EQ(s->scene()->source["dryers"][0]["speed"], 31.5) << "the scene document follows";
  r = call(*s, protocol::ParamSet{"dryers.0.direction", Json::array({0, 0, 0})});
  EXPECT_EQ(r.code, ErrorCode::BadField) << "checked like dryer.set: " << r.message;
  r = call(*s, protocol::ParamSet{"heat.time_scale", 20});
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "rebuild");
  EXPECT_EQ(s->scene()->dryers.at(0).speed, 31.5) << "a rebuild keeps the in-place change";
  const Field* speed = find_field(scene_schema(), "dryers[0].speed");
  ASSERT_TRUE(speed);
  EXPECT_TRUE(speed->settable && speed->in_place);
}

// A tap a client turns (emitter.set, and param.set of an emitter's field): closing and opening it and a
// slower flow go into the running solver; a faster jet than the run's sound speed was chosen for
// rebuilds it from the particles as they are, keeping what has come in; a tap that does not exist is
// not_found, a bad value a bad field.
TEST_F(SessionTest, EmitterSetTurnsTheTapInPlaceOrRebuildsForAFasterJet) {
  auto s = make("pour-into-glass");
  s->start();
  wait_for_stats(*s, [](const Json& j) { return j["steps"].get<std::uint64_t>() >= 1; });
  ASSERT_FALSE(call(*s, protocol::SimPause{}).code);
  const auto inflow = [&] {
    const Json stats = *s->latest_stats();
    return stats.contains("inflow") ? stats["inflow"]["particles"].get<std::uint64_t>() : 0;
  };
  protocol::EmitterSet close;
  close.open = false;
  Reply r = call(*s, close);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "in place");
  EXPECT_EQ(r.result["open"], false);
  ASSERT_FALSE(call(*s, protocol::SimStep{200}).code);
  const std::uint64_t closed = inflow();
  ASSERT_FALSE(call(*s, protocol::SimStep{200}).code);
  EXPECT_EQ(inflow(), closed) << "a closed tap poured";

  protocol::EmitterSet open;
  open.open = true;
  open.rate = 0.05;  // L/s, slower than the scene's 0.08
  r = call(*s, open);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "in place");
  EXPECT_NEAR(r.result["rate"].get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(s->scene()->emitters.at(0).volume_flow(), 0.05e-3, 1e-15);
  EXPECT_FALSE(s->scene()->source["emitters"][0].contains("rate")) << "the exit speed says it now";
  ASSERT_FALSE(call(*s, protocol::SimStep{400}).code);
  const std::uint64_t poured = inflow();
  EXPECT_GT(poured, closed);

  protocol::EmitterSet fast;
  fast.speed = 6.0;
  r = call(*s, fast);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "rebuild");
  EXPECT_EQ(s->scene()->emitters.at(0).speed, 6.0);
  EXPECT_EQ(inflow(), poured) << "the rebuild keeps the books of what came in";
  ASSERT_FALSE(call(*s, protocol::SimStep{100}).code);
  EXPECT_GT(inflow(), poured);

  r = call(*s, protocol::ParamSet{"emitters[0].rate", 0.02});
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "in place");
  EXPECT_NEAR(s->scene()->emitters.at(0).volume_flow(), 0.02e-3, 1e-15);

  protocol::EmitterSet missing;
  missing.emitter = 3;
  EXPECT_EQ(call(*s, missing).code, ErrorCode::NotFound);
  protocol::EmitterSet narrow;
  narrow.radius = 0.001;
  r = call(*s, narrow);
  EXPECT_EQ(r.code, ErrorCode::BadField);
  EXPECT_NE(r.message.find("emitters[0].radius"), std::string::npos) << r.message;
  // A nozzle wider than the glass (issue 44: a 1 m one was acked in place, 350,722 particles came in in one
  // step and the service stopped answering) is refused, and nothing came in.
  protocol::EmitterSet wide;
  wide.radius = 1.0;
  const std::size_t before = inflow();
  r = call(*s, wide);
  EXPECT_EQ(r.code, ErrorCode::BadField);
  EXPECT_NE(r.message.find("emitters[0].radius"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("inside the domain"), std::string::npos) << r.message;
  EXPECT_NE(s->scene()->emitters.at(0).radius, 1.0);
  EXPECT_FALSE(call(*s, protocol::SimStep{1}).code);
  EXPECT_LT(inflow() - before, 100u);
}

TEST_F(SessionTest, StatsCarryTheWaterThatRanOutThroughAnOpenSide) {
  auto s = make("dam-break",
                {"spacing=0.02", "domain.walls=[\"-x\", \"-y\", \"+y\", \"-z\"]", "domain.open=[\"+x\"]"});
  const std::size_t water = initial_state(*s->scene()).particles.count(Phase::Water);
  s->start();
  const auto stats = wait_for_stats(
      *s, [](const Json& j) { return j.contains("outflow"); }, 120s);
  ASSERT_TRUE(stats->contains("outflow")) << stats->dump();
  const Json& out = (*stats)["outflow"];
  EXPECT_GT(out["particles"].get<std::size_t>(), 0u);
  EXPECT_GT(out["mass"].get<double>(), 0.0);
  EXPECT_EQ((*stats)["particles"]["water"].get<std::size_t>() + out["particles"].get<std::size_t>(), water);
}

// The same with DFSPH: water runs out through the open side with every particle accounted for, and the
// stats carry the pressure solves.
TEST_F(SessionTest, DfsphRunsLiveWithItsSolvesInTheStatsAndWaterRunsOut) {
  auto s = make("dam-break", {"spacing=0.02", "solver.pressure=dfsph",
                              "domain.walls=[\"-x\", \"-y\", \"+y\", \"-z\"]", "domain.open=[\"+x\"]"});
  const std::size_t water = initial_state(*s->scene()).particles.count(Phase::Water);
  s->start();
  const auto stats = wait_for_stats(
      *s, [](const Json& j) { return j.contains("outflow") && j.contains("dfsph"); }, 120s);
  ASSERT_TRUE(stats->contains("dfsph")) << stats->dump();
  const Json& d = (*stats)["dfsph"];
  EXPECT_GE(d["density"]["iterations"].get<int>(), 2);
  EXPECT_LE(d["density"]["error"].get<double>(), d["density"]["tolerance"].get<double>());
  EXPECT_EQ(d["unconverged_density_steps"].get<int>(), 0);
  ASSERT_TRUE(stats->contains("outflow")) << stats->dump();
  EXPECT_EQ(
      (*stats)["particles"]["water"].get<std::size_t>() + (*stats)["outflow"]["particles"].get<std::size_t>(),
      water);
}

// Free ice under DFSPH in the live service: the default scene (coarse) runs with its three free bodies,
// the stats carry the solves, and the dryer is steered in place as under WCSPH.
TEST_F(SessionTest, DfsphRunsTheDefaultSceneWithItsFreeIceLive) {
  auto s = make("default", {"spacing=0.006", "solver.pressure=dfsph"});
  s->start();
  const auto stats = wait_for_stats(
      *s, [](const Json& j) { return j.contains("dfsph") && j["steps"].get<std::uint64_t>() >= 20; }, 120s);
  ASSERT_TRUE(stats->contains("dfsph")) << stats->dump();
  EXPECT_FALSE(stats->contains("error")) << stats->dump();
  EXPECT_EQ((*stats)["dfsph"]["unconverged_density_steps"].get<int>(), 0);
  const Reply r = call(*s, protocol::ParamSet{"dryers[0].speed", 31.5});
  ASSERT_TRUE(r.answered);
  ASSERT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["applied"], "in place");
  EXPECT_EQ(s->scene()->dryers.at(0).speed, 31.5);
}

TEST_F(SessionTest, BlowUpPausesAndReportsWithoutCrashing) {
  // A block thrown down at 1 m/s under a speed limit of 1.02 m/s: gravity breaks the limit within
  // a few milliseconds of simulated time.
  auto s = make("water-drop", {"spacing=0.01", "solver.max_speed=1.02"});
  s->start();
  auto stats = wait_for_stats(*s, [](const Json& j) { return j.contains("error"); });
  ASSERT_TRUE(stats->contains("error"));
  EXPECT_TRUE((*stats)["paused"].get<bool>());
  EXPECT_FALSE((*stats)["error"].get<std::string>().empty());
  EXPECT_EQ(call(*s, protocol::SimStep{1}).code, ErrorCode::Failed);
  // Still serving commands.
  Reply r = call(*s, protocol::SimReset{});
  ASSERT_TRUE(r.answered);
  EXPECT_FALSE(r.code) << r.message;
  EXPECT_EQ(r.result["steps"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(call(*s, protocol::CameraSet{}).code, ErrorCode::Failed);  // not the session's business
}

// The (width, height) in a baseline or progressive JPEG's start-of-frame segment.
std::pair<int, int> jpeg_size(const std::string& j) {
  for (std::size_t i = 2; i + 9 < j.size();) {
    if (std::uint8_t(j[i]) != 0xFF) return {0, 0};
    const std::uint8_t marker = std::uint8_t(j[i + 1]);
    const std::size_t length = std::uint8_t(j[i + 2]) * 256u + std::uint8_t(j[i + 3]);
    if (marker == 0xC0 || marker == 0xC1 || marker == 0xC2)
      return {std::uint8_t(j[i + 7]) * 256 + std::uint8_t(j[i + 8]),
              std::uint8_t(j[i + 5]) * 256 + std::uint8_t(j[i + 6])};
    i += 2 + length;
  }
  return {0, 0};
}

class RenderWorkerTest : public testing::ClSuite {
 protected:
  TempDir dir_{"render-worker"};
};

TEST_F(RenderWorkerTest, TheCameraStaysOnTheSceneAndFramesKeepWithinThePixelBudget) {
  // camera.orbit with zoom 100, repeated, grew the distance without bound (3.5 s a frame); quality.set
  // 1920x1080 at full quality and 60 frames a second dropped everyone under 1 frame a second.
  Session s(cl(), "ice-on-plate", {"spacing=0.006"}, (dir_.path() / "states").string());
  RenderWorker w(s);
  const auto snapshot = s.latest_snapshot();
  RenderOptions framed = w.options();
  framed.distance = 0;
  const double framing = camera_for(framed, *snapshot).distance;
  ASSERT_GT(framing, 0);
  for (int i = 0; i < 30; ++i) w.orbit(0, 0, 100);
  EXPECT_LE(w.options().distance, kFarthest * framing * (1 + 1e-12));
  EXPECT_LE(camera_for(w.options(), *snapshot).distance, kFarthest * framing * (1 + 1e-12));
  for (int i = 0; i < 30; ++i) w.orbit(0, 0, 0.02);
  EXPECT_GE(w.options().distance, kClosest * framing * (1 - 1e-12));
  // camera.set takes any positive distance and any finite target; what is drawn stays bounded.
  w.set_camera(std::nullopt, std::nullopt, 1e12, Eigen::Vector3d(1e9, -1e9, 0), std::nullopt);
  const OrbitCamera far = camera_for(w.options(), *snapshot);
  EXPECT_LE(far.distance, kFarthest * framing * (1 + 1e-12));
  const double diagonal = (snapshot->domain_max - snapshot->domain_min).cast<double>().norm();
  EXPECT_LE(far.target.x(), double(snapshot->domain_max.x()) + diagonal + 1e-9);
  EXPECT_GE(far.target.y(), double(snapshot->domain_min.y()) - diagonal - 1e-9);

  // The service's frame (640x480, fast, 3/4 scale) is within the budget at the default cap; every pixel
  // at full quality is held to 13 frames a second; the largest frame to a rate the budget allows.
  w.set_quality(std::nullopt, std::nullopt, std::nullopt, std::nullopt, "fast", 0.75);
  EXPECT_EQ(w.fps_limit(), w.fps_cap());
  w.set_quality(std::nullopt, std::nullopt, std::nullopt, std::nullopt, "full", 1.0);
  EXPECT_NEAR(w.fps_limit(),
              RenderWorker::kMaxPixelsPerSecond / (640.0 * 480 * RenderWorker::kFullQualityWeight), 1e-9);
  w.set_quality(1920, 1080, 95, 60.0, "full");
  EXPECT_EQ(w.fps_cap(), 60.0);
  EXPECT_NEAR(w.fps_limit(),
              RenderWorker::kMaxPixelsPerSecond / (1920.0 * 1080 * RenderWorker::kFullQualityWeight), 1e-9);
  EXPECT_LT(w.fps_limit(), 2.0);
  // Drawn: over 3 s, hurried after every frame as 50 commands a second would, frames stay within it.
  w.set_quality(960, 540, 80, 60.0, "fast");
  const double limit = w.fps_limit();
  ASSERT_LT(limit, 60.0);
  s.start();
  w.start();
  auto first = w.wait_for_frame(0, 30s);
  if (!first && w.status().rfind("error", 0) == 0) {
    // No EGL here: the CPU particle view is drawn under the same budget.
    std::printf("surface view unavailable (%s); timing the particle view\n", w.status().c_str());
    w.set_view("particles");
    first = w.wait_for_frame(0, 30s);
  }
  ASSERT_TRUE(first) << w.status();
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t last = first->frame;
  while (std::chrono::steady_clock::now() - t0 < 3s) {
    w.hurry();
    if (auto f = w.wait_for_frame(last, 100ms)) last = f->frame;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = double(last - first->frame) / seconds;
  std::printf("[ info ] 960x540 hurried: %.1f frames/s, budget %.1f\n", rate, limit);
  EXPECT_LE(rate, limit * 1.1 + 0.5);
}

TEST_F(RenderWorkerTest, RendersNumberedJpegFramesAndPicksTheIce) {
  Session s(cl(), "ice-on-plate", {"spacing=0.006"}, (dir_.path() / "states").string());
  s.start();
  std::atomic<int> notified{0};
  RenderWorker w(s, {}, [&] { ++notified; });
  EXPECT_THROW(w.set_quality(8, std::nullopt, std::nullopt, std::nullopt, std::nullopt), Error);
  w.set_quality(160, 120, 70, 60.0, "fast");
  w.start();
  auto first = w.wait_for_frame(0, 30s);
  if (!first && w.status().rfind("error", 0) == 0) {
    // No EGL here: the worker said so and keeps running; the CPU views still give frames.
    std::printf("surface view unavailable (%s); testing the particle view\n", w.status().c_str());
    w.set_view("particles");
    first = w.wait_for_frame(0, 30s);
  }
  ASSERT_TRUE(first) << w.status();
  EXPECT_EQ(w.status().rfind("ok", 0), 0u) << w.status();
  ASSERT_GT(first->jpeg.size(), 2u);
  EXPECT_EQ(std::uint8_t(first->jpeg[0]), 0xFF);
  EXPECT_EQ(std::uint8_t(first->jpeg[1]), 0xD8);
  EXPECT_EQ(first->width, 160);
  EXPECT_EQ(first->height, 120);
  EXPECT_EQ(jpeg_size(first->jpeg), std::make_pair(160, 120));

  auto second = w.wait_for_frame(first->frame, 30s);
  ASSERT_TRUE(second);
  EXPECT_GT(second->frame, first->frame);
  EXPECT_GE(second->step, first->step);
  EXPECT_GE(notified.load(), 1);  // the first frame's callback ran before the second frame began

  // The default camera looks at the domain's centre, where the cube sits on its plate.
  auto hit = w.pick(80, 60);
  ASSERT_TRUE(hit);
  EXPECT_GT(hit->hit.x(), 0.035);
  EXPECT_LT(hit->hit.x(), 0.085);
  EXPECT_GT(hit->hit.y(), 0.035);
  EXPECT_LT(hit->hit.y(), 0.085);
  EXPECT_GT(hit->hit.z(), 0.0);
  EXPECT_LT(hit->hit.z(), 0.05);
  EXPECT_NEAR(hit->normal.norm(), 1.0, 1e-6);
  EXPECT_FALSE(w.pick(1, 1));  // a corner of the picture shows only background

  // A new size takes effect with the next frame.
  w.set_quality(96, 64, std::nullopt, std::nullopt, std::nullopt);
  w.orbit(20, 5, 0.9);
  auto resized = w.wait_for_frame(second->frame, 30s);
  for (int i = 0; i < 5 && resized && resized->width != 96; ++i)
    resized = w.wait_for_frame(resized->frame, 30s);
  ASSERT_TRUE(resized);
  EXPECT_EQ(resized->width, 96);
  EXPECT_EQ(resized->height, 64);
  EXPECT_EQ(jpeg_size(resized->jpeg), std::make_pair(96, 64));
  w.stop();
  s.stop();
}

TEST_F(RenderWorkerTest, UnwatchedDrawsOnlyItsFirstFrameAndHurrySkipsTheFpsCap) {
  Session s(cl(), "ice-on-plate", {"spacing=0.006"}, (dir_.path() / "states").string());
  s.start();
  RenderWorker w(s);
  w.set_view("particles");  // CPU-drawn: this test is about scheduling, not EGL
  w.set_quality(64, 48, std::nullopt, 60.0, std::nullopt);
  w.set_watched(false);
  w.start();
  auto first = w.wait_for_frame(0, 30s);
  ASSERT_TRUE(first) << w.status();
  EXPECT_EQ(first->frame, 1u);
  // Nobody watches: the simulation keeps publishing, but no further frame is drawn.
  const std::uint64_t seq = s.sequence();
  s.wait_for_sequence(seq + 3, 5s);
  EXPECT_GT(s.sequence(), seq);
  EXPECT_EQ(w.wait_for_frame(first->frame, 500ms)->frame, 1u);

  // Watched again, at one frame a second: after a frame, the next waits for its slot unless hurried.
  w.set_quality(std::nullopt, std::nullopt, std::nullopt, 1.0, std::nullopt);
  w.set_watched(true);
  auto next = w.wait_for_frame(first->frame, 30s);
  ASSERT_TRUE(next);
  EXPECT_EQ(w.wait_for_frame(next->frame, 300ms)->frame, next->frame);  // within its one-second slot
  auto slot = w.wait_for_frame(next->frame, 30s);  // the cap's frame comes after the slot
  ASSERT_TRUE(slot && slot->frame > next->frame);
  w.hurry();
  auto hurried = w.wait_for_frame(slot->frame, 700ms);  // well inside the one-second slot
  ASSERT_TRUE(hurried);
  EXPECT_GT(hurried->frame, slot->frame);  // (on timeout it would be the slot's frame again)
  EXPECT_GT(w.fps(), 0.0);
  w.stop();
  s.stop();
}

// While the camera moves, surface frames march at kMovingScale and say so; once it stops for
// kSettleSeconds, one frame at the chosen scale follows though the simulation is paused (no new
// snapshot asks for it), and then none.
TEST_F(RenderWorkerTest, FramesMarchAtHalfScaleWhileTheCameraMovesAndOneAtTheChosenScaleFollows) {
  Session s(cl(), "ice-on-plate", {"spacing=0.006"}, (dir_.path() / "states").string());  // not started
  RenderWorker w(s);
  EXPECT_THROW(w.set_quality(std::nullopt, std::nullopt, std::nullopt, std::nullopt, std::nullopt, 0.2),
               Error);
  w.set_quality(160, 120, 70, 60.0, "fast", 0.75);
  EXPECT_EQ(w.options().scale, 0.75);
  w.start();
  auto first = w.wait_for_frame(0, 30s);
  ASSERT_TRUE(first) << "the surface view needs EGL (as RenderTest does): " << w.status();
  EXPECT_EQ(first->scale, 0.75);
  EXPECT_FALSE(first->moving);
  EXPECT_EQ(first->width, 160);

  w.orbit(15, 0, 1);
  auto moving = w.wait_for_frame(first->frame, 30s);
  ASSERT_TRUE(moving && moving->frame > first->frame);
  EXPECT_TRUE(moving->moving);
  EXPECT_EQ(moving->scale, RenderWorker::kMovingScale);
  EXPECT_EQ(moving->width, 160) << "the frame keeps its size; only the march is smaller";
  EXPECT_EQ(jpeg_size(moving->jpeg), std::make_pair(160, 120));

  const auto stopped = std::chrono::steady_clock::now();
  auto settled = w.wait_for_frame(moving->frame, 30s);
  ASSERT_TRUE(settled && settled->frame > moving->frame);
  const double after = std::chrono::duration<double>(std::chrono::steady_clock::now() - stopped).count();
  EXPECT_FALSE(settled->moving);
  EXPECT_EQ(settled->scale, 0.75);
  EXPECT_GE(after, 0.5 * RenderWorker::kSettleSeconds);
  EXPECT_EQ(w.wait_for_frame(settled->frame, 600ms)->frame, settled->frame) << "nothing changed: no frame";

  // A chosen scale at or below kMovingScale is kept while moving.
  w.set_quality(std::nullopt, std::nullopt, std::nullopt, std::nullopt, std::nullopt, 0.25);
  auto small = w.wait_for_frame(settled->frame, 30s);
  ASSERT_TRUE(small);
  w.orbit(15, 0, 1);
  auto small_moving = w.wait_for_frame(small->frame, 30s);
  ASSERT_TRUE(small_moving && small_moving->frame > small->frame);
  EXPECT_EQ(small_moving->scale, 0.25);
  EXPECT_FALSE(small_moving->moving);
  w.stop();
}

// The mean red less blue over a JPEG frame's middle half.
double redness(const std::string& jpeg) {
  tjhandle tj = tjInitDecompress();
  int w = 0, h = 0, sub = 0, space = 0;
  const auto* bytes = reinterpret_cast<const unsigned char*>(jpeg.data());
  std::vector<unsigned char> rgb;
  if (tjDecompressHeader3(tj, bytes, static_cast<unsigned long>(jpeg.size()), &w, &h, &sub, &space) == 0) {
    rgb.resize(std::size_t(w) * h * 3);
    if (tjDecompress2(tj, bytes, static_cast<unsigned long>(jpeg.size()), rgb.data(), w, 0, h, TJPF_RGB, 0) !=
        0)
      rgb.clear();
  }
  tjDestroy(tj);
  double sum = 0;
  long n = 0;
  for (int y = h / 4; !rgb.empty() && y < h * 3 / 4; ++y)
    for (int x = w / 4; x < w * 3 / 4; ++x, ++n)
      sum += double(rgb[(std::size_t(y) * w + x) * 3]) - double(rgb[(std::size_t(y) * w + x) * 3 + 2]);
  return n ? sum / double(n) : -1e9;
}

// view.set's colouring by a substance reaches the surface view: the paused scene's next frame has its pool
// tinted by the dye, fainter against a higher reference, and back to the phases it is as it was.
TEST_F(RenderWorkerTest, ColouredByADyeTheSurfaceFrameTintsThePool) {
  Session s(cl(), "dye-in-meltwater", {}, (dir_.path() / "states").string());  // not started
  RenderWorker w(s);
  w.set_quality(160, 120, 90, 60.0, "fast", 1.0);
  w.start();
  auto plain = w.wait_for_frame(0, 30s);
  ASSERT_TRUE(plain) << "the surface view needs EGL (as RenderTest does): " << w.status();
  w.set_view("surface", "substance:dye");
  auto dyed = w.wait_for_frame(plain->frame, 30s);
  ASSERT_TRUE(dyed && dyed->frame > plain->frame) << w.status();
  // Full colour at 20 g/L, ten times the pool's: a fainter tint.
  w.set_view("surface", "substance:dye", 20.0);
  auto faint = w.wait_for_frame(dyed->frame, 30s);
  ASSERT_TRUE(faint && faint->frame > dyed->frame) << w.status();
  EXPECT_EQ(w.options().field.tint_reference, 20.0f);
  EXPECT_THROW(w.set_view("surface", "substance:dye", -1.0), Error);
  w.set_view("surface", "phase", 0.0);
  auto again = w.wait_for_frame(faint->frame, 30s);
  ASSERT_TRUE(again && again->frame > faint->frame) << w.status();
  const double r0 = redness(plain->jpeg), r1 = redness(dyed->jpeg), r2 = redness(again->jpeg),
               r3 = redness(faint->jpeg);
  std::printf(
      "[ info ] red less blue: by phase %.1f, by dye %.1f, against 20 g/L %.1f, by phase again %.1f\n", r0,
      r1, r3, r2);
  EXPECT_GT(r1, r0 + 8);
  EXPECT_GT(r1, r3 + 5);
  EXPECT_GT(r3, r0);
  EXPECT_NEAR(r2, r0, 1.0);
  w.stop();
}

TEST(ThreadPriority, LoweredForThisThreadAndInheritedByItsThreads) {
  const int before = this_thread_nice();
  int lowered = 0, child = 0;
  bool ok = false;
  std::thread([&] {
    ok = lower_this_thread_priority(3);
    lowered = this_thread_nice();
    std::thread([&] { child = this_thread_nice(); }).join();
  }).join();
  if (!ok) GTEST_SKIP() << "this system refuses to change a thread's nice value";
  EXPECT_EQ(lowered, std::min(before + 3, 19));
  EXPECT_EQ(child, lowered);              // e.g. an OpenCL CPU driver's workers started from that thread
  EXPECT_EQ(this_thread_nice(), before);  // the other threads keep theirs
}

}  // namespace
}  // namespace thaw

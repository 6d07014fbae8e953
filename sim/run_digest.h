#pragma once
// Digests of the states a thread's solvers pass through: to test that a run gives the same bits every time
// and, where it does not, to find the first step, stage and field where it parted from itself
// (docs/ARCHITECTURE.md, Determinism). While a RunDigest is installed on a thread, every Solver made on that
// thread reports to it: with Detail::Ends its whole state (the state file's bytes) when it is destroyed; with
// Detail::Steps also after each step; with Detail::Stages after each stage too, each state section on its
// own. A digest may also stop every run after some steps (a validation case's first few hundred). Nothing is
// recorded, and a solver made while none was installed pays one null-pointer test a stage.
#include <cstdint>
#include <string>
#include <vector>

namespace thaw {

struct SimState;

class RunDigest {
 public:
  enum class Detail { Ends, Steps, Stages };
  // Thrown by a solver's step once it has taken `stop_after` steps: what was recorded until then stands.
  struct Stopped {};
  struct Entry {
    std::uint32_t solver = 0;  // in the order the solvers were made while this digest was installed
    std::uint64_t step = 0;    // the solver's steps taken when it reported
    std::string stage;         // the stage just run ("step": the step's end; "end": the solver's)
    std::string section;       // a state section ("state": the whole state file)
    std::uint64_t hash = 0;    // FNV-1a-64 of its bytes
    bool operator==(const Entry&) const = default;
  };

  // Installs itself on this thread; stop_after 0: never stop.
  explicit RunDigest(Detail detail = Detail::Steps, std::uint64_t stop_after = 0);
  ~RunDigest();  // reinstates the one it replaced
  RunDigest(const RunDigest&) = delete;
  RunDigest& operator=(const RunDigest&) = delete;

  // The digest installed on this thread, or nullptr.
  static RunDigest* active();
  Detail detail() const { return detail_; }
  std::uint64_t stop_after() const { return stop_after_; }
  // A new solver's number (Solver's constructor).
  std::uint32_t solver_made() { return solvers_++; }
  // A solver's state after `stage` (with Detail::Stages), after a step (stage "step") or at its end ("end").
  void record(std::uint32_t solver, const char* stage, const SimState& state);

  const std::vector<Entry>& entries() const { return entries_; }
  // One hash over every entry, in order.
  std::uint64_t digest() const;
  // Where `other` first differs from this one ("solver 0, step 37, after heat: enthalpy differs"), or ""
  // when every entry agrees.
  std::string first_difference(const RunDigest& other) const;

 private:
  Detail detail_;
  std::uint64_t stop_after_;
  RunDigest* replaced_;
  std::uint32_t solvers_ = 0;
  std::vector<Entry> entries_;
};

}  // namespace thaw

// `thaw validate CASE`: a validation case's error against its reference, and its run time. `--all` runs every
// case at its default resolution into one table; `--twice` runs a case (or all) twice and checks that both
// runs leave the same bits (sim/run_digest.h).
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "server/cli_args.h"
#include "server/commands.h"
#include "sim/error.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

// The metric with the largest error over its gate (an error above a gate of 0 is infinitely over), and that
// ratio.
std::pair<std::string, double> worst_over_gate(const CaseResult& r) {
  std::pair<std::string, double> worst{"", 0.0};
  for (const auto& [key, m] : r.metrics) {
    const double over =
        m.gate > 0 ? m.error / m.gate : (m.error > 0 ? std::numeric_limits<double>::infinity() : 0.0);
    if (worst.first.empty() || over > worst.second) worst = {key, over};
  }
  return worst;
}

void print_result(const CaseResult& r, const ClRuntime& cl) {
  std::printf("%s at res %d: %zu particles, %llu steps, %.2f s wall on %s\n", r.name.c_str(), r.res,
              r.particles, (unsigned long long)r.steps, r.wall_s, cl.description().c_str());
  for (const auto& [key, m] : r.metrics)
    std::printf("  %-28s value %-12.6g reference %-12.6g error %-10.4g gate %-8.4g %s\n", key.c_str(),
                m.value, m.reference, m.error, m.gate, m.passed() ? "ok" : "FAILED");
  std::printf("%s\n", r.passed() ? "passed" : "FAILED");
}

// One case, or its two runs compared. A case that throws has failed, with the message as its reason.
struct Outcome {
  CaseResult result;
  std::string error;       // what the case threw
  bool twice = false;      // two runs compared: they pass by leaving the same bits, whatever their metrics
  std::string difference;  // where the second run parted from the first ("" where they agree)
  bool passed() const { return error.empty() && (twice ? difference.empty() : result.passed()); }
};

Outcome run_case(ClRuntime& cl, const std::string& name, int res, const std::vector<std::string>& sets,
                 bool twice, std::uint64_t steps) {
  Outcome o;
  o.twice = twice;
  try {
    if (!twice) {
      o.result = run_validation(cl, name, res, sets);
      return o;
    }
    Repeated r = run_validation_twice(cl, name, res, sets, steps);
    o.result = r.first;
    o.difference = r.difference;
  } catch (const std::exception& e) {  // a blow-up, a refused parameter or a device failure: that case failed
    o.error = e.what();
  }
  o.result.name = name;
  o.result.res = res > 0 ? res : find_case(name).default_res;
  return o;
}

void print_header(bool twice) {
  std::printf("%-18s %4s %9s %8s %8s  %-6s %s\n", "case", "res", "particles", "steps", "wall s", "result",
              twice ? "two runs, bit for bit" : "worst error / gate (metric)");
}

void print_row(const Outcome& o, bool twice) {
  const CaseResult& r = o.result;
  const std::string particles = r.particles ? std::to_string(r.particles) : "-";
  std::printf("%-18s %4d %9s %8llu %8.1f  %-6s ", r.name.c_str(), r.res, particles.c_str(),
              (unsigned long long)r.steps, r.wall_s, o.passed() ? "passed" : "FAILED");
  if (!o.error.empty()) {
    std::printf("%s\n", o.error.c_str());
  } else if (twice) {
    std::printf("%s\n", o.difference.empty() ? "the same" : o.difference.c_str());
  } else {
    const auto [metric, over] = worst_over_gate(r);
    std::printf("%.3g (%s)\n", over, metric.c_str());
  }
  std::fflush(stdout);
}

}  // namespace

int cmd_validate(int argc, char** argv) {
  CliArgs args(argc, argv, 2, {"--res", "--device", "--steps"}, {"--json", "--list", "--all", "--twice"});
  if (args.flag("--list")) {
    for (const auto& c : validation_cases())
      std::printf("%-18s res %-3d  %s\n", c.name.c_str(), c.default_res, c.summary.c_str());
    return 0;
  }
  const bool all = args.flag("--all"), twice = args.flag("--twice");
  if (all && !args.positional().empty()) throw Error("validate --all takes no CASE");
  if (!all && args.positional().size() != 1)
    throw Error("validate needs one CASE, or --all (see thaw validate --list)");
  if (all && args.value("--res"))
    throw Error("--res: validate --all runs each case at its default resolution");
  if (all && !args.sets().empty())
    throw Error("--set: validate --all runs each case with its default parameters");
  if (args.value("--steps") && !twice)
    throw Error("--steps: only with --twice (how far to run each case twice)");
  std::vector<std::string> names;
  if (all)
    for (const auto& c : validation_cases()) names.push_back(c.name);
  else
    names.push_back(find_case(args.positional()[0]).name);  // an unknown name fails before any device work
  const long long res = args.integer("--res", 0);
  if (args.value("--res") && res < 1) throw Error("--res: must be >= 1");
  const long long steps = args.integer("--steps", 0);
  if (steps < 0) throw Error("--steps: must be >= 0");
  ClRuntime cl(args.value("--device").value_or(""));

  // The table's rows as the cases finish (an --all run takes a while); with --json, a line each on stderr.
  const bool json = args.flag("--json"), table = !json && (all || twice);
  if (table) {
    std::printf("on %s\n", cl.description().c_str());
    print_header(twice);
  }
  std::vector<Outcome> outcomes;
  for (const std::string& name : names) {
    outcomes.push_back(run_case(cl, name, int(res), args.sets(), twice, std::uint64_t(steps)));
    if (table) print_row(outcomes.back(), twice);
    if (json && all)
      std::fprintf(stderr, "%s: %s\n", name.c_str(), outcomes.back().passed() ? "passed" : "FAILED");
  }
  bool passed = true;
  for (const Outcome& o : outcomes) passed = passed && o.passed();
  if (json) {
    Json out = Json::array();
    for (const Outcome& o : outcomes) {
      Json j = o.result.to_json();
      j["passed"] = o.passed();
      if (!o.error.empty()) j["error"] = o.error;
      if (twice) j["same_bits"] = o.difference.empty() && o.error.empty();
      if (!o.difference.empty()) j["difference"] = o.difference;
      if (!twice) j["worst_error_over_gate"] = worst_over_gate(o.result).second;
      out.push_back(j);
    }
    std::printf("%s\n", (all ? out : out[0]).dump(2).c_str());
  } else if (table) {
    std::printf("%s\n", passed ? "passed" : "FAILED");
  } else {
    if (!outcomes[0].error.empty()) throw Error(outcomes[0].error);
    print_result(outcomes[0].result, cl);
  }
  return passed ? 0 : 1;
}

}  // namespace thaw

// `thaw validate CASE`: a validation case's error against its reference, and its run time.
#include <cstdio>

#include "server/cli_args.h"
#include "server/commands.h"
#include "sim/error.h"
#include "sim/validation/case.h"

namespace thaw {

int cmd_validate(int argc, char** argv) {
  CliArgs args(argc, argv, 2, {"--res", "--device"}, {"--json", "--list"});
  if (args.flag("--list")) {
    for (const auto& c : validation_cases())
      std::printf("%-12s res %-3d  %s\n", c.name.c_str(), c.default_res, c.summary.c_str());
    return 0;
  }
  if (args.positional().size() != 1) throw Error("validate needs one CASE (see thaw validate --list)");
  const auto& name = args.positional()[0];
  find_case(name);  // an unknown name fails before any device work
  const long long res = args.integer("--res", 0);
  if (args.value("--res") && res < 1) throw Error("--res: must be >= 1");
  ClRuntime cl(args.value("--device").value_or(""));
  const CaseResult r = run_validation(cl, name, static_cast<int>(res), args.sets());
  if (args.flag("--json")) {
    std::printf("%s\n", r.to_json().dump(2).c_str());
  } else {
    std::printf("%s at res %d: %zu particles, %llu steps, %.2f s wall on %s\n", r.name.c_str(), r.res,
                r.particles, (unsigned long long)r.steps, r.wall_s, cl.description().c_str());
    for (const auto& [key, m] : r.metrics)
      std::printf("  %-28s value %-12.6g reference %-12.6g error %-10.4g gate %-8.4g %s\n", key.c_str(),
                  m.value, m.reference, m.error, m.gate, m.passed() ? "ok" : "FAILED");
    std::printf("%s\n", r.passed() ? "passed" : "FAILED");
  }
  return r.passed() ? 0 : 1;
}

}  // namespace thaw

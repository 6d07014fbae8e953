#include "bench/accuracy.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "sim/error.h"
#include "sim/validation/case.h"

namespace thaw {

Json bench_accuracy(ClRuntime& cl, const AccuracyOptions& o, bool print) {
  find_case(o.case_name);
  std::filesystem::create_directories(o.out_dir);
  const std::string base = o.out_dir + "/" + o.case_name + "-accuracy";
  Json rows = Json::array();
  std::ofstream csv(base + ".csv");
  if (!csv) throw Error("cannot write " + base + ".csv");
  csv << "case,res,particles,steps,wall_s,metric,value,reference,error,gate\n";
  for (int res : o.resolutions) {
    const CaseResult r = run_validation(cl, o.case_name, res, o.overrides);
    rows.push_back(r.to_json());
    for (const auto& [key, m] : r.metrics)
      csv << r.name << ',' << r.res << ',' << r.particles << ',' << r.steps << ',' << r.wall_s << ",\"" << key
          << "\"," << m.value << ',' << m.reference << ',' << m.error << ',' << m.gate << '\n';
    csv.flush();
    if (print) {
      double worst = 0;
      for (const auto& [key, m] : r.metrics) worst = std::max(worst, m.error / m.gate);
      std::printf("%s res %3d: %8zu particles %7llu steps %9.2f s wall, worst error/gate %.3f %s\n", r.name.c_str(),
                  r.res, r.particles, (unsigned long long)r.steps, r.wall_s, worst, r.passed() ? "passed" : "FAILED");
      std::fflush(stdout);
    }
  }
  Json out = {{"case", o.case_name}, {"device", cl.description()}, {"runs", rows}};
  std::ofstream(base + ".json") << out.dump(2) << '\n';
  const std::string script = std::string(THAW_SOURCE_DIR) + "/tools/plot_accuracy.py";
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + base + ".csv' '" + base + ".png'";
  const bool plotted = std::filesystem::exists(script) && std::system(cmd.c_str()) == 0;
  if (print)
    std::printf("wrote %s.json, %s.csv%s\n", base.c_str(), base.c_str(),
                plotted ? (", " + base + ".png").c_str() : " (no plot: needs /usr/bin/python3 with matplotlib)");
  out["plot"] = plotted ? base + ".png" : "";
  return out;
}

}  // namespace thaw

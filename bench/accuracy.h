#pragma once
// Accuracy against run time: a validation case at several resolutions, as a table (JSON and CSV) and a
// PNG plot of error against wall time (tools/plot_accuracy.py, Debian's python3-matplotlib).
#include <string>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/scene.h"

namespace thaw {

struct AccuracyOptions {
  std::string case_name;
  std::vector<int> resolutions = {10, 15, 20, 30};
  std::string out_dir = "bench-results";
  std::vector<std::string> overrides;
};

Json bench_accuracy(ClRuntime& cl, const AccuracyOptions& o, bool print);

}  // namespace thaw

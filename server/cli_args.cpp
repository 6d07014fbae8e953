#include "server/cli_args.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "sim/error.h"

namespace thaw {

CliArgs::CliArgs(int argc, char** argv, int first, const std::vector<std::string>& with_value,
                 const std::vector<std::string>& flags) {
  auto known = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.size() < 2 || a.rfind("--", 0) != 0) {
      positional_.push_back(a);
      continue;
    }
    std::string val;
    bool has_val = false;
    if (auto eq = a.find('='); eq != std::string::npos && a != "--set") {
      val = a.substr(eq + 1);
      a = a.substr(0, eq);
      has_val = true;
    }
    if (a == "--set" || known(with_value, a)) {
      if (!has_val) {
        if (i + 1 >= argc) throw Error(a + " needs a value");
        val = argv[++i];
      }
      if (a == "--set")
        sets_.push_back(val);
      else
        values_[a] = val;
    } else if (known(flags, a)) {
      flags_[a] = true;
    } else {
      std::string list = "--set";
      for (const auto& o : with_value) list += ", " + o;
      for (const auto& o : flags) list += ", " + o;
      throw Error("unknown option " + a + " (known here: " + list + ")");
    }
  }
}

std::optional<std::string> CliArgs::value(const std::string& option) const {
  auto it = values_.find(option);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

double CliArgs::number(const std::string& option, double fallback) const {
  auto v = value(option);
  if (!v) return fallback;
  char* end = nullptr;
  const double d = std::strtod(v->c_str(), &end);
  if (end == v->c_str() || *end != '\0' || !std::isfinite(d))
    throw Error(option + ": expected a number, got '" + *v + "'");
  return d;
}

long long CliArgs::integer(const std::string& option, long long fallback) const {
  auto v = value(option);
  if (!v) return fallback;
  char* end = nullptr;
  const long long d = std::strtoll(v->c_str(), &end, 10);
  if (end == v->c_str() || *end != '\0') throw Error(option + ": expected a whole number, got '" + *v + "'");
  return d;
}

}  // namespace thaw

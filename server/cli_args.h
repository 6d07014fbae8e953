#pragma once
// Command-line arguments of one subcommand: positionals, options with values, repeatable --set, flags.
// Unknown options are errors that name the option and list the known ones.
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace thaw {

class CliArgs {
 public:
  // `with_value`: options taking a value ("--until"); `flags`: options without one ("--json").
  CliArgs(int argc, char** argv, int first, const std::vector<std::string>& with_value,
          const std::vector<std::string>& flags);

  const std::vector<std::string>& positional() const { return positional_; }
  std::optional<std::string> value(const std::string& option) const;
  bool flag(const std::string& option) const { return flags_.count(option) > 0; }
  const std::vector<std::string>& sets() const { return sets_; }  // every --set, in order

  double number(const std::string& option, double fallback) const;
  long long integer(const std::string& option, long long fallback) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
  std::map<std::string, bool> flags_;
  std::vector<std::string> sets_;
};

}  // namespace thaw

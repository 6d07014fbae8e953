#include "sim/run_digest.h"

#include <sstream>
#include <string_view>

#include "sim/state_file.h"

namespace thaw {
namespace {
thread_local RunDigest* installed = nullptr;
}

RunDigest::RunDigest(Detail detail, std::uint64_t stop_after)
    : detail_(detail), stop_after_(stop_after), replaced_(installed) {
  installed = this;
}

RunDigest::~RunDigest() { installed = replaced_; }

RunDigest* RunDigest::active() { return installed; }

void RunDigest::record(std::uint32_t solver, const char* stage, const SimState& state) {
  if (detail_ != Detail::Stages || std::string_view(stage) == "end") {
    entries_.push_back({solver, state.step, stage, "state", fnv1a64(encode_state(state))});
    return;
  }
  for_each_state_section(state, [&](const std::string& section, std::string_view bytes) {
    entries_.push_back({solver, state.step, stage, section, fnv1a64(bytes)});
  });
}

std::uint64_t RunDigest::digest() const {
  std::uint64_t h = fnv1a64("");
  for (const Entry& e : entries_) {
    std::ostringstream os;
    os << e.solver << ' ' << e.step << ' ' << e.stage << ' ' << e.section << ' ' << e.hash << '\n';
    h = fnv1a64(os.str(), h);
  }
  return h;
}

std::string RunDigest::first_difference(const RunDigest& other) const {
  const std::size_t n = std::min(entries_.size(), other.entries_.size());
  for (std::size_t k = 0; k < n; ++k) {
    const Entry &a = entries_[k], &b = other.entries_[k];
    if (a == b) continue;
    std::ostringstream os;
    os << "solver " << a.solver << ", step " << a.step << ", after " << a.stage << ": ";
    if (a.section != b.section || a.solver != b.solver || a.step != b.step || a.stage != b.stage)
      os << "the runs took different paths (here " << a.section << ", there solver " << b.solver << ", step "
         << b.step << ", after " << b.stage << ", " << b.section << ")";
    else
      os << a.section << " differs";
    return os.str();
  }
  if (entries_.size() != other.entries_.size()) {
    std::ostringstream os;
    os << "one run reported " << entries_.size() << " digests, the other " << other.entries_.size()
       << " (the same until then)";
    return os.str();
  }
  return "";
}

}  // namespace thaw

#include "server/progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace thaw {
namespace {

// Redrawing more often than this costs terminal time and is unreadable anyway.
constexpr auto kTerminalInterval = std::chrono::milliseconds(100);
// Logs get a line this often: enough to see a run is alive, few enough to keep CI logs short.
constexpr auto kLogInterval = std::chrono::seconds(5);
// Rates are measured over windows at least this long, then smoothed with this time constant.
constexpr double kRateWindowS = 0.25;
constexpr double kRateSmoothingS = 3.0;
constexpr int kMinBarWidth = 10;

double seconds(Progress::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// "--:--" when unknown, "m:ss" below an hour, "h:mm:ss" above.
std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0.0) return "--:--";
  const long long total = std::llround(s);
  const long long h = total / 3600, m = total / 60 % 60, sec = total % 60;
  char buf[32];
  if (h > 0) {
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", h, m, sec);
  } else {
    std::snprintf(buf, sizeof buf, "%lld:%02lld", m, sec);
  }
  return buf;
}

// Wall time of a whole run: seconds with a decimal for short runs, a clock form for long ones.
std::string format_elapsed(double s) {
  if (s < 60.0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f s", s);
    return buf;
  }
  return format_duration(s);
}

std::string format_rate(double rate) {
  char buf[32];
  std::snprintf(buf, sizeof buf, rate >= 100.0 ? "%.0f" : rate >= 10.0 ? "%.1f" : "%.2f", rate);
  return buf;
}

// A terminal that can take "\r" and the erase-line escape; TERM=dumb (e.g. editor shells) cannot.
bool is_capable_terminal(std::FILE* f) {
  if (!isatty(fileno(f))) return false;
  const char* term = std::getenv("TERM");
  return term == nullptr || std::strcmp(term, "dumb") != 0;
}

int terminal_columns(std::FILE* f) {
  winsize ws{};
  if (ioctl(fileno(f), TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
  if (const char* env = std::getenv("COLUMNS")) {
    const int c = std::atoi(env);
    if (c > 0) return c;
  }
  return 80;
}

}  // namespace

Progress::Progress(double target, const char* unit, bool enabled)
    : Progress(target, unit, stderr, is_capable_terminal(stderr)) {
  enabled_ = enabled;
}

Progress::Progress(double target, const char* unit, std::FILE* out, bool terminal)
    : target_(target), unit_(unit), out_(out), enabled_(true), terminal_(terminal) {
  if (terminal_) columns_ = terminal_columns(out_);
  start_ = Clock::now();
  last_draw_ = start_;
  rate_time_ = start_;
}

Progress::~Progress() {
  // A plain newline, not finish(): an interrupted run must not be reported as done.
  if (line_open_) std::fputc('\n', out_);
}

void Progress::update(double done, std::uint64_t steps) {
  if (!enabled_ || finished_) return;
  const auto now = Clock::now();
  done_ = done;
  steps_ = steps;
  sample(now, done, steps);
  if (terminal_) {
    if (drawn_ && now - last_draw_ < kTerminalInterval) return;
    draw_terminal(status_text(steps_per_s_, false, true), target_ > 0.0 ? done / target_ : 0.0);
  } else {
    if (now - last_draw_ < kLogInterval) return;
    print_log_line(status_text(steps_per_s_, false, false));
  }
  last_draw_ = now;
}

void Progress::finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  end_ = Clock::now();
  const double elapsed = seconds(end_ - start_);
  const double average = elapsed > 0.0 ? static_cast<double>(steps_) / elapsed : 0.0;
  if (terminal_) {
    draw_terminal(status_text(average, true, true), target_ > 0.0 ? done_ / target_ : 1.0);
    std::fputc('\n', out_);
    line_open_ = false;
  } else if (drawn_) {
    // Short runs print no progress at all in logs; the run's own summary says enough for them.
    print_log_line(status_text(average, true, false));
  }
  std::fflush(out_);
}

void Progress::sample(Clock::time_point now, double done, std::uint64_t steps) {
  const double dt = seconds(now - rate_time_);
  if (dt < kRateWindowS) return;
  const double steps_rate = steps >= rate_steps_at_ ? static_cast<double>(steps - rate_steps_at_) / dt : 0.0;
  const double done_rate = (done - rate_done_at_) / dt;
  if (have_rate_) {
    const double a = 1.0 - std::exp(-dt / kRateSmoothingS);
    steps_per_s_ += a * (steps_rate - steps_per_s_);
    done_per_s_ += a * (done_rate - done_per_s_);
  } else {
    steps_per_s_ = steps_rate;
    done_per_s_ = done_rate;
    have_rate_ = true;
  }
  rate_time_ = now;
  rate_done_at_ = done;
  rate_steps_at_ = steps;
}

std::string Progress::status_text(double rate, bool final, bool compact) const {
  char buf[128];
  if (unit_ != "s") {
    std::snprintf(buf, sizeof buf, "%.0f / %.0f %s", done_, target_, unit_.c_str());
  } else if (compact) {
    std::snprintf(buf, sizeof buf, "t=%.3f/%.3f s", done_, target_);
  } else {
    std::snprintf(buf, sizeof buf, "t=%.3f s / %.3f s  step %llu", done_, target_,
                  static_cast<unsigned long long>(steps_));
  }
  std::string text = buf;
  text.append("  ").append(have_rate_ || final ? format_rate(rate) : "-").append(" steps/s");
  if (final) return text.append("  took ").append(format_elapsed(seconds(end_ - start_)));
  const double eta = have_rate_ && done_per_s_ > 0.0 ? (target_ - done_) / done_per_s_ : -1.0;
  return text.append("  ETA ").append(format_duration(eta));
}

void Progress::draw_terminal(const std::string& text, double fraction) {
  fraction = std::clamp(std::isfinite(fraction) ? fraction : 0.0, 0.0, 1.0);
  char pct[8];
  // Floor, so that 100 % appears only when the run has really reached its target.
  std::snprintf(pct, sizeof pct, "%3d%%", static_cast<int>(std::floor(fraction * 100.0)));

  // The line must not wrap (a wrapped line cannot be redrawn with "\r"): leave the last column free,
  // shrink or drop the bar first, then cut the text.
  const int room = columns_ - 1;
  const int fixed = static_cast<int>(std::strlen(pct) + 2 + text.size());
  // The bar only ever shrinks, so that it does not jitter as the numbers beside it change length.
  // The first line leaves room for the rate that is not known yet and for numbers gaining digits.
  const int slack = drawn_ ? 0 : 12;
  bar_width_ = std::min(bar_width_, room - fixed - 3 - slack);
  if (bar_width_ < kMinBarWidth) bar_width_ = 0;
  std::string line;
  if (bar_width_ > 0) {
    const int filled = static_cast<int>(fraction * bar_width_);
    line.append("[")
        .append(static_cast<std::size_t>(filled), '#')
        .append(static_cast<std::size_t>(bar_width_ - filled), '.')
        .append("] ");
  }
  line += pct;
  line += "  ";
  line += text;
  if (room > 0 && line.size() > static_cast<std::size_t>(room)) line.resize(static_cast<std::size_t>(room));

  // "\x1b[K" erases what a longer previous line left behind.
  std::fprintf(out_, "\r%s\x1b[K", line.c_str());
  std::fflush(out_);
  drawn_ = true;
  line_open_ = true;
}

void Progress::print_log_line(const std::string& text) {
  std::fprintf(out_, "%s\n", text.c_str());
  std::fflush(out_);
  drawn_ = true;
}

}  // namespace thaw

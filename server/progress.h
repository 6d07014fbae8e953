#pragma once
// Progress of a long run on stderr. On a terminal: one line redrawn in place (bar, percent, done /
// target, steps per second, ETA). In a log (CI, a pipe): a plain line every few seconds, so logs stay
// short and readable. Not thread-safe: one thread (the one stepping the simulation) owns it.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace thaw {

class Progress {
 public:
  using Clock = std::chrono::steady_clock;

  // target: where the run ends, in `unit`: "s" for simulated seconds, otherwise a count of what `unit`
  // names ("steps", "frames").
  // Writes to stderr and picks the terminal or the log form by isatty(stderr); disabled, it prints nothing.
  Progress(double target, const char* unit, bool enabled = true);
  // The same with the stream and the form given, for tests and for callers that redirect output.
  Progress(double target, const char* unit, std::FILE* out, bool terminal);
  // Ends an unfinished terminal line, so that an error printed while unwinding starts on its own line.
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // done: simulated time or steps so far (whichever `unit` names); steps: steps taken so far.
  // Cheap enough to call every step: it draws only when the last drawing is old enough.
  void update(double done, std::uint64_t steps);
  // Draws the final state with the average rate and total wall time; ends the terminal line.
  void finish();

 private:
  void sample(Clock::time_point now, double done, std::uint64_t steps);
  // compact: the terminal form, which must fit one line beside the bar.
  std::string status_text(double rate, bool final, bool compact) const;
  void draw_terminal(const std::string& text, double fraction);
  void print_log_line(const std::string& text);

  double target_;
  std::string unit_;
  std::FILE* out_;
  bool enabled_;
  bool terminal_;
  int columns_ = 80;
  int bar_width_ = 30;

  Clock::time_point start_;
  Clock::time_point last_draw_;
  Clock::time_point end_;
  bool drawn_ = false;      // something was printed (a log line, or the terminal line)
  bool line_open_ = false;  // the terminal line has no newline yet
  bool finished_ = false;

  double done_ = 0.0;
  std::uint64_t steps_ = 0;
  // Rates smoothed over the last few seconds: the adaptive time step and the warm-up (kernel builds)
  // make the rate since the start a poor guide to the time left.
  Clock::time_point rate_time_;
  double rate_done_at_ = 0.0;
  std::uint64_t rate_steps_at_ = 0;
  double steps_per_s_ = 0.0;
  double done_per_s_ = 0.0;
  bool have_rate_ = false;
};

}  // namespace thaw

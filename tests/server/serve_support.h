#pragma once
// Running `thaw serve` from a test: started in the background on a free loopback port (bounded by a
// timeout), its port read from its first line, Python clients run against it, SIGINT at the end.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "tests/test_support.h"

namespace thaw::testing {

class ServedScene {
 public:
  // Starts `thaw serve ARGS --port 0` in `dir`; port() is 0 when it did not come up within a minute.
  ServedScene(const TempDir& dir, const std::string& args) : dir_(dir) {
    const std::string start = "cd " + shell_quote(dir.path().string()) + " && (timeout 600 " +
                              shell_quote(THAW_BINARY) + " serve " + args +
                              " --port 0 >serve.log 2>&1 & echo $! >serve.pid)";
    if (std::system(start.c_str()) != 0) return;
    for (int i = 0; i < 600 && port_ == 0; ++i) {
      const std::string log = read_file_bytes(dir.path() / "serve.log");
      const auto at = log.find("127.0.0.1:");
      if (at != std::string::npos) port_ = std::stoi(log.substr(at + 10));
      else std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  ~ServedScene() { stop(); }

  int port() const { return port_; }
  std::string log() const { return read_file_bytes(dir_.path() / "serve.log"); }
  // The process id of the timeout wrapper, and of the server itself (its child).
  std::string pid() const {
    const std::string wrapper = read_file_bytes(dir_.path() / "serve.pid");
    return wrapper.substr(0, wrapper.find('\n'));
  }
  std::string server_pid() const {
    const std::string out = (dir_.path() / "server.pid").string();
    std::system(("pgrep -P " + pid() + " >" + shell_quote(out)).c_str());
    const std::string child = read_file_bytes(out);
    return child.substr(0, child.find('\n'));
  }

  // Runs `script` (Python, with tools/ on the path and PORT defined) and returns its output.
  std::string run_python(const std::string& script, int timeout_s, int* status = nullptr) const {
    write_text(dir_.path() / "client.py", "import sys\nsys.path.insert(0, " +
                                              shell_quote(std::string(THAW_SOURCE_DIR) + "/tools") +
                                              ")\nPORT = " + std::to_string(port_) + "\n" + script);
    const std::string cmd = "cd " + shell_quote(dir_.path().string()) + " && timeout " + std::to_string(timeout_s) +
                            " /usr/bin/python3 client.py >client.log 2>&1";
    const int s = std::system(cmd.c_str());
    if (status) *status = s;
    return read_file_bytes(dir_.path() / "client.log");
  }

  // SIGINT, then waits up to 10 s for "stopped" in the log; true when the server said so.
  bool stop() {
    if (stopped_ || port_ == 0) return stopped_;
    const std::string p = pid();
    std::system(("kill -INT " + p + " 2>/dev/null; pkill -INT -P " + p + " 2>/dev/null").c_str());
    for (int i = 0; i < 100 && !stopped_; ++i) {
      stopped_ = log().find("thaw serve: stopped") != std::string::npos;
      if (!stopped_) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return stopped_;
  }

 private:
  const TempDir& dir_;
  int port_ = 0;
  bool stopped_ = false;
};

}  // namespace thaw::testing

#include "server/thread_priority.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

namespace thaw {
namespace {

id_t this_thread_id() { return static_cast<id_t>(syscall(SYS_gettid)); }

}  // namespace

int this_thread_nice() {
  errno = 0;
  return getpriority(PRIO_PROCESS, this_thread_id());
}

bool lower_this_thread_priority(int steps) {
  if (steps <= 0) return true;
  const int now = this_thread_nice();
  return setpriority(PRIO_PROCESS, this_thread_id(), now + steps) == 0;
}

}  // namespace thaw

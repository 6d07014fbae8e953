// Scheduling priority of the calling thread: the service lets frames go ahead of simulation steps.
#pragma once

namespace thaw {

// Raises the calling thread's nice value by `steps` (Linux: nice is per thread, and threads it creates
// inherit it, e.g. an OpenCL CPU driver's workers). Lowering a priority needs no privilege. Returns
// false, changing nothing, where the system refuses.
bool lower_this_thread_priority(int steps);

// The calling thread's nice value.
int this_thread_nice();

}  // namespace thaw

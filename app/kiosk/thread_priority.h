// Lowering a worker thread's priority, so that the screen and the watchdog come first when the cores are busy.
#pragma once

namespace avatarbooth {

// Adds `niceness` to the calling thread's nice value (Linux keeps one per thread; threads it starts inherit it).
// Best effort: without it the booth still works, only its frame rate suffers under load.
void lowerThisThreadsPriority(int niceness);

}  // namespace avatarbooth

// The real monotonic clock.
#include "drivers/gpio/clock.h"

#include <thread>

namespace avatarbooth {

void SteadyClock::sleepUntil(SteadyTime t) { std::this_thread::sleep_until(t); }

}  // namespace avatarbooth

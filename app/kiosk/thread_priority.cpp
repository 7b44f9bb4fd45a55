// Lowering a worker thread's priority (see thread_priority.h).
#include "kiosk/thread_priority.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>

#include <sys/resource.h>
#include <unistd.h>

namespace avatarbooth {

void lowerThisThreadsPriority(int niceness) {
    if (niceness == 0) return;
    errno = 0;
    const int now = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
    if (errno != 0 || setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), now + niceness) != 0)
        spdlog::debug("this thread keeps its priority: {}", std::strerror(errno));
}

}  // namespace avatarbooth

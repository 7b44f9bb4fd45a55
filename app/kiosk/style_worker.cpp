// The reveal styles' worker (see style_worker.h).
#include "kiosk/style_worker.h"

namespace avatarbooth {

// (Niced: the drawing may take a second; the screen and the watchdog must not wait for it.)
StyleWorker::StyleWorker(KioskQueue& queue, int niceness)
    : queue_(queue),
      post_([this](std::function<void()> onScreenThread) { queue_.post(StyleWorkEnded{std::move(onScreenThread)}); }),
      thread_([this](StyleWork& work) { work(post_); }, niceness) {}

}  // namespace avatarbooth

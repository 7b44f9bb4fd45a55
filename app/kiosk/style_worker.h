// Runs the reveal styles' work for a visitor (drawing the toon) on its own thread, and posts what each piece of
// work hands back to the kiosk's queue, to be run on the main loop.
#pragma once

#include "kiosk/kiosk_messages.h"
#include "kiosk/worker_thread.h"
#include "reveal/styles/reveal_style.h"

#include <vector>

namespace avatarbooth {

class StyleWorker {
public:
    explicit StyleWorker(KioskQueue& queue, int niceness = 5);

    // A new visitor's work: what is queued for an earlier visitor and not started yet is dropped.
    void submit(std::vector<StyleWork> work) { thread_.replaceQueued(std::move(work)); }

private:
    KioskQueue& queue_;
    StylePost post_;
    WorkerThread<StyleWork> thread_;  // last: starts once everything above exists
};

}  // namespace avatarbooth

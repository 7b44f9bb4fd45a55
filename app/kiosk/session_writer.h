// Writes the visitor's session folder (booth/session_folder.h) on a background thread, so that the reveal starts
// as soon as the fit has a mesh and a texture instead of after the ~1 s of writing; posts FolderEnded when done.
#pragma once

#include "booth/session_lifecycle.h"
#include "kiosk/kiosk_messages.h"
#include "kiosk/worker_thread.h"

namespace avatarbooth {

class SessionWriter {
public:
    // Its renderer (for the previews) is made on the writing thread (EGL contexts belong to a thread) for each job.
    SessionWriter(int previewSize, KioskQueue& queue, int niceness = 5);

    void submit(session::WriteFolder job) { thread_.submit(std::move(job)); }
    // Blocks until nothing is queued or being written (its FolderEnded messages are posted by then).
    void waitIdle() { thread_.waitIdle(); }

private:
    void write(session::WriteFolder& job);

    int previewSize_;
    KioskQueue& queue_;
    WorkerThread<session::WriteFolder> thread_;  // last: starts once everything above exists
};

}  // namespace avatarbooth

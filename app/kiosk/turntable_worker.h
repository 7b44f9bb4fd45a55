// Makes the visitor's turntable picture (turntable.webp: the avatar turning once, an animated WebP the visitor's
// page offers) for each kept session, on a thread of its own at low priority after the keep, so that neither the
// keep nor the thanks screen's QR code waits for it; posts TurntableEnded. Only when the visitor's page is on.
#pragma once

#include "kiosk/kiosk_messages.h"
#include "kiosk/worker_thread.h"

#include <filesystem>

namespace avatarbooth {

// What the turntable is made of: 36 frames of 320 x 320 (10 degrees a frame, a turn in 2.9 s): 0.5 MB at most for
// the visitor's phone to fetch over the booth's Wi-Fi.
struct TurntableSpec {
    int size = 320;
    int frames = 36;
    int frameMs = 80;
    float quality = 70.0f;
};

// Renders and encodes the turntable of the kept session in `keptFolder` (from its avatar.glb) into
// keptFolder/turntable.webp, atomically. Throws BoothError (BadInput when the folder has no avatar).
TurntableEnded makeTurntable(const std::filesystem::path& keptFolder, const TurntableSpec& spec = {});

class TurntableWorker {
public:
    explicit TurntableWorker(KioskQueue& queue, int niceness = 10);
    void submit(std::filesystem::path keptFolder) { thread_.submit(std::move(keptFolder)); }
    void waitIdle() { thread_.waitIdle(); }

private:
    KioskQueue& queue_;
    WorkerThread<std::filesystem::path> thread_;  // last: starts once everything above exists
};

}  // namespace avatarbooth

// Screenshots of every screen (see screenshots.h).
#include "kiosk/screenshots.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"

#include <spdlog/spdlog.h>

#include <cstdio>

namespace avatarbooth {
namespace fs = std::filesystem;

Screenshots::Screenshots(fs::path dir) : dir_(std::move(dir)), due_(!dir_.empty()) {
    if (!dir_.empty()) fs::create_directories(dir_);
}

void Screenshots::frame(const ScreenModel& screen, const cv::Mat& drawn, bool complete, bool everything) {
    if (dir_.empty()) return;
    // A new screen, or another page of the operator menu, gets its own picture.
    if (screen.id != lastScreen_ || (screen.id == ScreenId::OperatorMenu && screen.menuPage != lastMenuPage_)) {
        if (due_ && !lastDrawn_.empty() && lastModel_.sinceEntered >= kSeenFor) write(next_++, lastModel_, lastDrawn_, false);
        lastMenuPage_ = screen.menuPage;
        due_ = true;
        provisional_ = -1;
    }
    lastScreen_ = screen.id;
    if (provisional_ >= 0 && everything) {
        write(provisional_, screen, drawn, true);
        provisional_ = -1;
    }
    if (due_ && complete) {
        if (!everything) provisional_ = next_;
        write(next_++, screen, drawn, false);
        due_ = false;
    }
    if (due_) {
        drawn.copyTo(lastDrawn_);
        lastModel_ = screen;
    } else {
        lastDrawn_.release();
    }
}

// replace: the screen's picture again, over the one written before under this index.
void Screenshots::write(int index, const ScreenModel& screen, const cv::Mat& drawn, bool replace) {
    const char* page = "";
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage == OperatorPage::LastCodes) page = "_last_codes";
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage == OperatorPage::FreeDisk) page = "_free_disk";
    char name[80];
    std::snprintf(name, sizeof name, "%02d_%s%s.png", index, toString(screen.id), page);
    const fs::path path = dir_ / name;
    try {
        writeFileAtomically(path, encodeImage(drawn, ".png"));
        if (!replace) written_.push_back(path);
    } catch (const BoothError& e) {
        spdlog::warn("screenshot not written: {}", e.what());
    }
}

}  // namespace avatarbooth

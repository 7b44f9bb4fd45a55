// A PNG of every screen the visitor saw (`avatarbooth run --screenshots DIR`), each taken once the screen shows
// what it is for: the preview on a guide, every style on the reveal, the code on the thanks screen.
#pragma once

#include "booth/flow_types.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <vector>

namespace avatarbooth {

class Screenshots {
public:
    // Nothing is written when `dir` is empty.
    explicit Screenshots(std::filesystem::path dir);

    // Called every frame with the screen drawn. `complete`: the screen has what it is pictured for; `everything`:
    // it also has what may come later (a guide's first hint, the toon): a picture taken without it is taken again,
    // under the same name, once it has. A screen the visitor left before it was complete (a keep pressed while a
    // style was still being made, on a busy machine) is pictured as it was last drawn when it was shown for
    // kSeenFor at least: a screen passed through in a moment (a countdown cut short by a lost camera) is not one
    // the visitor saw.
    void frame(const ScreenModel& screen, const cv::Mat& drawn, bool complete, bool everything);
    static constexpr Millis kSeenFor{700};
    const std::vector<std::filesystem::path>& written() const { return written_; }

private:
    void write(int index, const ScreenModel& screen, const cv::Mat& drawn, bool replace);

    std::filesystem::path dir_;
    std::vector<std::filesystem::path> written_;
    bool due_;
    int next_ = 0;
    int provisional_ = -1;  // the index of a picture to take again
    cv::Mat lastDrawn_;     // the screen due for its picture as last drawn (a copy: the caller draws into one image)
    ScreenModel lastModel_;
    ScreenId lastScreen_ = ScreenId::Attract;
    OperatorPage lastMenuPage_ = OperatorPage::Menu;
};

}  // namespace avatarbooth

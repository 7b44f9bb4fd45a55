// The camera description's one-line summary.
#include "drivers/camera/camera.h"

#include <sstream>

namespace avatarbooth {

namespace {

std::string formatText(const CameraStreamFormat& f) {
    std::ostringstream out;
    out << f.pixelFormat << " " << f.width << "x" << f.height;
    if (f.fps > 0) out << " @" << f.fps << " fps";
    return out.str();
}

}  // namespace

std::string CameraDescription::summary() const {
    std::string s = backend + " " + device;
    if (!name.empty()) s += " (" + name + ")";
    s += ": preview " + formatText(preview) + ", still " + formatText(still);
    if (!note.empty()) s += "; " + note;
    return s;
}

}  // namespace avatarbooth

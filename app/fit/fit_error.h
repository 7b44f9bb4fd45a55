// A fit that failed: a BoothError that also says, as fields, which photo is at fault and why, so that a booth asks
// for the right photo again without reading the message.
#pragma once

#include "common/error.h"

#include <string>

namespace avatarbooth {

// The photo a failure is about (the one to take again). Both: the photos disagree with each other, or the failure
// is about neither in particular.
enum class FitPhoto { Front, Side, Both };

// What went wrong, in the terms a visitor is told.
enum class FitFault {
    NoFace,      // no face or head found where one was looked for
    NotProfile,  // the side photo shows a front view
    TurnMore,    // the side photo is turned, but not far enough for a profile
    TurnBack,    // the side photo is turned past the profile (more of the back of the head shows)
    FaceHidden,  // no face shows on the side photo: turned well past the profile, or hair hides the face
    Mismatch,    // the two photos do not show the same head the same way
    Other,       // anything else (an unreadable file, an internal failure)
};

constexpr FitFault faultOf(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::NoFace: return FitFault::NoFace;
        case ErrorKind::Mismatch: return FitFault::Mismatch;
        default: return FitFault::Other;
    }
}

class FitError : public BoothError {
public:
    FitError(ErrorKind kind, FitPhoto photo, FitFault fault, std::string where, const std::string& what)
        : BoothError(kind, std::move(where), what), photo_(photo), fault_(fault) {}
    // `e`, raised about `photo`, named `where` when it names no file itself.
    FitError(const BoothError& e, FitPhoto photo, const std::string& where)
        : FitError(e.kind(), photo, faultOf(e.kind()), e.where().empty() ? where : e.where(), e.message()) {}
    // `e` again, named `where` when it names no file itself.
    FitError(const FitError& e, const std::string& where)
        : FitError(e.kind(), e.photo(), e.fault(), e.where().empty() ? where : e.where(), e.message()) {}
    FitError(const FitError&) = default;

    FitPhoto photo() const { return photo_; }
    FitFault fault() const { return fault_; }

private:
    FitPhoto photo_;
    FitFault fault_;
};

}  // namespace avatarbooth

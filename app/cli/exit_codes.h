// Exit codes of the avatarbooth executable, one per kind of failure, so scripts can tell them apart.
#pragma once

#include "common/error.h"

namespace avatarbooth {

enum ExitCode : int {
    kExitOk = 0,
    kExitInternal = 1,     // a bug or unexpected library failure
    kExitUsage = 2,        // wrong command-line usage (CLI11's own code)
    kExitBadInput = 3,     // an input file is missing, unreadable or corrupt
    kExitNoFace = 4,       // no face / head found in a photo
    kExitMismatch = 5,     // the front and side photos do not belong together
    kExitBadConfig = 6,    // the configuration is invalid
    kExitOutput = 7,       // the output could not be written
    kExitDevice = 8,       // a camera, button line or display is missing, busy or went away
    kExitSomeFailed = 9,   // `batch` finished, but some of its sessions failed (see its summary.json)
    kExitInterrupted = 130,  // stopped by Ctrl-C (SIGINT), after keeping what was complete (shell convention 128+2)
};

inline int exitCodeFor(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::BadInput: return kExitBadInput;
        case ErrorKind::NoFace: return kExitNoFace;
        case ErrorKind::Mismatch: return kExitMismatch;
        case ErrorKind::BadConfig: return kExitBadConfig;
        case ErrorKind::Output: return kExitOutput;
        case ErrorKind::Device: return kExitDevice;
        case ErrorKind::Internal: return kExitInternal;
    }
    return kExitInternal;
}

}  // namespace avatarbooth

// What the kiosk's worker threads tell its main loop, through one MessageQueue<KioskMessage>.
#pragma once

#include "booth/flow_types.h"
#include "common/error.h"
#include "fit/fit_pipeline.h"
#include "kiosk/message_queue.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>

namespace avatarbooth {

struct CharacterOutputs;

// The landmark model has loaded (FitWorker): the pipeline, or why it could not load.
struct ModelLoaded {
    const FitPipeline* pipeline = nullptr;  // owned by the FitWorker; null when loading failed
    std::string error;
};
// A fit has started a step.
struct FitStepStarted {
    std::uint64_t job;
    FitStep step;
};
// A fit ended: the outcome, or the error (a cancelled fit posts nothing).
struct FitEnded {
    std::uint64_t job;
    std::shared_ptr<const FitOutcome> outcome;
    std::optional<FitError> error;
};
// The character of a fit was made (null: off, or it could not be made: `error` says why).
struct CharacterEnded {
    std::uint64_t job;
    std::shared_ptr<const CharacterOutputs> character;
    std::optional<std::string> error;
};
// A preview frame was analysed (PreviewWorker), in `seconds`.
struct PreviewEnded {
    PreviewAnalysed analysed;
    double seconds;
};
// A session folder was written, or not (SessionWriter).
struct FolderEnded {
    std::uint64_t job;
    std::filesystem::path folder;
    std::optional<BoothError> error;
    double seconds;
};
// A reveal style's work for a visitor has a result (StyleWorker): `apply` hands it to the style, on the main loop.
struct StyleWorkEnded {
    std::function<void()> apply;
};

// The printer's news (PrintWorker): a card sent, a job's or the queue's new state; `problem` when the operator has
// to act (out of paper, stopped, a job held or failed).
struct PrintStatus {
    std::string line;
    bool problem = false;
};

// A kept session's turntable.webp was made (TurntableWorker), or not (`error`).
struct TurntableEnded {
    std::filesystem::path keptFolder;
    std::size_t bytes = 0;
    double renderSeconds = 0, encodeSeconds = 0;
    std::optional<std::string> error;
};

using KioskMessage = std::variant<ModelLoaded, FitStepStarted, FitEnded, CharacterEnded, PreviewEnded, FolderEnded,
                                  StyleWorkEnded, PrintStatus, TurntableEnded>;
using KioskQueue = MessageQueue<KioskMessage>;

}  // namespace avatarbooth

// The batch worker that runs the kiosk's fit pipeline on one item and writes its session folder and the small
// files the report shows (photo and overlay thumbnails, the avatar as a script the report can load from file://).
#pragma once

#include "batch/batch_runner.h"
#include "common/error.h"
#include "fit/fit_pipeline.h"
#include "reveal/character/character_head.h"

#include <memory>
#include <optional>

namespace avatarbooth {

// Longest side of the report's thumbnails, in pixels.
inline constexpr int kReportThumbnailSize = 320;

// What each session folder gets besides the fit: the character (when its settings are given) and the previews' size.
struct BatchFolderSettings {
    std::optional<CharacterSettings> character;
    int previewSize = 512;
};

// A worker for `runBatch`: make it on the worker thread. It shares `shared`'s loaded landmark model (and base head)
// and has its own face detector and offscreen renderer. `shared` must outlive the worker.
std::unique_ptr<BatchWorker> makeFitWorker(const FitPipeline& shared, BatchFolderSettings folders,
                                           const std::filesystem::path& out);

// The failure reason of an error, as summary.json names it.
std::string failureReason(ErrorKind kind);

// (Re)writes OUT/report_files/ID/ from a complete session folder: thumbnails of front.*, side.*, front_overlay.jpg,
// side_overlay.jpg, and avatar.glb.js (the glb as base64 inside a script: a report opened from file:// may load
// scripts but may not fetch files). Returns the record's `files` map (paths relative to OUT).
std::map<std::string, std::string> writeReportFiles(const std::filesystem::path& out, const std::string& id);

// The record of a complete session folder, from its fit.json.
SessionRecord recordFromSessionFolder(const std::filesystem::path& out, const BatchItem& item);

}  // namespace avatarbooth

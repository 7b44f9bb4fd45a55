// The session folder: what one fitted visitor (or one recorded photo pair) leaves on disk, written in one place
// for the kiosk, `avatarbooth fit` and batch runs alike. DESIGN.md, "Output session folder"; the README's table.
#pragma once

#include "fit/fit_pipeline.h"
#include "render/previews.h"
#include "reveal/character/character_outputs.h"

#include <filesystem>
#include <vector>

namespace avatarbooth {

struct SessionFolderContents {
    // The photos' files, copied byte for byte into the folder; where empty (photos in memory, the kiosk), the
    // photo is written as a JPEG. fit.json lists them as the inputs.
    FitPhotoFiles photoFiles;
    // character.json and character.glb, when the character is on (null: none in the folder).
    const CharacterOutputs* character = nullptr;
    int previewSize = 512;  // the preview PNGs' side, in pixels
    // Supersample4 with a renderer of one sample (the kiosk's writer, beside the reveal); render/previews.h.
    Antialias previewAntialias = Antialias::Multisample;
};

// Writes `outcome` into `folder` atomically: the folder is complete (fit.json, written last, marks it) or absent,
// and an earlier result there stays as it was when writing fails (BoothError Output naming the file). Refuses to
// replace a folder that is not an earlier result. `renderer` draws the previews. Returns the paths written.
std::vector<std::filesystem::path> writeSessionFolder(const FitOutcome& outcome, const SessionFolderContents& contents,
                                                      const std::filesystem::path& folder, MeshRenderer& renderer);

}  // namespace avatarbooth

// The booth's configuration file (TOML): one table per part, each filling that part's settings struct.
//
// Every key has a default (the struct's own), so an empty file is a valid configuration. The file is read
// strictly: an unknown table or key, a value of the wrong type or out of range is an error naming the file, the
// line and the key (ErrorKind::BadConfig), so a typo never silently falls back to a default; every mistake in the
// file is reported at once. Every key, its type,
// range and doc are in config/config_schema.h; the reference with the defaults is `avatarbooth config
// --print-default` (kept as app/assets/booth.toml, installed as /etc/avatarbooth/booth.toml).
#pragma once

#include "reveal/animation/avatar_motion.h"
#include "booth/guidance.h"
#include "booth/session_store.h"
#include "booth/share_link.h"
#include "print/print_settings.h"
#include "booth/visitor_flow.h"
#include "drivers/camera/camera_settings.h"
#include "drivers/display/display_settings.h"
#include "drivers/gpio/gpio_settings.h"
#include "drivers/sound/sound_settings.h"
#include "fit/head/base_head.h"
#include "reveal/character/character_head.h"
#include "reveal/styles/style_settings.h"
#include "fit/fit_pipeline.h"
#include "booth/screens/screens.h"
#include "common/error.h"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

// [fit]: the photo-to-head pipeline. The base head is the built-in one unless both files are given.
struct FitConfig {
    FitSettings settings;
    std::filesystem::path baseMesh;      // your own base head (glb with UVs), see `avatarbooth make-base-head`
    std::filesystem::path baseFeatures;  // its feature file
    int previewSize = 512;               // the session folder's preview PNGs, in pixels
};

// [character]: the character avatar (Narita), made from every fit when enabled: character.json + character.glb in
// the session, and the character style on the reveal.
struct CharacterConfig {
    bool enabled = true;
    CharacterSettings settings;
};

struct BoothConfig {
    std::filesystem::path file;  // where it was read from; empty for the built-in defaults
    FitConfig fit;               // [fit]
    CameraSettings camera;       // [camera]
    GpioSettings buttons;        // [buttons]
    DisplaySettings display;     // [display]
    ScreenSettings screen;       // [screen]
    BoothSettings flow;          // [flow]
    GuidanceSettings guidance;   // [guidance]
    SessionStoreSettings sessions;  // [sessions]
    AnimationSettings animation;    // [animation]
    CharacterConfig character;      // [character]
    RevealSettings reveal;          // [reveal]
    StageSettings stage;            // [stage]
    ShareSettings share;            // [share]
    PrintSettings print;            // [print]
    SoundSettings sound;            // [sound]
};

// Every mistake in a configuration file, in line order, each a BoothError(BadConfig) "FILE:LINE: key: what is
// wrong"; what() lists them one a line (a single mistake reads as it always did), where() is the first one's.
class ConfigErrors : public BoothError {
public:
    explicit ConfigErrors(std::vector<BoothError> mistakes);  // at least one
    const std::vector<BoothError>& mistakes() const { return mistakes_; }

private:
    std::vector<BoothError> mistakes_;
};

// Reads and checks a configuration file. Throws ConfigErrors naming every mistake (in a file that is not valid
// TOML: its first syntax error), or BoothError(BadInput) when the file cannot be read.
BoothConfig loadBoothConfig(const std::filesystem::path& file);

// The same from text (`name` stands for the file in messages).
BoothConfig parseBoothConfig(const std::string& text, const std::string& name);

// The base head the configuration asks for: the built-in one, or the operator's own (loaded once per call).
std::shared_ptr<const BaseHead> configuredBaseHead(const FitConfig& fit);

}  // namespace avatarbooth

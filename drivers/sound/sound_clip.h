// Sounds as the player mixes them: 32-bit float stereo at kSoundRate, from an Ogg Vorbis file (the freedesktop
// sound theme's .oga, decoded with libvorbisfile and resampled with libsamplerate) or a tone made here.
#pragma once

#include <filesystem>
#include <vector>

namespace avatarbooth {

inline constexpr int kSoundRate = 48000;  // frames per second of every clip and of the output stream
inline constexpr int kSoundChannels = 2;

struct SoundClip {
    std::vector<float> samples;  // interleaved left, right; -1..1
    std::size_t frames() const { return samples.size() / kSoundChannels; }
    double seconds() const { return static_cast<double>(frames()) / kSoundRate; }
};

// An Ogg Vorbis file as a clip (mono is doubled, more than two channels keep the first two). Throws
// BoothError(BadInput) naming the file when it is missing or not Ogg Vorbis.
SoundClip loadOggVorbis(const std::filesystem::path& file);

// A sine tone of `hz` for `seconds` at `level` (0-1), faded in and out over 5 ms so that it does not click.
SoundClip makeTone(double hz, double seconds, double level);

}  // namespace avatarbooth

// Decoding and making the booth's sound clips (see sound_clip.h).
#include "drivers/sound/sound_clip.h"

#include "common/error.h"

#include <samplerate.h>
#include <vorbis/vorbisfile.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

namespace avatarbooth {

SoundClip loadOggVorbis(const std::filesystem::path& file) {
    OggVorbis_File vf;
    if (ov_fopen(file.c_str(), &vf) != 0)
        throw BoothError(ErrorKind::BadInput, file.string(), "not a readable Ogg Vorbis file (sound-theme-freedesktop?)");
    std::unique_ptr<OggVorbis_File, decltype(&ov_clear)> closer(&vf, ov_clear);
    const vorbis_info* info = ov_info(&vf, -1);
    const int channels = info->channels;
    const long rate = info->rate;
    std::vector<float> stereo;
    for (;;) {
        float** pcm = nullptr;
        int section = 0;
        const long n = ov_read_float(&vf, &pcm, 4096, &section);
        if (n == 0) break;
        if (n < 0) throw BoothError(ErrorKind::BadInput, file.string(), "corrupt Ogg Vorbis data");
        for (long i = 0; i < n; ++i) {
            stereo.push_back(pcm[0][i]);
            stereo.push_back(pcm[channels > 1 ? 1 : 0][i]);
        }
    }
    SoundClip clip;
    if (rate == kSoundRate) {
        clip.samples = std::move(stereo);
        return clip;
    }
    // libsamplerate's best converter: the clips are short and converted once, at start-up.
    const double ratio = static_cast<double>(kSoundRate) / static_cast<double>(rate);
    const long inFrames = static_cast<long>(stereo.size() / kSoundChannels);
    clip.samples.resize(static_cast<std::size_t>(std::ceil(static_cast<double>(inFrames) * ratio) + 16) * kSoundChannels);
    SRC_DATA data{};
    data.data_in = stereo.data();
    data.input_frames = inFrames;
    data.data_out = clip.samples.data();
    data.output_frames = static_cast<long>(clip.samples.size() / kSoundChannels);
    data.src_ratio = ratio;
    if (const int e = src_simple(&data, SRC_SINC_BEST_QUALITY, kSoundChannels); e != 0)
        throw BoothError(ErrorKind::Internal, file.string(), std::string("resampling: ") + src_strerror(e));
    clip.samples.resize(static_cast<std::size_t>(data.output_frames_gen) * kSoundChannels);
    return clip;
}

SoundClip makeTone(double hz, double seconds, double level) {
    SoundClip clip;
    const auto frames = static_cast<std::size_t>(seconds * kSoundRate);
    const double fade = 0.005 * kSoundRate;
    clip.samples.resize(frames * kSoundChannels);
    for (std::size_t i = 0; i < frames; ++i) {
        const double t = static_cast<double>(i) / kSoundRate;
        const double edge = std::min({1.0, static_cast<double>(i) / fade, static_cast<double>(frames - i) / fade});
        const auto v = static_cast<float>(level * edge * std::sin(2.0 * std::numbers::pi * hz * t));
        clip.samples[2 * i] = clip.samples[2 * i + 1] = v;
    }
    return clip;
}

}  // namespace avatarbooth

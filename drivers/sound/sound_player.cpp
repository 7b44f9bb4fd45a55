// The ALSA output stream and its mixer (see sound_player.h).
#include "drivers/sound/sound_player.h"

#include "common/error.h"

#include <alsa/asoundlib.h>

#include <algorithm>
#include <cmath>

namespace avatarbooth {

namespace {
constexpr int kPeriodFrames = kSoundRate / 100;     // 10 ms mixed at a time
constexpr unsigned kDeviceLatencyUs = 100000;       // the device's buffer: above the lead, so pacing never starves it
snd_pcm_t* handle(void* p) { return static_cast<snd_pcm_t*>(p); }
}  // namespace

SoundPlayer::SoundPlayer(const std::string& device, double volume)
    : device_(device), volume_(static_cast<float>(std::clamp(volume, 0.0, 1.0))) {
    snd_pcm_t* pcm = nullptr;
    if (const int e = snd_pcm_open(&pcm, device.c_str(), SND_PCM_STREAM_PLAYBACK, 0); e < 0)
        throw BoothError(ErrorKind::Device, "sound " + device, snd_strerror(e));
    // S16 interleaved at kSoundRate: ALSA's plug layer converts to what the card takes.
    if (const int e = snd_pcm_set_params(pcm, SND_PCM_FORMAT_S16_LE, SND_PCM_ACCESS_RW_INTERLEAVED, kSoundChannels,
                                         kSoundRate, 1, kDeviceLatencyUs);
        e < 0) {
        snd_pcm_close(pcm);
        throw BoothError(ErrorKind::Device, "sound " + device, std::string("cannot play 48 kHz stereo: ") + snd_strerror(e));
    }
    pcm_ = pcm;
    started_ = anchor_ = std::chrono::steady_clock::now();
    thread_ = std::thread([this] { run(); });
}

SoundPlayer::~SoundPlayer() {
    quit_ = true;
    thread_.join();
    snd_pcm_drop(handle(pcm_));
    snd_pcm_close(handle(pcm_));
}

int SoundPlayer::add(SoundClip clip) {
    std::lock_guard lock(mutex_);
    clips_.push_back(std::move(clip));
    return static_cast<int>(clips_.size()) - 1;
}

long long SoundPlayer::play(int id, Time when) {
    std::lock_guard lock(mutex_);
    if (id < 0 || id >= static_cast<int>(clips_.size())) return -1;
    const double at = std::chrono::duration<double>(when - anchor_).count() + lead();
    voices_.push_back({nextVoice_, id, anchorFrame_ + static_cast<long long>(std::llround(at * kSoundRate))});
    return nextVoice_++;
}

void SoundPlayer::cancel(long long voice) {
    std::lock_guard lock(mutex_);
    std::erase_if(voices_, [voice](const Voice& v) { return v.id == voice && !v.mixed; });
}

void SoundPlayer::run() {
    std::vector<float> mix(kPeriodFrames * kSoundChannels);
    std::vector<short> out(mix.size());
    long long written = 0;  // stream frames written
    while (!quit_) {
        Time anchor;
        long long anchorFrame;
        {
            std::lock_guard lock(mutex_);
            anchor = anchor_;
            anchorFrame = anchorFrame_;
        }
        // Pacing by the wall clock: never more than kAhead ahead of real time (a device that does not pace, a file,
        // would otherwise take the whole stream at once).
        const Time due = anchor + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(static_cast<double>(written - anchorFrame) / kSoundRate - kAhead));
        std::this_thread::sleep_until(due);
        std::fill(mix.begin(), mix.end(), 0.0f);
        {
            std::lock_guard lock(mutex_);
            for (auto v = voices_.begin(); v != voices_.end();) {
                const SoundClip& clip = clips_[static_cast<std::size_t>(v->clip)];
                // A clip asked for late (its first frame already written) starts at once.
                if (!v->mixed && v->startFrame < written) v->startFrame = written;
                if (v->startFrame < written + kPeriodFrames) v->mixed = true;  // it sounds from this period on
                const long long from = v->startFrame - written;  // frames into this period it starts
                for (long long f = std::max(0LL, from); f < kPeriodFrames; ++f) {
                    const long long c = written + f - v->startFrame;
                    if (c >= static_cast<long long>(clip.frames())) break;
                    for (int ch = 0; ch < kSoundChannels; ++ch)
                        mix[static_cast<std::size_t>(f * kSoundChannels + ch)] +=
                            clip.samples[static_cast<std::size_t>(c * kSoundChannels + ch)];
                }
                const bool done = written + kPeriodFrames - v->startFrame >= static_cast<long long>(clip.frames());
                v = done ? voices_.erase(v) : v + 1;
            }
        }
        for (std::size_t i = 0; i < mix.size(); ++i)
            out[i] = static_cast<short>(std::lround(std::clamp(mix[i] * volume_, -1.0f, 1.0f) * 32767.0f));
        snd_pcm_sframes_t n = snd_pcm_writei(handle(pcm_), out.data(), kPeriodFrames);
        if (n < 0) {
            // An underrun (the device drained the stream) or a suspend: recover and re-anchor the clock to now.
            if (snd_pcm_recover(handle(pcm_), static_cast<int>(n), 1) < 0) break;
            ++underruns_;
            {
                std::lock_guard lock(mutex_);
                anchor_ = std::chrono::steady_clock::now();  // the device starts again from the next frame
                anchorFrame_ = written;
            }
            n = snd_pcm_writei(handle(pcm_), out.data(), kPeriodFrames);
            if (n < 0) continue;
        }
        written += kPeriodFrames;
    }
}

std::vector<std::string> soundCards() {
    std::vector<std::string> cards;
    int card = -1;
    while (snd_card_next(&card) == 0 && card >= 0) {
        char* name = nullptr;
        if (snd_card_get_name(card, &name) == 0 && name) {
            cards.push_back(std::to_string(card) + ": " + name);
            free(name);
        }
    }
    return cards;
}

}  // namespace avatarbooth

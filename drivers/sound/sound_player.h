// Plays the booth's sound clips through ALSA on a thread of its own: one output stream kept open and fed with
// 10 ms periods (silence between sounds, clips mixed where they start), so that a sound starts within a period of
// being asked for and never waits for a device to open, and the main loop never waits for the sound card.
//
// Timing: a clip asked for at steady time t starts at the stream frame for t + lead() (the stream's first frame is
// started()), the same delay for every clip, so the sounds keep the rhythm of the events that asked for them. The
// stream is paced by the wall clock as well as by the device (written kAhead ahead of real time): a device that
// does not pace (ALSA's file and null outputs, which tests record with) still gets real time, and in a recording a
// clip asked for at t starts at sample (t - started() + lead()) * rate exactly. A card whose clock runs fast drains the lead after many minutes: the underrun is recovered and the
// stream re-anchored, a few milliseconds of silence lost.
#pragma once

#include "drivers/sound/sound_clip.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace avatarbooth {

class SoundPlayer {
public:
    using Time = std::chrono::steady_clock::time_point;

    // Opens the ALSA PCM `device` for kSoundRate stereo and starts the stream; `volume` 0-1 scales every clip.
    // Throws BoothError(Device) with ALSA's reason when the device cannot be opened.
    SoundPlayer(const std::string& device, double volume);
    ~SoundPlayer();  // stops the stream (a clip still playing is cut) and closes the device
    SoundPlayer(const SoundPlayer&) = delete;
    SoundPlayer& operator=(const SoundPlayer&) = delete;

    // Registers a clip before use; returns its id for play().
    int add(SoundClip clip);
    // Starts clip `id` at `when` + lead() (from any thread; returns at once). Clips overlap by mixing. `when` may
    // lie in the future: the clip waits for its time. Returns the voice, for cancel(); -1 for an unknown clip.
    long long play(int id, Time when = std::chrono::steady_clock::now());
    // Takes back a voice that has not started to sound (a cue asked for ahead of its time that no longer holds);
    // a voice already playing, finished or unknown is left as it is.
    void cancel(long long voice);

    Time started() const { return started_; }
    // Seconds from play() to the sound: more than the stream is written ahead of real time (kAhead), so that a clip
    // never finds its first frame already written and starts exactly where it was asked for.
    static constexpr double lead() { return 0.08; }
    static constexpr double kAhead = 0.05;
    const std::string& device() const { return device_; }
    // Underruns recovered so far (the device drained the stream).
    int underruns() const { return underruns_.load(); }

private:
    struct Voice {
        long long id;
        int clip;
        long long startFrame;  // in stream frames
        bool mixed = false;    // its first period has been mixed
    };
    void run();

    std::string device_;
    float volume_;
    void* pcm_ = nullptr;  // snd_pcm_t*, kept out of this header
    std::vector<SoundClip> clips_;
    std::mutex mutex_;
    std::vector<Voice> voices_;  // asked for and not finished
    long long nextVoice_ = 0;
    Time anchor_;                // the steady time of stream frame anchorFrame_ (re-anchored after an underrun)
    long long anchorFrame_ = 0;
    std::atomic<bool> quit_{false};
    std::atomic<int> underruns_{0};
    Time started_;
    std::thread thread_;  // last: starts once everything above exists
};

// The sound cards ALSA knows ("0: bcm2835 Headphones"); empty when there is none.
std::vector<std::string> soundCards();

}  // namespace avatarbooth

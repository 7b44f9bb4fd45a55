// What a test hears in a WAV file that ALSA's file output recorded (16-bit PCM): where each sound starts. A
// sound's onset is the first 1 ms window louder than -26 dBFS after at least 40 ms quieter than that.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace avatarbooth::test {

struct Wav {
    int rate = 0, channels = 0;
    std::vector<std::int16_t> samples;  // interleaved
    double seconds() const { return rate && channels ? static_cast<double>(samples.size()) / channels / rate : 0.0; }
};

// The RIFF chunks of a 16-bit PCM WAV ("fmt " and "data"); rate 0 when it is not one.
inline Wav readWav(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    Wav w;
    if (bytes.size() < 12 || bytes.compare(0, 4, "RIFF") != 0 || bytes.compare(8, 4, "WAVE") != 0) return w;
    const auto u32 = [&](std::size_t at) {
        std::uint32_t v;
        std::memcpy(&v, bytes.data() + at, 4);
        return v;
    };
    const auto u16 = [&](std::size_t at) {
        std::uint16_t v;
        std::memcpy(&v, bytes.data() + at, 2);
        return v;
    };
    for (std::size_t at = 12; at + 8 <= bytes.size();) {
        const std::string id = bytes.substr(at, 4);
        std::size_t size = u32(at + 4);
        if (id == "fmt " && size >= 16) {
            w.channels = u16(at + 10);
            w.rate = static_cast<int>(u32(at + 12));
            if (u16(at + 22) != 16) return Wav{};
        } else if (id == "data") {
            // ALSA writes the sizes when the file is closed; a recording cut short has them as 0 or too large.
            size = std::min(size == 0 ? bytes.size() : size, bytes.size() - at - 8);
            w.samples.resize(size / 2);
            std::memcpy(w.samples.data(), bytes.data() + at + 8, w.samples.size() * 2);
            return w;
        }
        at += 8 + size + (size & 1);
    }
    return Wav{};
}

// Seconds from the recording's start at which sounds start.
inline std::vector<double> onsets(const Wav& w) {
    std::vector<double> found;
    if (!w.rate || !w.channels) return found;
    const std::size_t window = static_cast<std::size_t>(w.rate / 1000);
    const std::size_t frames = w.samples.size() / static_cast<std::size_t>(w.channels);
    const int loud = static_cast<int>(32767 * 0.05);
    int quietWindows = 40;
    for (std::size_t f = 0; f + window <= frames; f += window) {
        int peak = 0;
        for (std::size_t i = f * w.channels; i < (f + window) * w.channels; ++i) peak = std::max(peak, std::abs(int{w.samples[i]}));
        if (peak >= loud) {
            if (quietWindows >= 40) {
                // The first sample over the threshold in this window: the onset to the sample.
                std::size_t at = f;
                for (std::size_t i = f * w.channels; i < (f + window) * w.channels; ++i)
                    if (std::abs(int{w.samples[i]}) >= loud) {
                        at = i / static_cast<std::size_t>(w.channels);
                        break;
                    }
                found.push_back(static_cast<double>(at) / w.rate);
            }
            quietWindows = 0;
        } else {
            ++quietWindows;
        }
    }
    return found;
}

}  // namespace avatarbooth::test

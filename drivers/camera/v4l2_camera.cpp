// The V4L2 backend: ioctls on a single-planar capture node, mmap buffers, poll + DQBUF for frames.
#include "drivers/camera/v4l2_camera.h"

#include "drivers/camera/frame_conversion.h"

#include <spdlog/spdlog.h>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <span>

namespace avatarbooth {

namespace {

constexpr auto kStillFrameTimeout = std::chrono::seconds(5);

int xioctl(int fd, unsigned long request, void* arg) {
    int r;
    do {
        r = ::ioctl(fd, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
}

std::string text(const __u8* bytes, std::size_t size) {
    const auto* chars = reinterpret_cast<const char*>(bytes);
    return std::string(chars, strnlen(chars, size));
}

// The capabilities of the node itself (a driver with several nodes reports the union in `capabilities`).
std::uint32_t nodeCaps(const v4l2_capability& cap) {
    return (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
}

double fpsOf(const v4l2_fract& interval) {
    return interval.numerator ? static_cast<double>(interval.denominator) / interval.numerator : 0.0;
}

// The highest rate a format offers at one size; 0 when the driver does not say.
double maxFps(int fd, std::uint32_t fourcc, std::uint32_t width, std::uint32_t height) {
    double best = 0;
    v4l2_frmivalenum ival{};
    ival.pixel_format = fourcc;
    ival.width = width;
    ival.height = height;
    for (ival.index = 0; xioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &ival) == 0; ++ival.index) {
        if (ival.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
            best = std::max(best, fpsOf(ival.discrete));
        } else {
            best = std::max(best, fpsOf(ival.stepwise.min));
            break;
        }
    }
    return best;
}

// TRY_FMT's answer for one wanted size (the driver clamps to what it can).
std::optional<std::pair<int, int>> trySize(int fd, std::uint32_t fourcc, std::uint32_t width, std::uint32_t height) {
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.pixelformat = fourcc;
    fmt.fmt.pix.width = width;
    fmt.fmt.pix.height = height;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd, VIDIOC_TRY_FMT, &fmt) != 0 || fmt.fmt.pix.pixelformat != fourcc) return std::nullopt;
    return std::pair{static_cast<int>(fmt.fmt.pix.width), static_cast<int>(fmt.fmt.pix.height)};
}

std::vector<V4l2Format> queryFormats(int fd) {
    std::vector<V4l2Format> formats;
    v4l2_fmtdesc desc{};
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    for (desc.index = 0; xioctl(fd, VIDIOC_ENUM_FMT, &desc) == 0; ++desc.index) {
        V4l2Format format;
        format.fourcc = desc.pixelformat;
        format.description = text(desc.description, sizeof desc.description);
        v4l2_frmsizeenum size{};
        size.pixel_format = desc.pixelformat;
        for (size.index = 0; xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) == 0; ++size.index) {
            if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
                format.sizes.push_back(V4l2FrameSize::discrete(
                    static_cast<int>(size.discrete.width), static_cast<int>(size.discrete.height),
                    maxFps(fd, desc.pixelformat, size.discrete.width, size.discrete.height)));
            } else {
                const auto& s = size.stepwise;
                format.sizes.push_back({static_cast<int>(s.min_width), static_cast<int>(s.max_width),
                                        static_cast<int>(s.step_width), static_cast<int>(s.min_height),
                                        static_cast<int>(s.max_height), static_cast<int>(s.step_height), 0});
                break;
            }
        }
        // Drivers without ENUM_FRAMESIZES: ask TRY_FMT for the smallest and largest and treat it as a range.
        if (format.sizes.empty()) {
            const auto smallest = trySize(fd, desc.pixelformat, 1, 1);
            const auto largest = trySize(fd, desc.pixelformat, 16384, 16384);
            if (smallest && largest)
                format.sizes.push_back({smallest->first, largest->first, 1, smallest->second, largest->second, 1, 0});
        }
        formats.push_back(std::move(format));
    }
    return formats;
}

std::string errorText(int error) { return std::strerror(error); }

}  // namespace

std::vector<std::string> listV4l2Nodes() {
    std::vector<std::pair<int, std::string>> nodes;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
        const auto name = entry.path().filename().string();
        if (name.size() > 5 && name.starts_with("video") &&
            std::all_of(name.begin() + 5, name.end(), [](char c) { return c >= '0' && c <= '9'; }))
            nodes.emplace_back(std::stoi(name.substr(5)), entry.path().string());
    }
    std::sort(nodes.begin(), nodes.end());
    std::vector<std::string> paths;
    for (auto& [number, path] : nodes) paths.push_back(std::move(path));
    return paths;
}

V4l2DeviceInfo probeV4l2Device(const std::string& path) {
    V4l2DeviceInfo info;
    info.path = path;
    const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        info.error = "cannot open: " + errorText(errno);
        return info;
    }
    v4l2_capability cap{};
    if (xioctl(fd, VIDIOC_QUERYCAP, &cap) != 0) {
        info.error = "not a V4L2 device (VIDIOC_QUERYCAP: " + errorText(errno) + ")";
    } else {
        info.card = text(cap.card, sizeof cap.card);
        info.driver = text(cap.driver, sizeof cap.driver);
        info.bus = text(cap.bus_info, sizeof cap.bus_info);
        const auto caps = nodeCaps(cap);
        info.canCapture = (caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING);
        info.mediaControllerCentric = (caps & V4L2_CAP_IO_MC) != 0;
        if (info.canCapture) info.formats = queryFormats(fd);
    }
    ::close(fd);
    return info;
}

std::string v4l2Unusable(const V4l2DeviceInfo& info) {
    if (!info.error.empty()) return info.error;
    if (!info.canCapture) return "not a single-planar video capture node";
    if (info.mediaControllerCentric) return "media-controller node (use libcamera)";
    if (!negotiateV4l2Format(info.formats, 0, 0, 0)) return "offers no format the booth reads (YUYV, MJPEG, RGB)";
    return "";
}

V4l2Camera::V4l2Camera(const CameraSettings& settings) : settings_(settings), device_(settings.device) {
    if (device_.empty()) {
        for (const auto& node : listV4l2Nodes()) {
            if (v4l2Unusable(probeV4l2Device(node)).empty()) {
                device_ = node;
                break;
            }
        }
        if (device_.empty())
            throw BoothError(ErrorKind::Device, "/dev/video*", "no V4L2 camera offering YUYV or MJPEG found");
    }

    fd_ = ::open(device_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
        const int e = errno;
        if (e == ENOENT || e == ENODEV || e == ENXIO)
            throw BoothError(ErrorKind::Device, device_,
                             "no such camera device (is the camera plugged in? `avatarbooth check` lists the cameras)");
        if (e == EACCES || e == EPERM)
            throw BoothError(ErrorKind::Device, device_,
                             "permission denied opening the camera (the booth's user must be in the `video` group)");
        if (e == EBUSY) throw BoothError(ErrorKind::Device, device_, "the camera is busy (another program is using it)");
        throw BoothError(ErrorKind::Device, device_, "cannot open the camera: " + errorText(e));
    }
    try {
        v4l2_capability cap{};
        if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0)
            throw BoothError(ErrorKind::Device, device_, "is not a V4L2 video device (VIDIOC_QUERYCAP: " + errorText(errno) + ")");
        card_ = text(cap.card, sizeof cap.card);
        const auto caps = nodeCaps(cap);
        if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
            if (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE)
                throw BoothError(ErrorKind::Device, device_,
                                 "is a multi-planar capture device, which the v4l2 backend does not drive; use the libcamera backend");
            throw BoothError(ErrorKind::Device, device_,
                             "is not a video capture node (" + card_ + "; cameras often have a second, metadata node)");
        }
        if (!(caps & V4L2_CAP_STREAMING))
            throw BoothError(ErrorKind::Device, device_, "cannot stream (no V4L2_CAP_STREAMING)");
        if (caps & V4L2_CAP_IO_MC)
            spdlog::warn("camera {}: a media-controller pipeline node; it may not stream unless the pipeline is set "
                         "up (the libcamera backend does that)", device_);

        formats_ = queryFormats(fd_);
        const auto preview = negotiateV4l2Format(formats_, settings_.previewWidth, settings_.previewHeight, settings_.previewFps);
        const auto still = negotiateV4l2Format(formats_, settings_.stillWidth, settings_.stillHeight, 0);
        if (!preview || !still)
            throw BoothError(ErrorKind::Device, device_,
                             "offers no format the booth can read (YUYV, MJPEG, RGB24, BGR24); it offers: " +
                                 describeV4l2Formats(formats_));
        previewChoice_ = *preview;
        stillChoice_ = *still;
        setFormat(previewChoice_, settings_.previewFps);
        previewActive_ = active_;
        stillActive_ = {stillChoice_.fourcc, stillChoice_.width, stillChoice_.height, 0, 0};
        spdlog::info("camera {}: {}", device_, describe().summary());
    } catch (...) {
        ::close(fd_);
        throw;
    }
}

V4l2Camera::~V4l2Camera() {
    stopStreaming();
    if (fd_ >= 0) ::close(fd_);
}

void V4l2Camera::fail(const char* call, int error) const {
    if (error == ENODEV || error == ENXIO || error == EIO || error == ESHUTDOWN)
        throw CameraGoneError(device_, std::string(call) + ": " + errorText(error));
    if (error == EBUSY)
        throw BoothError(ErrorKind::Device, device_, std::string(call) + ": the camera is busy (another program is streaming from it)");
    throw BoothError(ErrorKind::Device, device_, std::string(call) + " failed: " + errorText(error));
}

bool V4l2Camera::activeIs(const V4l2FormatChoice& choice) const {
    return active_.fourcc == choice.fourcc && active_.width == choice.width && active_.height == choice.height;
}

void V4l2Camera::setFormat(const V4l2FormatChoice& choice, double fps) {
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.width = static_cast<__u32>(choice.width);
    fmt.fmt.pix.height = static_cast<__u32>(choice.height);
    fmt.fmt.pix.pixelformat = choice.fourcc;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd_, VIDIOC_S_FMT, &fmt) != 0) fail("VIDIOC_S_FMT", errno);
    if (!rawFormatFromV4l2(fmt.fmt.pix.pixelformat))
        throw BoothError(ErrorKind::Device, device_,
                         "the driver set " + fourccName(fmt.fmt.pix.pixelformat) + " instead of " + fourccName(choice.fourcc));
    active_ = {fmt.fmt.pix.pixelformat, static_cast<int>(fmt.fmt.pix.width), static_cast<int>(fmt.fmt.pix.height),
               fmt.fmt.pix.bytesperline, 0};

    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_, VIDIOC_G_PARM, &parm) != 0) return;  // optional: many drivers have no rate control
    if (fps > 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
        parm.parm.capture.timeperframe = {1000, static_cast<__u32>(std::lround(fps * 1000))};
        if (xioctl(fd_, VIDIOC_S_PARM, &parm) != 0) spdlog::debug("camera {}: VIDIOC_S_PARM: {}", device_, errorText(errno));
    }
    active_.fps = fpsOf(parm.parm.capture.timeperframe);
}

void V4l2Camera::startStreaming(int bufferCount) {
    try {
        v4l2_requestbuffers req{};
        req.count = static_cast<__u32>(std::max(2, bufferCount));
        req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        req.memory = V4L2_MEMORY_MMAP;
        if (xioctl(fd_, VIDIOC_REQBUFS, &req) != 0) fail("VIDIOC_REQBUFS", errno);
        streaming_ = true;  // from here on stopStreaming() has buffers to give back
        if (req.count < 2)
            throw BoothError(ErrorKind::Device, device_, "the driver granted " + std::to_string(req.count) + " buffer(s), 2 are needed");
        for (__u32 i = 0; i < req.count; ++i) {
            v4l2_buffer buf{};
            buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            buf.memory = V4L2_MEMORY_MMAP;
            buf.index = i;
            if (xioctl(fd_, VIDIOC_QUERYBUF, &buf) != 0) fail("VIDIOC_QUERYBUF", errno);
            void* start = ::mmap(nullptr, buf.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buf.m.offset);
            if (start == MAP_FAILED) fail("mmap", errno);
            buffers_.push_back({start, buf.length});
        }
        for (__u32 i = 0; i < req.count; ++i) {
            v4l2_buffer buf{};
            buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            buf.memory = V4L2_MEMORY_MMAP;
            buf.index = i;
            if (xioctl(fd_, VIDIOC_QBUF, &buf) != 0) fail("VIDIOC_QBUF", errno);
        }
        int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (xioctl(fd_, VIDIOC_STREAMON, &type) != 0) fail("VIDIOC_STREAMON", errno);
    } catch (...) {
        stopStreaming();
        throw;
    }
}

void V4l2Camera::stopStreaming() noexcept {
    if (!streaming_) return;
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly when STREAMON never happened or the device is gone
    for (const auto& b : buffers_) ::munmap(b.start, b.length);
    buffers_.clear();
    v4l2_requestbuffers req{};
    req.count = 0;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    xioctl(fd_, VIDIOC_REQBUFS, &req);
    streaming_ = false;
}

std::optional<CameraFrame> V4l2Camera::readFrame(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        pollfd p{fd_, POLLIN, 0};
        const int r = ::poll(&p, 1, static_cast<int>(std::max<long long>(0, left.count())));
        if (r < 0) {
            if (errno == EINTR) continue;
            fail("poll", errno);
        }
        if (r == 0) return std::nullopt;

        v4l2_buffer buf{};
        buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf.memory = V4L2_MEMORY_MMAP;
        if (xioctl(fd_, VIDIOC_DQBUF, &buf) != 0) {
            const int e = errno;
            // POLLERR with nothing to dequeue: the queue is in error (vb2 does this when the device goes away).
            if (e == EAGAIN && (p.revents & (POLLERR | POLLHUP | POLLNVAL)))
                throw CameraGoneError(device_, "the driver reported an error on the stream");
            if (e == EAGAIN) continue;
            fail("VIDIOC_DQBUF", e);
        }
        if (buf.index >= buffers_.size())
            throw BoothError(ErrorKind::Device, device_, "VIDIOC_DQBUF returned buffer " + std::to_string(buf.index) + " of " + std::to_string(buffers_.size()));

        cv::Mat image;
        if (!(buf.flags & V4L2_BUF_FLAG_ERROR)) {
            const auto& mapped = buffers_[buf.index];
            const std::size_t used = buf.bytesused ? std::min<std::size_t>(buf.bytesused, mapped.length) : mapped.length;
            RawFrame raw{*rawFormatFromV4l2(active_.fourcc), active_.width, active_.height, active_.bytesPerLine,
                         {std::span(static_cast<const std::uint8_t*>(mapped.start), used)}};
            image = rawFrameToBgr(raw);
        }
        CameraFrame frame;
        frame.sequence = buf.sequence;
        if ((buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC)
            frame.timestamp = std::chrono::seconds(buf.timestamp.tv_sec) + std::chrono::microseconds(buf.timestamp.tv_usec);
        else
            frame.timestamp = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch());
        // QBUF writes the buffer's new (queued) state back into `buf`: read the frame's fields before it.
        if (xioctl(fd_, VIDIOC_QBUF, &buf) != 0) fail("VIDIOC_QBUF", errno);
        if (image.empty()) {
            ++dropped_;
            spdlog::debug("camera {}: dropped broken frame {}", device_, frame.sequence);
            continue;
        }
        frame.image = std::move(image);
        return frame;
    }
}

void V4l2Camera::start() {
    if (previewRunning_) return;
    if (!activeIs(previewChoice_)) {
        setFormat(previewChoice_, settings_.previewFps);
        previewActive_ = active_;
    }
    startStreaming(settings_.bufferCount);
    previewRunning_ = true;
    sequenceBase_ = nextSequence_;
}

std::optional<CameraFrame> V4l2Camera::nextFrame(std::chrono::milliseconds timeout) {
    start();
    auto frame = readFrame(timeout);
    if (frame) {
        // Some drivers repeat a sequence number when they fall behind (vivid under load does): keep ours rising.
        frame->sequence = std::max(frame->sequence + sequenceBase_, nextSequence_);
        nextSequence_ = frame->sequence + 1;
    }
    return frame;
}

CameraFrame V4l2Camera::captureStill() {
    const bool wasRunning = previewRunning_;
    const auto format = fourccName(stillChoice_.fourcc) + " " + std::to_string(stillChoice_.width) + "x" +
                        std::to_string(stillChoice_.height);
    auto take = [&](int skip) {
        for (int i = 0;; ++i) {
            auto f = readFrame(kStillFrameTimeout);
            if (!f)
                throw BoothError(ErrorKind::Device, device_,
                                 "no frame within " + std::to_string(kStillFrameTimeout.count()) + " s while taking a still (" + format + ")");
            if (i >= skip) return std::move(*f);
        }
    };

    CameraFrame still;
    const bool samePreviewFormat = stillChoice_.fourcc == previewChoice_.fourcc &&
                                   stillChoice_.width == previewChoice_.width && stillChoice_.height == previewChoice_.height;
    if (samePreviewFormat) {
        // The preview already is the still format: the next preview frame is the still. Frames already waiting
        // in the queue were exposed before the still was asked for (up to bufferCount frames ago): skip them.
        start();
        if (wasRunning)
            while (readFrame(std::chrono::milliseconds(0))) {
            }
        still = take(wasRunning ? 0 : settings_.stillWarmupFrames);
        if (!wasRunning) stop();
    } else {
        stop();
        try {
            setFormat(stillChoice_, 0);
            stillActive_ = active_;
            startStreaming(2);
            still = take(settings_.stillWarmupFrames);
            stopStreaming();
        } catch (const CameraGoneError&) {
            throw;
        } catch (...) {
            // Leave the camera as it was for the next attempt, if it still answers.
            stopStreaming();
            try {
                if (wasRunning) start();
            } catch (const std::exception& e) {
                spdlog::warn("camera {}: preview did not restart after a failed still: {}", device_, e.what());
            }
            throw;
        }
        if (wasRunning) start();
    }
    still.sequence = stillsTaken_++;
    return still;
}

void V4l2Camera::stop() {
    stopStreaming();
    previewRunning_ = false;
}

CameraDescription V4l2Camera::describe() const {
    CameraDescription d;
    d.backend = "v4l2";
    d.device = device_;
    d.name = card_;
    d.preview = {fourccName(previewActive_.fourcc), previewActive_.width, previewActive_.height, previewActive_.fps};
    d.still = {fourccName(stillActive_.fourcc), stillActive_.width, stillActive_.height, stillActive_.fps};
    return d;
}

}  // namespace avatarbooth

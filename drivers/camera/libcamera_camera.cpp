// The libcamera backend: one shared CameraManager, requests completing into a queue read by nextFrame(), the
// viewfinder configuration swapped for the still one around a capture.
#include "drivers/camera/libcamera_camera.h"

#include "drivers/camera/frame_conversion.h"
#include "drivers/camera/libcamera_compat.h"
#include "drivers/camera/libcamera_log.h"

#include <libcamera/libcamera.h>
#include <spdlog/spdlog.h>

#include <sys/mman.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

namespace avatarbooth {

namespace lc = libcamera;

namespace {

constexpr auto kStillFrameTimeout = std::chrono::seconds(5);

// libcamera allows one CameraManager per process: every user shares this one, started on first use and
// stopped when the last user lets go.
std::shared_ptr<lc::CameraManager> sharedCameraManager() {
    static std::mutex mutex;
    static std::weak_ptr<lc::CameraManager> shared;
    std::lock_guard lock(mutex);
    if (auto manager = shared.lock()) return manager;
    routeLibcameraLogToSpdlog();
    std::shared_ptr<lc::CameraManager> manager(new lc::CameraManager, [](lc::CameraManager* m) {
        m->stop();
        delete m;
    });
    if (const int r = manager->start(); r != 0)
        throw BoothError(ErrorKind::Device, "libcamera", "the camera manager did not start: " + std::string(std::strerror(-r)));
    shared = manager;
    return manager;
}

std::string modelOf(const lc::Camera& camera) {
    const auto model = camera.properties().get(lc::properties::Model);
    return model ? *model : std::string();
}

// The first pixel format we convert that the stream offers (RGB first: no conversion beyond a copy).
void choosePixelFormat(lc::StreamConfiguration& stream) {
    static const lc::PixelFormat preferred[] = {lc::formats::RGB888, lc::formats::XRGB8888, lc::formats::BGR888,
                                                lc::formats::XBGR8888, lc::formats::YUYV, lc::formats::NV12,
                                                lc::formats::YUV420, lc::formats::MJPEG};
    const auto offered = stream.formats().pixelformats();
    for (const auto& format : preferred) {
        if (std::find(offered.begin(), offered.end(), format) != offered.end()) {
            stream.pixelFormat = format;
            return;
        }
    }
    stream.pixelFormat = lc::formats::RGB888;  // validate() will say what it can do instead
}

}  // namespace

std::string libcameraVersion() { return lc::CameraManager::version(); }

std::vector<LibcameraCameraInfo> listLibcameraCameras() {
    const auto manager = sharedCameraManager();
    std::vector<LibcameraCameraInfo> list;
    for (const auto& camera : manager->cameras()) list.push_back({camera->id(), modelOf(*camera)});
    return list;
}

struct LibcameraCamera::Impl {
    struct Mapping {
        void* start = nullptr;
        std::size_t length = 0;
    };

    CameraSettings settings;
    // Declared first so it is destroyed last, after the camera.
    std::shared_ptr<lc::CameraManager> manager;
    std::shared_ptr<lc::Camera> camera;
    std::string id, model;
    bool acquired = false;
    std::unique_ptr<lc::CameraConfiguration> previewConfig, stillConfig;
    lc::CameraConfiguration* configured = nullptr;
    std::unique_ptr<lc::FrameBufferAllocator> allocator;
    std::vector<std::unique_ptr<lc::Request>> requests;
    std::map<int, Mapping> mappings;  // by dmabuf fd
    bool running = false, previewRunning = false;
    std::uint64_t sequenceBase = 0, nextSequence = 0, stillsTaken = 0;

    std::mutex mutex;
    std::condition_variable completedChanged;
    std::deque<lc::Request*> completed;
    bool gone = false;

    ~Impl() {
        stopStream();
        releaseBuffers();
        if (camera) {
            camera->requestCompleted.disconnect(this);
            camera->disconnected.disconnect(this);
            if (acquired) camera->release();
        }
    }

    // libcamera's thread.
    void onRequestCompleted(lc::Request* request) {
        if (request->status() == lc::Request::RequestCancelled) return;
        std::lock_guard lock(mutex);
        completed.push_back(request);
        completedChanged.notify_one();
    }

    // libcamera's thread.
    void onDisconnected() {
        std::lock_guard lock(mutex);
        gone = true;
        completedChanged.notify_all();
    }

    void checkConnected() {
        std::lock_guard lock(mutex);
        if (gone) throw CameraGoneError(id, "libcamera reported the camera disconnected");
    }

    [[noreturn]] void fail(const char* call, int r) const {
        if (r == -ENODEV || r == -EIO) throw CameraGoneError(id, std::string(call) + ": " + std::strerror(-r));
        throw BoothError(ErrorKind::Device, id, std::string(call) + " failed: " + std::strerror(-r));
    }

    std::unique_ptr<lc::CameraConfiguration> makeConfig(lc::StreamRole role, int width, int height, int buffers) {
        auto config = camera->generateConfiguration({role});
        if (!config || config->empty())
            throw BoothError(ErrorKind::Device, id, "has no configuration for a " + std::string(role == lc::StreamRole::Viewfinder ? "viewfinder" : "still") + " stream");
        auto& stream = config->at(0);
        choosePixelFormat(stream);
        if (width > 0 && height > 0) stream.size = lc::Size(static_cast<unsigned>(width), static_cast<unsigned>(height));
        if (buffers > 0) stream.bufferCount = static_cast<unsigned>(buffers);
        libcamera_compat::uprightImages(*config);
        if (config->validate() == lc::CameraConfiguration::Invalid)
            throw BoothError(ErrorKind::Device, id, "refused the stream configuration " + stream.toString());
        spdlog::debug("camera {}: {} {}, orientation {}", id, role == lc::StreamRole::Viewfinder ? "viewfinder" : "still",
                      stream.toString(), libcamera_compat::orientationName(*config));
        if (!rawFormatFromLibcamera(stream.pixelFormat.toString()))
            throw BoothError(ErrorKind::Device, id, "offers only the pixel format " + stream.pixelFormat.toString() + ", which the booth cannot convert");
        return config;
    }

    void releaseBuffers() {
        requests.clear();
        for (auto& [fd, m] : mappings) ::munmap(m.start, m.length);
        mappings.clear();
        allocator.reset();
        configured = nullptr;
    }

    void configure(lc::CameraConfiguration& config) {
        if (configured == &config) return;
        releaseBuffers();
        if (const int r = camera->configure(&config); r < 0) fail("Camera::configure", r);
        configured = &config;
        lc::Stream* stream = config.at(0).stream();
        allocator = std::make_unique<lc::FrameBufferAllocator>(camera);
        if (const int r = allocator->allocate(stream); r < 0) fail("FrameBufferAllocator::allocate", r);
        for (const auto& buffer : allocator->buffers(stream)) {
            // Planes may share one dmabuf at different offsets: map each dmabuf once, over all its planes.
            for (const auto& plane : buffer->planes()) {
                auto& m = mappings[plane.fd.get()];
                m.length = std::max<std::size_t>(m.length, std::size_t{plane.offset} + plane.length);
            }
            auto request = camera->createRequest();
            if (!request) throw BoothError(ErrorKind::Device, id, "could not create a capture request");
            if (const int r = request->addBuffer(stream, buffer.get()); r < 0) fail("Request::addBuffer", r);
            requests.push_back(std::move(request));
        }
        for (auto& [fd, m] : mappings) {
            m.start = ::mmap(nullptr, m.length, PROT_READ, MAP_SHARED, fd, 0);
            if (m.start == MAP_FAILED) {
                m.start = nullptr;
                const int e = errno;
                mappings.erase(fd);
                releaseBuffers();
                throw BoothError(ErrorKind::Device, id, std::string("mmap of a frame buffer failed: ") + std::strerror(e));
            }
        }
    }

    void startStream() {
        if (running) return;
        {
            std::lock_guard lock(mutex);
            completed.clear();
        }
        // The preview rate, where the pipeline lets us set it (frame duration in microseconds, min = max).
        lc::ControlList controls(lc::controls::controls);
        const double fps = configured == previewConfig.get() ? settings.previewFps : 0;
        if (fps > 0 && camera->controls().count(&lc::controls::FrameDurationLimits)) {
            const auto us = static_cast<std::int64_t>(1e6 / fps);
            controls.set(lc::controls::FrameDurationLimits, lc::Span<const std::int64_t, 2>({us, us}));
        }
        if (const int r = camera->start(&controls); r < 0) fail("Camera::start", r);
        running = true;
        for (auto& request : requests) {
            request->reuse(lc::Request::ReuseBuffers);
            if (const int r = camera->queueRequest(request.get()); r < 0) fail("Camera::queueRequest", r);
        }
    }

    void stopStream() noexcept {
        if (!running) return;
        camera->stop();  // completes every queued request as cancelled
        running = false;
        std::lock_guard lock(mutex);
        completed.clear();
    }

    std::optional<CameraFrame> read(std::chrono::milliseconds timeout) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        for (;;) {
            lc::Request* request = nullptr;
            {
                std::unique_lock lock(mutex);
                completedChanged.wait_until(lock, deadline, [&] { return gone || !completed.empty(); });
                if (gone) throw CameraGoneError(id, "libcamera reported the camera disconnected");
                if (completed.empty()) return std::nullopt;
                request = completed.front();
                completed.pop_front();
            }
            auto frame = convert(*request);
            request->reuse(lc::Request::ReuseBuffers);
            if (const int r = camera->queueRequest(request); r < 0) fail("Camera::queueRequest", r);
            if (frame) return frame;
        }
    }

    // The request's frame as BGR; nullopt for a frame the pipeline marks as broken or that does not convert.
    std::optional<CameraFrame> convert(lc::Request& request) {
        const auto& stream = configured->at(0);
        const auto it = request.buffers().find(stream.stream());
        if (it == request.buffers().end()) return std::nullopt;
        const lc::FrameBuffer& buffer = *it->second;
        const auto& meta = buffer.metadata();
        if (meta.status != lc::FrameMetadata::FrameSuccess) return std::nullopt;

        RawFrame raw;
        raw.format = *rawFormatFromLibcamera(stream.pixelFormat.toString());
        raw.width = static_cast<int>(stream.size.width);
        raw.height = static_cast<int>(stream.size.height);
        raw.stride = stream.stride;
        const auto& planes = buffer.planes();
        for (std::size_t i = 0; i < planes.size(); ++i) {
            const auto& m = mappings.at(planes[i].fd.get());
            std::size_t length = planes[i].length;
            if (i < meta.planes().size() && meta.planes()[i].bytesused) length = std::min<std::size_t>(length, meta.planes()[i].bytesused);
            raw.planes.emplace_back(static_cast<const std::uint8_t*>(m.start) + planes[i].offset, length);
        }
        CameraFrame frame;
        frame.image = rawFrameToBgr(raw);
        if (frame.image.empty()) {
            spdlog::debug("camera {}: dropped a frame that did not convert ({})", id, stream.toString());
            return std::nullopt;
        }
        frame.sequence = meta.sequence;
        const auto sensorTime = request.metadata().get(lc::controls::SensorTimestamp);
        frame.timestamp = std::chrono::nanoseconds(sensorTime ? *sensorTime : static_cast<std::int64_t>(meta.timestamp));
        return frame;
    }
};

LibcameraCamera::LibcameraCamera(const CameraSettings& settings) : impl_(std::make_unique<Impl>()) {
    auto& d = *impl_;
    d.settings = settings;
    d.manager = sharedCameraManager();
    const auto cameras = d.manager->cameras();
    if (cameras.empty())
        throw BoothError(ErrorKind::Device, "libcamera", "no cameras found (libcamera " + libcameraVersion() + ")");
    if (settings.device.empty()) {
        d.camera = cameras.front();
    } else {
        d.camera = d.manager->get(settings.device);
        if (!d.camera) {
            std::string ids;
            for (const auto& c : cameras) ids += (ids.empty() ? "" : ", ") + c->id();
            throw BoothError(ErrorKind::Device, settings.device, "no such libcamera camera; found: " + ids);
        }
    }
    d.id = d.camera->id();
    d.model = modelOf(*d.camera);
    if (d.camera->acquire() != 0)
        throw BoothError(ErrorKind::Device, d.id, "the camera is in use by another program");
    d.acquired = true;
    d.camera->requestCompleted.connect(&d, &Impl::onRequestCompleted);
    d.camera->disconnected.connect(&d, &Impl::onDisconnected);

    d.previewConfig = d.makeConfig(lc::StreamRole::Viewfinder, settings.previewWidth, settings.previewHeight, settings.bufferCount);
    d.stillConfig = d.makeConfig(lc::StreamRole::StillCapture, settings.stillWidth, settings.stillHeight, 0);
    spdlog::info("camera {}: {}", d.id, describe().summary());
}

LibcameraCamera::~LibcameraCamera() = default;

void LibcameraCamera::start() {
    auto& d = *impl_;
    d.checkConnected();
    if (d.previewRunning) return;
    d.configure(*d.previewConfig);
    d.startStream();
    d.previewRunning = true;
    d.sequenceBase = d.nextSequence;
}

std::optional<CameraFrame> LibcameraCamera::nextFrame(std::chrono::milliseconds timeout) {
    auto& d = *impl_;
    start();
    auto frame = d.read(timeout);
    if (frame) {
        // Some drivers repeat a sequence number when they fall behind (vivid under load does): keep ours rising.
        frame->sequence = std::max(frame->sequence + d.sequenceBase, d.nextSequence);
        d.nextSequence = frame->sequence + 1;
    }
    return frame;
}

CameraFrame LibcameraCamera::captureStill() {
    auto& d = *impl_;
    d.checkConnected();
    const bool wasRunning = d.previewRunning;
    stop();
    CameraFrame still;
    try {
        d.configure(*d.stillConfig);
        d.startStream();
        for (int i = 0;; ++i) {
            auto f = d.read(kStillFrameTimeout);
            if (!f)
                throw BoothError(ErrorKind::Device, d.id, "no frame within " + std::to_string(kStillFrameTimeout.count()) +
                                                              " s while taking a still (" + d.stillConfig->at(0).toString() + ")");
            if (i >= d.settings.stillWarmupFrames) {
                still = std::move(*f);
                break;
            }
        }
        d.stopStream();
    } catch (const CameraGoneError&) {
        throw;
    } catch (...) {
        d.stopStream();
        try {
            if (wasRunning) start();
        } catch (const std::exception& e) {
            spdlog::warn("camera {}: preview did not restart after a failed still: {}", d.id, e.what());
        }
        throw;
    }
    if (wasRunning) start();
    still.sequence = d.stillsTaken++;
    return still;
}

void LibcameraCamera::stop() {
    impl_->stopStream();
    impl_->previewRunning = false;
}

CameraDescription LibcameraCamera::describe() const {
    const auto& d = *impl_;
    auto format = [](const lc::StreamConfiguration& s, double fps) {
        return CameraStreamFormat{s.pixelFormat.toString(), static_cast<int>(s.size.width), static_cast<int>(s.size.height), fps};
    };
    CameraDescription desc;
    desc.backend = "libcamera";
    desc.device = d.id;
    desc.name = d.model;
    const bool rateControl = d.camera->controls().count(&lc::controls::FrameDurationLimits) > 0;
    desc.preview = format(d.previewConfig->at(0), rateControl ? d.settings.previewFps : 0);
    desc.still = format(d.stillConfig->at(0), 0);
    return desc;
}

}  // namespace avatarbooth

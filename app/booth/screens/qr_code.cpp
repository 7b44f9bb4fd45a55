// QR codes with libqrencode (see qr_code.h).
#include "booth/screens/qr_code.h"

#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <qrencode.h>

#include <memory>

namespace avatarbooth {

cv::Mat encodeQrModules(const std::string& text) {
    const std::unique_ptr<QRcode, decltype(&QRcode_free)> code(
        QRcode_encodeString8bit(text.c_str(), 0, QR_ECLEVEL_M), &QRcode_free);
    if (!code) throw BoothError(ErrorKind::Internal, "QR code", "cannot encode " + std::to_string(text.size()) + " bytes");
    const int n = code->width;
    cv::Mat modules(n, n, CV_8U);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) modules.at<unsigned char>(y, x) = code->data[y * n + x] & 1;  // bit 0: dark
    return modules;
}

cv::Mat drawQrCode(const cv::Mat& modules, int modulePixels) {
    const int scale = std::max(1, modulePixels);
    const int side = (modules.cols + 2 * kQrQuietModules) * scale;
    cv::Mat image(side, side, CV_8UC3, cv::Scalar(255, 255, 255));
    for (int y = 0; y < modules.rows; ++y)
        for (int x = 0; x < modules.cols; ++x)
            if (modules.at<unsigned char>(y, x))
                image(cv::Rect((x + kQrQuietModules) * scale, (y + kQrQuietModules) * scale, scale, scale))
                    .setTo(cv::Scalar(0, 0, 0));
    return image;
}

}  // namespace avatarbooth

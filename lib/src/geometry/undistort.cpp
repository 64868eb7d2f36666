#include "celc/geometry/undistort.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace celc {

std::vector<Vec2> undistortPixelsCv(const CameraModel& camera, const std::vector<Vec2>& pixels) {
  std::vector<Vec2> out(pixels.size());
  if (pixels.empty()) return out;
  cv::Mat K = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  cv::Mat src(int(pixels.size()), 1, CV_64FC2), dst;
  for (std::size_t i = 0; i < pixels.size(); ++i)
    src.at<cv::Vec2d>(int(i)) = cv::Vec2d(pixels[i].x(), pixels[i].y());
  const auto& c = camera.coeffs;
  switch (camera.distortion) {
    case DistortionModel::None:
      for (std::size_t i = 0; i < pixels.size(); ++i)
        out[i] = Vec2((pixels[i].x() - camera.cx) / camera.fx, (pixels[i].y() - camera.cy) / camera.fy);
      return out;
    case DistortionModel::RadTan: {
      cv::Mat D = (cv::Mat_<double>(1, 5) << c[0], c[1], c[2], c[3], c[4]);
      // more iterations than OpenCV's default 5 so that strong distortion converges
      cv::undistortPoints(src, dst, K, D, cv::noArray(), cv::noArray(),
                          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
      break;
    }
    case DistortionModel::Equidistant: {
      cv::Mat D = (cv::Mat_<double>(1, 4) << c[0], c[1], c[2], c[3]);
      cv::fisheye::undistortPoints(src, dst, K, D, cv::noArray(), cv::noArray(),
                                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
      break;
    }
  }
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const cv::Vec2d v = dst.at<cv::Vec2d>(int(i));
    out[i] = Vec2(v[0], v[1]);
  }
  return out;
}

UndistortLut::UndistortLut(const CameraModel& camera) {
  const std::string err = camera.validate();
  if (!err.empty()) throw std::invalid_argument("undistortion table: " + err);
  if (camera.width > kMaxSensorSide || camera.height > kMaxSensorSide)
    throw std::invalid_argument("undistortion table: sensor " + std::to_string(camera.width) + "x" +
                                std::to_string(camera.height) + " exceeds " + std::to_string(kMaxSensorSide) + "x" +
                                std::to_string(kMaxSensorSide));
  w_ = camera.width;
  h_ = camera.height;
  // Row blocks: the peak memory is the table plus one block, not three copies
  // of the table (each pixel is undistorted independently: same values).
  xy_.resize(2 * std::size_t(w_) * std::size_t(h_));
  constexpr int kRowsPerBlock = 64;
  std::vector<Vec2> px;
  for (int y0 = 0; y0 < h_; y0 += kRowsPerBlock) {
    const int y1 = std::min(h_, y0 + kRowsPerBlock);
    px.clear();
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w_; ++x) px.emplace_back(double(x), double(y));
    const auto un = undistortPixelsCv(camera, px);
    const std::size_t base = 2 * std::size_t(y0) * std::size_t(w_);
    for (std::size_t i = 0; i < un.size(); ++i) {
      xy_[base + 2 * i] = un[i].x();
      xy_[base + 2 * i + 1] = un[i].y();
    }
  }
}

}  // namespace celc

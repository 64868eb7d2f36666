// The per-pixel undistortion table (OpenCV) against CameraModel::undistort.
#include <gtest/gtest.h>

#include "celc/geometry/undistort.hpp"
#include "celc/io/event_reader.hpp"

using namespace celc;

namespace {
CameraModel ecdCamera() {  // Event Camera Dataset DAVIS240C calib.txt
  CameraModel c;
  c.width = 240, c.height = 180;
  c.fx = 199.092366542, c.fy = 198.82882047, c.cx = 132.192071378, c.cy = 110.712660011;
  c.distortion = DistortionModel::RadTan;
  c.coeffs = {-0.368436311798, 0.150947243557, -0.000296130534385, -0.000759431726241, 0.0};
  return c;
}
}  // namespace

TEST(GeometryUndistort, LutMatchesCameraModelRadTan) {
  const CameraModel c = ecdCamera();
  const UndistortLut lut(c);
  ASSERT_EQ(lut.width(), 240);
  double worst = 0.0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const Vec2 u = lut.at(x, y);
      // re-distorting the table entry gives back the pixel (the real criterion)
      const Vec2 d = c.distort(u);
      const Vec2 px(c.fx * d.x() + c.cx, c.fy * d.y() + c.cy);
      worst = std::max(worst, (px - Vec2(x, y)).norm());
      const Vec3 b = c.bearing(Vec2(x, y));
      EXPECT_LT((u - b.head<2>()).norm(), 1e-6) << x << "," << y;
    }
  EXPECT_LT(worst, 1e-6);  // [px]
}

TEST(GeometryUndistort, LutMatchesCameraModelEquidistantAndNone) {
  CameraModel c;
  c.width = 346, c.height = 260, c.fx = c.fy = 250.0, c.cx = 170.0, c.cy = 128.0;
  c.distortion = DistortionModel::Equidistant;
  c.coeffs = {0.05, -0.01, 0.002, -0.0005, 0.0};
  const UndistortLut lut(c);
  for (int y = 0; y < c.height; y += 7)
    for (int x = 0; x < c.width; x += 5) {
      const Vec2 d = c.distort(lut.at(x, y));
      EXPECT_LT((Vec2(c.fx * d.x() + c.cx, c.fy * d.y() + c.cy) - Vec2(x, y)).norm(), 1e-6);
    }
  c.distortion = DistortionModel::None;
  const UndistortLut pin(c);
  EXPECT_LT((pin.at(10, 20) - Vec2((10 - 170.0) / 250.0, (20 - 128.0) / 250.0)).norm(), 1e-15);
  Vec3 b;
  EXPECT_FALSE(pin.bearing(346, 0, b));
  EXPECT_FALSE(pin.bearing(-1, 0, b));
  EXPECT_TRUE(pin.bearing(0, 0, b));
  EXPECT_DOUBLE_EQ(b.z(), 1.0);
}

TEST(GeometryUndistort, InvalidCameraThrows) {
  CameraModel c;
  c.fx = -1.0;
  EXPECT_THROW(UndistortLut{c}, std::invalid_argument);
}

// ---- sizes bounded before allocation ------------------------------------------

TEST(IoRobustness, UndistortTableRefusesHugeSensorsAndReaderOptionsAreBounded) {
  CameraModel c;
  c.width = 30000;
  c.height = 30000;
  c.fx = c.fy = 300;
  c.cx = c.cy = 100;
  try {
    UndistortLut lut(c);
    ADD_FAILURE() << "built a 30000x30000 table";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds 4096x4096"), std::string::npos) << e.what();
  }
  ReaderOptions o;
  o.width = 5000;
  o.height = 10;
  EXPECT_NE(o.validate().find("4096"), std::string::npos);
}

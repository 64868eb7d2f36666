// Calibration YAML (docs/formats.md) and RPG calib.txt.
#include <gtest/gtest.h>

#include "celc/io/calibration.hpp"
#include "io_test_util.hpp"

using namespace celc;
using namespace celc;
using celc::test::expectPrintable;
using celc::test::TempDir;
using celc::test::writeBytes;

namespace {
const char* kGood = R"(camera:
  width: 240
  height: 180
  fx: 199.092366542
  fy: 198.82882047
  cx: 132.192071378
  cy: 110.712660011
  distortion_model: radtan
  distortion: [-0.368436311798, 0.150947243557, -0.000296130534385, -0.000759431726241, 0.0]
imu:
  R_cam_imu: [0,-1,0, 1,0,0, 0,0,1]
  time_offset: 0.0025
body:
  T_body_cam: [1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3, 0,0,0,1]
)";
}  // namespace

TEST(IoCalibration, YamlFull) {
  TempDir d;
  celc::test::writeBytes(d.file("c.yaml"), kGood);
  const Calibration c = loadCalibrationYaml(d.file("c.yaml"));
  EXPECT_EQ(c.camera.width, 240);
  EXPECT_EQ(c.camera.height, 180);
  EXPECT_DOUBLE_EQ(c.camera.fx, 199.092366542);
  EXPECT_DOUBLE_EQ(c.camera.cy, 110.712660011);
  EXPECT_EQ(c.camera.distortion, DistortionModel::RadTan);
  EXPECT_DOUBLE_EQ(c.camera.coeffs[0], -0.368436311798);
  EXPECT_DOUBLE_EQ(c.camera.coeffs[3], -0.000759431726241);
  EXPECT_TRUE(c.has_imu);
  EXPECT_DOUBLE_EQ(c.time_offset, 0.0025);
  EXPECT_LT((c.R_cam_imu * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(c.T_body_cam(1, 3), 0.2);
}

TEST(IoCalibration, YamlDefaultsAndTCamImuAndEquidistant) {
  TempDir d;
  celc::test::writeBytes(d.file("c.yaml"),
                            "camera: {width: 346, height: 260, fx: 300, fy: 300, cx: 173, cy: 130,\n"
                            "  distortion_model: equidistant, distortion: [0.1, -0.01, 0.001, 0]}\n"
                            "imu:\n  T_cam_imu: [1,0,0,5, 0,0,-1,6, 0,1,0,7, 0,0,0,1]\n");
  const Calibration c = loadCalibrationYaml(d.file("c.yaml"));
  EXPECT_EQ(c.camera.distortion, DistortionModel::Equidistant);
  EXPECT_DOUBLE_EQ(c.camera.coeffs[2], 0.001);
  EXPECT_DOUBLE_EQ(c.R_cam_imu(1, 2), -1.0);
  EXPECT_DOUBLE_EQ(c.time_offset, 0.0);
  EXPECT_TRUE(c.T_body_cam.isIdentity());
  EXPECT_FALSE(c.has_body);
}

TEST(IoCalibrationBad, UnknownKeysWrongTypesAndValues) {
  TempDir d;
  auto check = [&](const std::string& text, std::vector<std::string> frags) {
    celc::test::writeBytes(d.file("c.yaml"), text);
    frags.push_back(d.file("c.yaml"));
    try {
      loadCalibrationYaml(d.file("c.yaml"));
      ADD_FAILURE() << "no error for:\n" << text;
    } catch (const celc::ConfigError& e) {
      for (const auto& f : frags) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what() << " / " << f;
    }
  };
  const std::string cam = "camera: {width: 240, height: 180, fx: 200, fy: 200, cx: 120, cy: 90}\n";
  check(cam + "imu: {R_cam_imu: [1,0,0, 0,1,0, 0,0,1], time_ofset: 0.1}\n", {"unknown key 'imu.time_ofset'", "c.yaml:2"});
  check("camera: {width: 240, height: 180, fx: 200, fy: 200, cx: 120, cy: 90, k1: 0}\n", {"unknown key 'camera.k1'"});
  check("cam: {}\n", {"missing key 'camera'"});
  check(cam + "cam: {}\n", {"unknown key 'cam'"});
  check("camera: {width: 240, height: 180, fx: abc, fy: 200, cx: 120, cy: 90}\n", {"key 'camera.fx'", "number"});
  check("camera: {width: 24.5, height: 180, fx: 200, fy: 200, cx: 120, cy: 90}\n", {"key 'camera.width'", "integer"});
  check("camera: {width: 240, height: 180, fx: [1], fy: 200, cx: 120, cy: 90}\n", {"key 'camera.fx'"});
  check("camera: {width: 240, height: 180, fy: 200, cx: 120, cy: 90}\n", {"missing key 'camera.fx'"});
  check(cam + "imu: {R_cam_imu: [1,0,0, 0,1,0, 0,0]}\n", {"key 'imu.R_cam_imu'", "9 numbers, found 8"});
  check(cam + "imu: {R_cam_imu: [1,0,0, 0,2,0, 0,0,1]}\n", {"key 'imu.R_cam_imu'", "not a rotation"});
  check(cam + "imu: {R_cam_imu: [1,0,0, 0,1,0, 0,0,1], T_cam_imu: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}\n",
        {"not both"});
  check(cam + "body: {T_body_cam: [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,0,0,1]}\n", {"body.T_body_cam", "last row"});
  check("camera: {width: 240, height: 180, fx: 200, fy: 200, cx: 120, cy: 90, distortion_model: kb4}\n",
        {"camera.distortion_model", "kb4"});
  check("camera: {width: 240, height: 180, fx: 200, fy: 200, cx: 120, cy: 90, distortion_model: equidistant, "
        "distortion: [1, 2, 3]}\n",
        {"camera.distortion", "found 3"});
  check("camera: {width: 240, height: 180, fx: -200, fy: 200, cx: 120, cy: 90}\n", {"key 'camera.fx'", "must be > 0"});
  check("camera: [1, 2\n", {"YAML syntax"});
  check("- 1\n- 2\n", {"expected a map"});
  EXPECT_THROW(loadCalibrationYaml(d.file("missing.yaml")), celc::ConfigError);
}

TEST(IoCalibration, CalibTxt) {
  TempDir d;
  celc::test::writeBytes(d.file("calib.txt"),
                            "199.092366542 198.82882047 132.192071378 110.712660011 -0.368436311798 "
                            "0.150947243557 -0.000296130534385 -0.000759431726241 0.0\r\n");
  const Calibration c = loadCalibration(d.file("calib.txt"));
  EXPECT_EQ(c.camera.width, 240);
  EXPECT_EQ(c.camera.distortion, DistortionModel::RadTan);
  EXPECT_DOUBLE_EQ(c.camera.coeffs[1], 0.150947243557);
  EXPECT_DOUBLE_EQ(c.camera.coeffs[4], 0.0);
  celc::test::writeBytes(d.file("pin.txt"), "200 200 120 90\n");
  EXPECT_EQ(loadCalibTxt(d.file("pin.txt"), 240, 180).camera.distortion, DistortionModel::None);
  celc::test::writeBytes(d.file("bad.txt"), "200 200 120\n");
  EXPECT_IO_ERROR(loadCalibTxt(d.file("bad.txt")), "bad.txt: line 1", "found 3");
  celc::test::writeBytes(d.file("nan.txt"), "200 200 x 90\n");
  EXPECT_IO_ERROR(loadCalibTxt(d.file("nan.txt")), "line 1", "non-numeric", "column 3");
  celc::test::writeBytes(d.file("empty.txt"), "# nothing\n");
  EXPECT_IO_ERROR(loadCalibTxt(d.file("empty.txt")), "no calibration line");
}

TEST(IoCalibrationConformance, EcdCalibTxt) {
  const std::string p = celc::test::sharedData("ecd_slices/boxes_translation/calib.txt");
  SKIP_IF_NO_SHARED(p);
  const Calibration c = loadCalibration(p);
  EXPECT_EQ(c.camera.distortion, DistortionModel::RadTan);
  EXPECT_GT(c.camera.fx, 150.0);
  EXPECT_LT(c.camera.fx, 250.0);
  EXPECT_TRUE(c.camera.validate().empty());
}

// ---- malformed and hostile inputs (docs/robustness.md's table) -------------------

// ---- sizes from headers bounded before allocation -------------------------------

TEST(IoRobustness, CalibrationYamlHugeSensorRefusedWithFileAndKey) {
  TempDir d;
  for (const char* size : {"65535", "4097"}) {
    writeBytes(d.file("c.yaml"), std::string("camera:\n  width: ") + size + "\n  height: 180\n  fx: 200\n  fy: 200\n"
                                 "  cx: 120\n  cy: 90\n");
    try {
      (void)loadCalibration(d.file("c.yaml"));
      ADD_FAILURE() << "accepted width " << size;
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("c.yaml"), std::string::npos) << m;
      EXPECT_NE(m.find("width"), std::string::npos) << m;
      EXPECT_NE(m.find("4096"), std::string::npos) << m;
    }
  }
}

// ---- found by fuzz_calibration: a YAML syntax error quoting a raw byte ------------

TEST(IoRobustness, CalibrationYamlSyntaxErrorIsPrintable) {
  TempDir d;
  writeBytes(d.file("c.yaml"), std::string("camera: \"\\\xcd\xdf\"\n"));  // an unknown escape: a byte >= 0x80
  try {
    (void)loadCalibration(d.file("c.yaml"));
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    expectPrintable(m);
    EXPECT_NE(m.find("c.yaml:1"), std::string::npos) << m;
  }
}

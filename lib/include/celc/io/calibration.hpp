#pragma once
/// \file calibration.hpp
/// Camera / IMU / body calibration (schema: docs/formats.md).
///  - camera intrinsics and distortion -> celc::CameraModel;
///  - R_cam_imu (or the rotation of T_cam_imu): maps IMU-frame vectors to the
///    camera frame, w_cam = R_cam_imu * w_imu;
///  - time_offset [s]: t_cam = t_imu + time_offset;
///  - T_body_cam: pose of the camera in the ground-truth body frame (identity by default).
/// Also loads the RPG `calib.txt` (`fx fy cx cy k1 k2 p1 p2 k3`, radial-tangential).
#include <string>

#include "celc/geometry/camera.hpp"
#include "celc/io/event_reader.hpp"

namespace celc {

struct Calibration {
  CameraModel camera;
  Mat3 R_cam_imu = Mat3::Identity();
  double time_offset = 0.0;  ///< [s], t_cam = t_imu + time_offset
  Eigen::Matrix4d T_body_cam = Eigen::Matrix4d::Identity();
  bool has_imu = false;   ///< the file had an `imu` section
  bool has_body = false;  ///< the file had a `body` section
};

/// Loads a calibration YAML (docs/formats.md). Unknown keys, wrong types,
/// wrong list lengths, non-orthonormal rotations and invalid intrinsics are
/// ConfigErrors naming the file, the line and the key.
Calibration loadCalibrationYaml(const std::string& path);

/// Loads an RPG calib.txt (one line `fx fy cx cy k1 k2 p1 p2 k3`; 4 values =
/// no distortion). The file holds no resolution: width/height are given
/// (DAVIS240C 240x180 by default).
Calibration loadCalibTxt(const std::string& path, int width = 240, int height = 180);

/// A ROS bag: the camera of its sensor_msgs/CameraInfo. Otherwise by
/// extension: .yaml / .yml -> YAML, otherwise calib.txt.
Calibration loadCalibration(const std::string& path, int width = 240, int height = 180);

}  // namespace celc

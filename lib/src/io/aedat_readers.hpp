#pragma once
// Private: constructors of the binary readers (AEDAT, ROS bag, HDF5) (the factory in event_reader.cpp uses them).
#include <cstdint>
#include <memory>
#include <string>

#include "celc/geometry/camera.hpp"
#include "celc/io/event_reader.hpp"

namespace celc::detail {
std::unique_ptr<EventReader> openAedat2(const std::string& path, const ReaderOptions& o);
std::unique_ptr<EventReader> openAedat31(const std::string& path, const ReaderOptions& o);
std::unique_ptr<EventReader> openAedat4(const std::string& path, const ReaderOptions& o);
std::unique_ptr<EventReader> openRosBag(const std::string& path, const ReaderOptions& o);  ///< rosbag_reader.cpp
/// The camera of a bag's first sensor_msgs/CameraInfo (plumb_bob -> radtan,
/// equidistant -> equidistant); false when the bag has none. Throws IoError.
bool bagCameraModel(const std::string& path, CameraModel& camera);
std::unique_ptr<EventReader> openHdf5(const std::string& path, const ReaderOptions& o);    ///< hdf5_reader.cpp
/// The file address of the object a hard link of an HDF5 file points to (tests
/// patch headers with it). Throws IoError.
std::uint64_t hdf5LinkAddress(const std::string& path, const std::string& link);
}  // namespace celc::detail

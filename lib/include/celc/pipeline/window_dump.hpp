#pragma once
/// \file window_dump.hpp
/// One window of `celc run` written out for `celc solve` (`celc run
/// --dump-windows DIR`): its events with the pipeline's cluster labels and
/// the gyroscope samples its motion model integrated, so that the window can
/// be studied alone (another method, option or seed; Python's celc.solve)
/// and `celc solve` gives the run's answers on it.
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/types.hpp"
#include "celc/io/imu_window.hpp"

namespace celc {

/// What the reproduction command names besides the window's own files.
struct WindowDumpContext {
  std::string dir;          ///< output folder (exists)
  std::string program = "celc";  ///< the executable the command calls
  std::string calib;        ///< the run's calibration file
  std::string config;       ///< the run's configuration file (OUTDIR/config.yaml)
  std::uint64_t seed = 0;   ///< the run's seed (a window draws with seed + index)
  bool gyro_integrated = true;  ///< motion.model; false: constant twist at the mean rate
};

/// Writes, for window `index` starting at t0 [s]:
///  - DIR/window_NNNNN.csv: `t,x,y,cluster` per event of the window, in the
///    window's order (s, px; cluster = the clustering's index, -1 =
///    unclustered): `celc solve`'s input;
///  - DIR/window_NNNNN_gyro.csv: `t,wx,wy,wz` [s, rad/s, camera frame, bias
///    subtracted], the samples of the window's motion model (when gyro has them);
///  - DIR/window_NNNNN.sh: the `celc solve` command that reproduces the
///    run's answers (its configuration, seed and reference time t0).
/// Numbers are printed with 17 significant digits. Throws std::runtime_error
/// naming the file when one cannot be written.
void dumpWindow(const WindowDumpContext& context, std::uint64_t index, double t0, const std::vector<Event>& events,
                const std::vector<int>& labels, const GyroWindow* gyro, const Vec3& omega);

}  // namespace celc

// One window of `celc run` as `celc solve`'s input.
#include "celc/pipeline/window_dump.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace celc {

namespace {

std::ofstream openFor(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  return out;
}

void closeChecked(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::string number(double x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

// A path as one shell word.
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

void dumpWindow(const WindowDumpContext& context, std::uint64_t index, double t0, const std::vector<Event>& events,
                const std::vector<int>& labels, const GyroWindow* gyro, const Vec3& omega) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "window_%05llu", static_cast<unsigned long long>(index));
  const std::string base = (std::filesystem::path(context.dir) / stem).string();
  const std::string events_path = base + ".csv", gyro_path = base + "_gyro.csv", command_path = base + ".sh";
  {
    std::ofstream out = openFor(events_path);
    out << "t,x,y,cluster\n";
    for (std::size_t i = 0; i < events.size(); ++i)
      out << number(events[i].t) << ',' << number(events[i].x) << ',' << number(events[i].y) << ','
          << (i < labels.size() ? labels[i] : -1) << '\n';
    closeChecked(out, events_path);
  }
  const bool with_gyro = gyro && gyro->ok();
  if (with_gyro) {
    std::ofstream out = openFor(gyro_path);
    out << "t,wx,wy,wz\n";
    for (std::size_t i = 0; i < gyro->times.size(); ++i)
      out << number(gyro->times[i]) << ',' << number(gyro->rates[i].x()) << ',' << number(gyro->rates[i].y())
          << ',' << number(gyro->rates[i].z()) << '\n';
    closeChecked(out, gyro_path);
  }
  std::ofstream out = openFor(command_path);
  out << "#!/bin/sh\n# celc run's window " << index << ", as `celc solve` reproduces it.\n"
      << quoted(context.program) << " solve " << quoted(events_path);
  if (with_gyro && context.gyro_integrated) out << " --gyro " << quoted(gyro_path);
  else out << " --omega " << number(omega.x()) << ',' << number(omega.y()) << ',' << number(omega.z());
  out << " --calib " << quoted(context.calib) << " -c " << quoted(context.config) << " --set seed="
      << context.seed + index << " --t-ref " << number(t0) << " \"$@\"\n";
  closeChecked(out, command_path);
}

}  // namespace celc

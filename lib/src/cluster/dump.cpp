#include "celc/cluster/dump.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include <png.h>

namespace celc {
namespace {

/// Writes an 8-bit BGR image as PNG with libpng's simplified API (OpenCV's
/// imgcodecs would load 118 more shared libraries at every start of celc).
void writePng(const std::string& path, const cv::Mat& bgr) {
  if (bgr.type() != CV_8UC3) throw std::runtime_error(path + ": cannot write PNG: not an 8-bit BGR image");
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(bgr.cols);
  image.height = static_cast<png_uint_32>(bgr.rows);
  image.format = PNG_FORMAT_BGR;
  const int ok = png_image_write_to_file(&image, path.c_str(), 0, bgr.data, static_cast<png_int_32>(bgr.step[0]),
                                         nullptr);
  const std::string why = image.message;
  png_image_free(&image);
  if (!ok) throw std::runtime_error(path + ": cannot write PNG: " + why);
}

cv::Scalar clusterColour(int id) {
  // Hues spread by the golden angle; full saturation and value (BGR out).
  const double h = std::fmod(id * 137.508, 360.0) / 2.0;  // OpenCV hue range 0..180
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(h, 230, 255)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

struct Segment {
  Vec2 a, b;   ///< end points [px]
  double t;    ///< [s]
  bool ok = false;
};

// The fitted line of events in [f.t_begin, f.t_end) as a segment over their extent.
Segment segmentOf(const FittedLine& f, const std::vector<double>& times,
                  const std::vector<Vec3>& pts) {
  Segment s;
  if (f.status != LineFitStatus::Ok) return s;
  const Vec3& n = f.line.normal;
  const double nn = n.head<2>().norm();
  if (!(nn > 1e-12)) return s;
  const Vec2 nrm = n.head<2>() / nn, dir(-nrm.y(), nrm.x());
  const Vec2 p0 = -nrm * n.z() / nn;  // closest point of the line to the origin
  double lo = 1e300, hi = -1e300;
  for (size_t i = 0; i < times.size(); ++i) {
    if (times[i] < f.t_begin || times[i] >= f.t_end) continue;
    const double u = dir.dot(pts[i].head<2>() - p0);
    lo = std::min(lo, u), hi = std::max(hi, u);
  }
  if (!(hi >= lo)) return s;
  s.a = p0 + dir * lo;
  s.b = p0 + dir * hi;
  s.t = f.line.t;
  s.ok = true;
  return s;
}

}  // namespace

void writeClusterPng(const std::string& path, const std::vector<Event>& events,
                     const ClusterResult& result, const ClusterDumpOptions& opt) {
  int w = opt.width, h = opt.height;
  double t0 = 1e300, t1 = -1e300;
  for (const Event& e : events) {
    if (!std::isfinite(e.t) || !std::isfinite(e.x) || !std::isfinite(e.y)) continue;
    if (opt.width <= 0) w = std::max(w, static_cast<int>(e.x) + 1);
    if (opt.height <= 0) h = std::max(h, static_cast<int>(e.y) + 1);
    t0 = std::min(t0, e.t), t1 = std::max(t1, e.t);
  }
  w = std::clamp(w, 1, 4096), h = std::clamp(h, 1, 4096);
  const int s = std::clamp(opt.scale, 1, 8);
  const int W = w * s, H = h * s, margin = 24;
  cv::Mat img(H + margin, 2 * W + 10, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat xy = img(cv::Rect(0, margin, W, H)), xt = img(cv::Rect(W + 10, margin, W, H));
  const double span = t1 > t0 ? t1 - t0 : 1.0;
  auto rowOf = [&](double t) { return (t - t0) / span * (H - 1); };
  const bool labelled = result.labels.size() == events.size();
  // Noise first, then clusters on top.
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < events.size(); ++i) {
      const Event& e = events[i];
      if (!std::isfinite(e.t) || !(e.x >= 0.0f) || !(e.y >= 0.0f) || e.x >= w || e.y >= h) continue;
      const int l = labelled ? result.labels[i] : -1;
      if ((pass == 0) != (l < 0)) continue;
      const cv::Scalar c = l < 0 ? cv::Scalar(70, 70, 70) : clusterColour(l);
      const int x = static_cast<int>(e.x) * s, y = static_cast<int>(e.y) * s;
      cv::rectangle(xy, cv::Rect(x, y, s, s), c, cv::FILLED);
      const int r = std::clamp(static_cast<int>(rowOf(e.t)), 0, H - 1);
      xt.at<cv::Vec3b>(r, std::min(W - 1, x)) = cv::Vec3b(static_cast<uchar>(c[0]), static_cast<uchar>(c[1]),
                                                         static_cast<uchar>(c[2]));
    }
  }
  // Fitted l1 / l3 per cluster, in pixel coordinates.
  if (labelled) {
    std::vector<std::vector<int>> members(result.clusters.size());
    for (size_t i = 0; i < events.size(); ++i)
      if (result.labels[i] >= 0 && static_cast<size_t>(result.labels[i]) < members.size())
        members[result.labels[i]].push_back(static_cast<int>(i));
    for (size_t k = 0; k < members.size(); ++k) {
      auto& idx = members[k];
      std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return events[a].t < events[b].t; });
      std::vector<double> times;
      std::vector<Vec3> pts;
      for (int i : idx) times.push_back(events[i].t), pts.emplace_back(events[i].x, events[i].y, 1.0);
      const ClusterLines cl = fitClusterLines(times, pts, 1.0, opt.lines);
      const cv::Scalar colour = clusterColour(static_cast<int>(k));
      const Segment l1 = segmentOf(cl.l1, times, pts), l3 = segmentOf(cl.l3, times, pts);
      auto P = [&](const Vec2& p) { return cv::Point(static_cast<int>((p.x() + 0.5) * s), static_cast<int>((p.y() + 0.5) * s)); };
      auto T = [&](const Vec2& p, double t) {
        return cv::Point(static_cast<int>((p.x() + 0.5) * s), static_cast<int>(rowOf(t)));
      };
      // l1 white, l3 black, each over a black / white halo to stand out on any colour.
      if (l3.ok) {
        cv::line(xy, P(l3.a), P(l3.b), cv::Scalar(255, 255, 255), s + 2, cv::LINE_AA);
        cv::line(xy, P(l3.a), P(l3.b), cv::Scalar(0, 0, 0), s, cv::LINE_AA);
        cv::line(xt, T(l3.a, l3.t), T(l3.b, l3.t), colour, 3, cv::LINE_AA);
      }
      if (l1.ok) {
        cv::line(xy, P(l1.a), P(l1.b), cv::Scalar(0, 0, 0), s + 2, cv::LINE_AA);
        cv::line(xy, P(l1.a), P(l1.b), cv::Scalar(255, 255, 255), s, cv::LINE_AA);
        cv::line(xt, T(l1.a, l1.t), T(l1.b, l1.t), colour, 3, cv::LINE_AA);
      }
    }
  }
  char info[256];
  std::snprintf(info, sizeof info, "%s  %zu events  %zu clusters  c=%.0f px/s  | x-y: l1 white, l3 black | x-t (t down, %.1f ms)",
                opt.title.c_str(), events.size(), result.clusters.size(), result.c_px_per_s,
                (t1 > t0 ? t1 - t0 : 0.0) * 1e3);
  cv::putText(img, info, cv::Point(4, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  writePng(path, img);
}

void writeClusterPly(const std::string& path, const std::vector<Event>& events,
                     const ClusterResult& result) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  const bool labelled = result.labels.size() == events.size();
  size_t n = 0;
  for (const Event& e : events) n += std::isfinite(e.t) && std::isfinite(e.x) && std::isfinite(e.y);
  out << "ply\nformat ascii 1.0\ncomment celc clustered window: z = c (t - t0) [px], c = "
      << result.c_px_per_s << " px/s, t0 = " << result.t0 << " s\n"
      << "element vertex " << n << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property double t\nproperty int label\nend_header\n";
  char line[128];
  for (size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    if (!(std::isfinite(e.t) && std::isfinite(e.x) && std::isfinite(e.y))) continue;
    std::snprintf(line, sizeof line, "%g %g %.4f %.9f %d\n", e.x, e.y,
                  result.c_px_per_s * (e.t - result.t0), e.t, labelled ? result.labels[i] : -1);
    out << line;
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace celc

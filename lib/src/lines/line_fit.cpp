#include "celc/lines/line_fit.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "moving_line.hpp"

namespace celc {

std::string toString(LineModel model) { return model == LineModel::Moving ? "moving" : "static"; }

std::string LineFitOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (model == LineModel::Moving && min_events < 6)
    e += "min_events: must be >= 6 with the moving line model (five degrees of freedom), got " +
         std::to_string(min_events) + "; ";
  return e;
}

std::string toString(LineFitStatus status) {
  switch (status) {
    case LineFitStatus::Ok: return "ok";
    case LineFitStatus::TooFewEvents: return "too_few_events";
    case LineFitStatus::PoorFit: return "poor_fit";
  }
  return "unknown";
}

FittedLine fitLine(const std::vector<Vec3>& bearings, const std::vector<double>& times,
                   double focal_px) {
  FittedLine out;
  out.n_events = static_cast<int>(bearings.size());
  if (bearings.size() < 2) return out;
  // Fit in pixel units around the centroid (keeps float precision).
  Vec2 centroid = Vec2::Zero();
  for (const auto& b : bearings) centroid += b.head<2>();
  centroid /= static_cast<double>(bearings.size());
  std::vector<cv::Point2f> pts;
  pts.reserve(bearings.size());
  for (const auto& b : bearings) {
    const Vec2 p = (b.head<2>() - centroid) * focal_px;
    pts.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  cv::Vec4f fit;
  cv::fitLine(pts, fit, cv::DIST_HUBER, 0.0, 0.01, 0.01);
  const Vec2 dir(fit[0], fit[1]);
  const Vec2 p0 = centroid + Vec2(fit[2], fit[3]) / focal_px;
  // Plane through the centre and the line: n = (p0, 1) x (dir, 0).
  out.line.normal = Vec3(p0.x(), p0.y(), 1.0).cross(Vec3(dir.x(), dir.y(), 0.0)).normalized();
  double t_sum = 0.0;
  for (double t : times) t_sum += t;
  out.line.t = times.empty() ? 0.0 : t_sum / static_cast<double>(times.size());
  if (!times.empty()) {
    out.t_first = *std::min_element(times.begin(), times.end());
    out.t_last = *std::max_element(times.begin(), times.end());
  }
  // Residuals and extent in pixels.
  const Vec2 nrm(-dir.y(), dir.x());
  double ss = 0.0, lo = 1e300, hi = -1e300;
  for (const auto& p : pts) {
    const Vec2 q = Vec2(p.x, p.y) - Vec2(fit[2], fit[3]);
    ss += std::pow(nrm.dot(q), 2);
    lo = std::min(lo, dir.dot(q));
    hi = std::max(hi, dir.dot(q));
  }
  out.rms_px = std::sqrt(ss / static_cast<double>(pts.size()));
  out.length_px = hi - lo;
  out.status = LineFitStatus::Ok;
  out.rms_ok = true;  // no thresholds here; fitClusterLines applies LineFitOptions
  out.length_ok = true;
  // Non-finite input (NaN bearings) must not pass as a line.
  if (!out.line.normal.allFinite() || !std::isfinite(out.rms_px)) {
    out.status = LineFitStatus::PoorFit;
    out.rms_ok = out.length_ok = false;
  }
  return out;
}

namespace {
void applyThresholds(FittedLine& f, const LineFitOptions& opt) {
  if (f.status != LineFitStatus::Ok) return;
  f.rms_ok = f.rms_px <= opt.max_rms_px;
  f.length_ok = f.length_px >= opt.min_length_px;
  if (!f.rms_ok || !f.length_ok) f.status = LineFitStatus::PoorFit;
}

// Static model: fits the events with times in [t0, t1). While the interval holds fewer than
// min_events it slides toward `centre` by half its length; it stops sliding
// once it reaches the centre.
FittedLine fitInterval(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                       double t0, double t1, double centre, double focal_px,
                       const LineFitOptions& opt) {
  const double step = 0.5 * (t1 - t0) * (centre > t0 ? 1.0 : -1.0);
  bool slid = false;
  // Bounded: the distance to the centre halves no slower than by `step`, but
  // with huge timestamps t0 + step may round to t0 (the cap stops that).
  for (int iter = 0;; ++iter) {
    const auto b = std::lower_bound(times.begin(), times.end(), t0) - times.begin();
    const auto e = std::lower_bound(times.begin(), times.end(), t1) - times.begin();
    const bool reached_centre = t0 <= centre && centre <= t1;
    if (e - b >= opt.min_events || reached_centre || step == 0.0 || iter >= 200 ||
        t0 + step == t0) {
      FittedLine f;
      if (e - b >= opt.min_events) {
        f = fitLine(std::vector<Vec3>(bearings.begin() + b, bearings.begin() + e),
                    std::vector<double>(times.begin() + b, times.begin() + e), focal_px);
        applyThresholds(f, opt);
      } else {
        f.n_events = static_cast<int>(e - b);
      }
      f.t_begin = t0;
      f.t_end = t1;
      f.slid = slid;
      return f;
    }
    t0 += step;
    t1 += step;
    slid = true;
  }
}
// Moving model: each interval starts at `len` and grows by half while it
// holds fewer than min_events events or spans less than target_length_px,
// up to half the cluster's duration, or three quarters while it holds too
// few events (sparse clusters: l1 and l3 then share events, but their mean
// times still differ by a quarter of the duration). `where` < 0: at the start, > 0: at the
// end, 0: centred on the middle. The line is evaluated at the mean time of
// the interval's events, where the fitted n(t) is the data's own average: at
// the interval's edge a motion of a pixel or two, seen through integer pixel
// positions as a staircase, would tilt the fitted slope and bias the line.
FittedLine fitGrowing(const std::vector<double>& times, const detail::DerotatedEvents& ev,
                      double len, int where, double focal_px, const MotionModel* motion,
                      const LineFitOptions& opt) {
  const double ts = times.front(), te = times.back(), tm = 0.5 * (ts + te);
  const double half = 0.5 * (te - ts), most = 0.75 * (te - ts);
  len = std::min(len, half);
  FittedLine best;
  bool grown = false;
  for (int iter = 0; iter < 64; ++iter) {
    const double t0 = where < 0 ? ts : where > 0 ? te - len : tm - 0.5 * len;
    const double t1 = where < 0 ? ts + len : where > 0 ? te : tm + 0.5 * len;
    // Closed at both ends: the first / last event belongs to its interval.
    const auto b = static_cast<std::size_t>(std::lower_bound(times.begin(), times.end(), t0) - times.begin());
    const auto e = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t1) - times.begin());
    FittedLine f;
    if (e >= b + static_cast<std::size_t>(opt.min_events)) {
      double t_line = 0.0;
      for (std::size_t j = b; j < e; ++j) t_line += times[j] - ts;
      t_line = ts + t_line / static_cast<double>(e - b);
      const Mat3 R_line = motion ? motion->rotation(t_line) : Mat3::Identity();
      f = detail::fitMovingLine(times, ev, b, e, t_line, R_line, focal_px);
    } else {
      f.n_events = static_cast<int>(e - b);
    }
    f.t_begin = t0;
    f.t_end = t1;
    f.slid = grown;
    best = f;
    const bool enough = f.status == LineFitStatus::Ok && f.length_px >= opt.target_length_px;
    const double cap = f.n_events < opt.min_events ? most : half;
    if (enough || len >= cap) break;
    len = std::min(cap, 1.5 * len);
    grown = true;
  }
  applyThresholds(best, opt);
  return best;
}
}  // namespace

ClusterLines fitClusterLines(const std::vector<double>& times, const std::vector<Vec3>& bearings,
                             double focal_px, const LineFitOptions& opt, const MotionModel* motion) {
  ClusterLines out;
  if (times.size() < 2 || times.size() != bearings.size()) return out;
  if (!(focal_px > 0.0) || !std::is_sorted(times.begin(), times.end())) return out;
  const double ts = times.front(), te = times.back(), tm = 0.5 * (ts + te);
  if (opt.model == LineModel::Moving) {
    const double len = opt.interval_fraction > 0.0 ? opt.interval_fraction * (te - ts) : opt.interval_s;
    if (!(len > 0.0) || !(te > ts)) return out;
    const detail::DerotatedEvents ev = detail::derotate(times, bearings, motion);
    out.l1 = fitGrowing(times, ev, len, -1, focal_px, motion, opt);
    out.l3 = fitGrowing(times, ev, len, +1, focal_px, motion, opt);
    out.l2 = fitGrowing(times, ev, len, 0, focal_px, motion, opt);
    return out;
  }
  const double len = opt.interval_fraction > 0.0 ? opt.interval_fraction * (te - ts)
                                                 : std::min(opt.interval_s, 0.5 * (te - ts));
  if (!(len > 0.0)) return out;
  // The last interval is closed at te: nudge its end past the last timestamp.
  const double te_open = std::nextafter(te, 1e300);
  out.l1 = fitInterval(times, bearings, ts, ts + len, tm, focal_px, opt);
  out.l3 = fitInterval(times, bearings, te_open - len, te_open, tm, focal_px, opt);
  out.l2 = fitInterval(times, bearings, tm - 0.5 * len, tm + 0.5 * len, tm, focal_px, opt);
  return out;
}

bool attachFittedLines(ClusterObservation& cluster, double focal_px, const LineFitOptions& options,
                       const MotionModel* motion) {
  const ClusterLines lines = fitClusterLines(cluster.times, cluster.bearings, focal_px, options, motion);
  cluster.has_lines = lines.ok();
  if (!lines.ok()) return false;
  cluster.l1 = lines.l1.line;
  cluster.l3 = lines.l3.line;
  cluster.has_l2 = lines.l2.status == LineFitStatus::Ok;
  if (cluster.has_l2) cluster.l2 = lines.l2.line;
  return true;
}

}  // namespace celc

#include "celc/sim/render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "celc/core/parallel.hpp"

namespace celc {

namespace {
constexpr int64_t kNever = std::numeric_limits<int64_t>::min();
constexpr size_t kStepsPerChunk = 64;
constexpr double kAheadDt = 1e-4;                ///< [s] for the texture velocity at each pixel
constexpr double kMaxSkip = 0.05;                ///< [s] longest time a pixel goes without shading
constexpr int64_t kMaxPixels = 4 * 1024 * 1024;  ///< ~60 B of state per pixel

inline uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
/// Uniform in (0, 1].
inline double uniform01(uint64_t& state) {
  return (static_cast<double>(splitmix64(state) >> 11) + 1.0) * (1.0 / 9007199254740992.0);
}
/// Runs f(band, y0, y1) on `threads` bands of rows [0, H), one band per thread.
/// The bands depend on H and the thread count only, so does the output.
template <typename F>
void forRowBands(int H, int threads, const F& f) {
  threads = std::max(1, std::min(threads, H));
  parallelFor(static_cast<std::size_t>(threads), threads, [&](std::size_t band) {
    const int b = static_cast<int>(band);
    f(b, H * b / threads, H * (b + 1) / threads);
  });
}
inline bool eventLess(const SimEvent& a, const SimEvent& b) {
  if (a.t_us != b.t_us) return a.t_us < b.t_us;
  if (a.y != b.y) return a.y < b.y;
  return a.x < b.x;
}
}  // namespace

std::string RenderOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (min_step > max_step) e += "min_step: must be <= max_step; ";
  return e;
}

std::vector<double> pixelBearings(const CameraModel& camera) {
  std::vector<double> b(2 * static_cast<size_t>(camera.width) * camera.height);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Vec3 d = camera.bearing(Vec2(x, y));
      const size_t i = static_cast<size_t>(y) * camera.width + x;
      b[2 * i] = d.x();
      b[2 * i + 1] = d.y();
    }
  return b;
}

std::vector<float> renderLogImage(const Scene& scene, const CameraModel& camera,
                                  const RigidPose& T_world_cam, double log_eps,
                                  double smoothing_px) {
  std::vector<CameraPlane> cp;
  for (const auto& pl : scene.planes) cp.push_back(toCameraFrame(pl, T_world_cam));
  const std::vector<double> b = pixelBearings(camera);
  std::vector<float> L(b.size() / 2);
  for (size_t i = 0; i < L.size(); ++i)
    L[i] = std::log(
        static_cast<float>(log_eps) +
        shadePixel(scene, cp, b[2 * i], b[2 * i + 1], camera.fx, camera.fy, smoothing_px, false)
            .intensity);  // the simulator's own float formula
  return L;
}

struct RenderEventSimulator::Impl {
  Scene scene;
  CameraModel camera;
  Trajectory trajectory;
  RenderOptions opt;
  double t = 0.0;
  double speed_now = -1.0;  ///< image speed at t [px/s] (< 0: not computed yet)
  RenderStats stats;
  std::vector<double> bearings;
  std::vector<float> L, ref, cp, cm;
  std::vector<float> I_last;  ///< intensity of the last shading (L = log(eps + I_last))
  std::vector<int64_t> last_us;
  std::vector<double> skip_until;  ///< the pixel needs no shading before this time [s]
  std::vector<double> wake;        ///< min(skip_until, noise_next)
  std::vector<double> noise_next;
  std::vector<uint64_t> rng;
  std::vector<Vec2> speed_samples;   ///< pixels where the image speed is measured
  std::vector<Vec3> speed_bearings;  ///< their bearings

  Impl(const Scene& s, const CameraModel& c, const Trajectory& tr, const RenderOptions& o)
      : scene(s), camera(c), trajectory(tr), opt(o) {}

  std::vector<CameraPlane> planesAt(double time) const {
    const RigidPose T = trajectory.pose(time);
    std::vector<CameraPlane> out;
    out.reserve(scene.planes.size());
    for (const auto& pl : scene.planes) out.push_back(toCameraFrame(pl, T));
    return out;
  }

  double speed(double time) const {
    const double h = 1e-4;
    const RigidPose T0 = trajectory.pose(time), T1 = trajectory.pose(time + h);
    const std::vector<CameraPlane> cps = planesAt(time);
    double vmax = 0.0;
    for (const Vec3& d : speed_bearings) {
      Vec3 X;
      if (frontHit(scene, cps, d.x(), d.y(), T0, X) < 0) continue;
      const Vec3 c0 = T0.R.transpose() * (X - T0.p), c1 = T1.R.transpose() * (X - T1.p);
      if (!(c0.z() > 1e-6) || !(c1.z() > 1e-6)) continue;
      vmax = std::max(vmax, (camera.project(c1) - camera.project(c0)).norm() / h);
    }
    return vmax;
  }

  struct BandOutput {
    std::vector<std::vector<SimEvent>> events;  ///< per step of the chunk
    int64_t on = 0, off = 0, noise = 0, dropped = 0, shaded = 0;
  };

  /// One chunk of render steps, shared by the bands.
  struct Chunk {
    double t_begin = 0.0;
    std::vector<double> steps;                     ///< render times
    std::vector<std::vector<CameraPlane>> planes;  ///< planes at each render time
    std::vector<std::vector<CameraPlane>> ahead;   ///< ... kAheadDt later
    std::vector<double> speed;                     ///< largest image speed [px/s] at each
    std::vector<double> skip_cap;                  ///< longest skip [s] from each render
  };

  void runBand(int y0, int y1, const Chunk& chunk, BandOutput& out) {
    const std::vector<double>& steps = chunk.steps;
    const int W = camera.width;
    const int64_t refr_us = std::llround(opt.refractory * 1e6);
    const double noise_rate = opt.noise_rate;
    struct Crossing {
      double t;
      bool on;
      bool noise;
    };
    std::vector<Crossing> cross;
    // Raw pointers: the compiler cannot prove that the vectors do not alias.
    double* const until_p = skip_until.data();
    double* const wake_p = wake.data();
    const double* const noise_p = noise_next.data();
    const double* const bear_p = bearings.data();
    float* const L_p = L.data();
    float* const I_p = I_last.data();
    const double fx = camera.fx, fy = camera.fy, smoothing = opt.smoothing_px;
    const float eps = static_cast<float>(opt.log_eps);
    const bool skip_static = opt.skip_static;
    out.events.assign(steps.size(), {});
    // Tiles of a few rows run through all the steps of the chunk, so that their
    // per-pixel state stays in cache.
    constexpr int kTileRows = 4;
    for (int ty = y0; ty < y1; ty += kTileRows) {
      const int ty1 = std::min(y1, ty + kTileRows);
      double ta = chunk.t_begin;
      for (size_t s = 0; s < steps.size(); ++s) {
        const double tb = steps[s];
        const double dt = tb - ta;
        const std::vector<CameraPlane>& cps = chunk.planes[s];
        const std::vector<CameraPlane>* ahead = &chunk.ahead[s];
        // Edges move at most ~max_step_px per step anywhere (the step is set from
        // the largest speed sampled on a 12 x 9 grid of pixels); 1.5x margin.
        const double global_speed = 1.5 * chunk.speed[s];
        const double cap = chunk.skip_cap[s];
        std::vector<SimEvent>& step_events = out.events[s];
        for (int y = ty; y < ty1; ++y) {
          for (int x = 0; x < W; ++x) {
            const size_t i = static_cast<size_t>(y) * W + x;
            // Fast path: a pixel no edge can reach yet and no noise event due.
            if (tb < wake_p[i]) continue;
            const bool shade = tb >= until_p[i];
            const double bx = bear_p[2 * i], by = bear_p[2 * i + 1];
            const float L0 = L_p[i];
            float L1 = L0;
            if (shade) {
              const PixelSample ps =
                  shadePixel(scene, cps, bx, by, fx, fy, smoothing, false, ahead, kAheadDt);
              // Most re-shaded pixels see the very same intensity: skip the log then.
              if (ps.intensity != I_p[i]) {
                I_p[i] = ps.intensity;
                L1 = std::log(eps + ps.intensity);
              }
              ++out.shaded;
              if (skip_static) {
                // Two lower bounds of the time before an edge can reach the pixel:
                // at the texture's own velocity at this pixel (1.5x margin), and
                // at the image's largest speed.
                const double d = ps.free_px - 0.5 * smoothing - 0.25;
                const double t_global = d > 0.0 && global_speed > 0.0 ? d / global_speed : 0.0;
                const double t_skip = std::min(std::max(ps.free_time / 1.5, t_global), cap);
                until_p[i] = tb + t_skip;
              } else {
                until_p[i] = tb;
              }
              wake_p[i] = std::min(until_p[i], noise_p[i]);
            }
            const bool has_noise = noise_rate > 0.0 && noise_p[i] <= tb;
            if (L1 == L0 && !has_noise) continue;
            L_p[i] = L1;
            cross.clear();
            float r = ref[i];
            const double dL = static_cast<double>(L1) - L0;
            if (L1 >= r + cp[i]) {
              while (L1 >= r + cp[i]) {
                r += cp[i];
                cross.push_back({ta + (r - L0) / dL * dt, true, false});
              }
            } else if (L1 <= r - cm[i]) {
              while (L1 <= r - cm[i]) {
                r -= cm[i];
                cross.push_back({ta + (r - L0) / dL * dt, false, false});
              }
            }
            ref[i] = r;
            const size_t n_signal = cross.size();
            if (has_noise) {
              while (noise_next[i] <= tb) {
                const bool on = (splitmix64(rng[i]) >> 63) != 0;
                cross.push_back({noise_next[i], on, true});
                noise_next[i] += -std::log(uniform01(rng[i])) / noise_rate;
              }
              wake_p[i] = std::min(until_p[i], noise_p[i]);
              std::inplace_merge(cross.begin(), cross.begin() + n_signal, cross.end(),
                                 [](const Crossing& a, const Crossing& b) { return a.t < b.t; });
            }
            if (cross.empty()) continue;
            int label = -1;
            if (n_signal > 0)
              label =
                  shadePixel(scene, cps, bx, by, camera.fx, camera.fy, opt.smoothing_px, true).edge;
            for (const Crossing& c : cross) {
              const int64_t tu = std::llround(c.t * 1e6);
              if (refr_us > 0 && last_us[i] != kNever && tu - last_us[i] < refr_us) {
                ++out.dropped;
                continue;
              }
              last_us[i] = tu;
              SimEvent e;
              e.t_us = tu;
              e.x = static_cast<uint16_t>(x);
              e.y = static_cast<uint16_t>(y);
              e.on = c.on;
              e.label = c.noise ? -1 : label;
              step_events.push_back(e);
              if (c.on)
                ++out.on;
              else
                ++out.off;
              if (c.noise) ++out.noise;
            }
          }
        }
        ta = tb;
      }
    }
  }
};

RenderEventSimulator::RenderEventSimulator(const Scene& scene, const CameraModel& camera,
                                           const Trajectory& trajectory,
                                           const RenderOptions& options, double t0)
    : impl_(std::make_unique<Impl>(scene, camera, trajectory, options)) {
  const std::string e1 = options.validate();
  if (!e1.empty()) throw std::invalid_argument("render options: " + e1);
  const std::string e2 = camera.validate();
  if (!e2.empty()) throw std::invalid_argument("camera: " + e2);
  if (camera.width > 4096 || camera.height > 4096 ||
      static_cast<int64_t>(camera.width) * camera.height > kMaxPixels)
    throw std::invalid_argument("camera: at most 4096 px a side and 4 Mpx in all");
  Impl& m = *impl_;
  m.t = t0;
  const size_t n = static_cast<size_t>(camera.width) * camera.height;
  m.bearings.resize(2 * n);
  m.L.resize(n);
  m.I_last.resize(n);
  // Bearings (undistortion) and the first image, in parallel bands of rows.
  {
    std::vector<CameraPlane> cps;
    for (const auto& pl : scene.planes) cps.push_back(toCameraFrame(pl, trajectory.pose(t0)));
    forRowBands(camera.height, options.threads, [&](int, int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < camera.width; ++x) {
          const size_t i = static_cast<size_t>(y) * camera.width + x;
          const Vec3 d = camera.bearing(Vec2(x, y));
          m.bearings[2 * i] = d.x();
          m.bearings[2 * i + 1] = d.y();
          m.I_last[i] = shadePixel(scene, cps, d.x(), d.y(), camera.fx, camera.fy,
                                   options.smoothing_px, false)
                            .intensity;
          m.L[i] = std::log(static_cast<float>(options.log_eps) + m.I_last[i]);
        }
    });
  }
  m.ref.resize(n);
  m.cp.resize(n);
  m.cm.resize(n);
  m.last_us.assign(n, kNever);
  m.skip_until.assign(n, -std::numeric_limits<double>::infinity());
  m.wake.assign(n, -std::numeric_limits<double>::infinity());
  m.noise_next.assign(n, std::numeric_limits<double>::infinity());
  m.rng.resize(n);
  std::mt19937_64 gen(options.seed);
  std::normal_distribution<double> N(0.0, 1.0);
  for (size_t i = 0; i < n; ++i) {
    m.cp[i] =
        static_cast<float>(std::max(0.01, options.contrast_on + options.contrast_sigma * N(gen)));
    m.cm[i] =
        static_cast<float>(std::max(0.01, options.contrast_off + options.contrast_sigma * N(gen)));
    m.rng[i] = options.seed * 0xD1B54A32D192ED03ULL + 0x632BE59BD9B4E019ULL * (i + 1);
    if (options.noise_rate > 0.0)
      m.noise_next[i] = t0 - std::log(uniform01(m.rng[i])) / options.noise_rate;
  }
  m.ref = m.L;
  m.stats.renders = 1;
  const int gx = 12, gy = 9;
  for (int j = 0; j < gy; ++j) {
    for (int i = 0; i < gx; ++i) {
      const int x = static_cast<int>(std::lround((camera.width - 1) * double(i) / (gx - 1)));
      const int y = static_cast<int>(std::lround((camera.height - 1) * double(j) / (gy - 1)));
      const size_t k = static_cast<size_t>(y) * camera.width + x;
      m.speed_samples.emplace_back(x, y);
      m.speed_bearings.emplace_back(m.bearings[2 * k], m.bearings[2 * k + 1], 1.0);
    }
  }
}

RenderEventSimulator::~RenderEventSimulator() = default;

void RenderEventSimulator::advanceTo(double t_end, std::vector<SimEvent>& out) {
  Impl& m = *impl_;
  if (!(t_end > m.t)) return;
  const int H = m.camera.height;
  const int n_threads = std::min(m.opt.threads, H);
  while (m.t < t_end) {
    Impl::Chunk chunk;
    chunk.t_begin = m.t;
    double cur = m.t;
    if (!(m.speed_now >= 0.0)) m.speed_now = m.speed(cur);
    while (cur < t_end && chunk.steps.size() < kStepsPerChunk) {
      const double v = m.speed_now;
      const double dt = std::clamp(v > 0.0 ? m.opt.max_step_px / v : m.opt.max_step, m.opt.min_step,
                                   m.opt.max_step);
      // Avoid a sliver of a step at the end: split the last two steps evenly.
      const double rest = t_end - cur;
      // (1e-9 relative tolerance: slices such as 0.01 - 0.008 are not exactly 0.002).
      double next =
          rest <= dt * (1.0 + 1e-9) ? t_end : (rest < 2.0 * dt ? cur + 0.5 * rest : cur + dt);
      // A render exactly at each jump of a piecewise twist.
      const double brk = m.trajectory.nextBreak(cur);
      if (brk > cur + m.opt.min_step && brk < next) next = brk;
      const double used = next - cur;
      if (m.stats.max_step == 0.0) m.stats.min_step = used;  // first step ever
      m.stats.min_step = std::min(m.stats.min_step, used);
      m.stats.max_step = std::max(m.stats.max_step, used);
      m.speed_now = m.speed(next);
      chunk.steps.push_back(next);
      chunk.planes.push_back(m.planesAt(next));
      chunk.ahead.push_back(m.planesAt(next + kAheadDt));
      chunk.speed.push_back(m.speed_now);
      chunk.skip_cap.push_back(
          std::min({kMaxSkip, m.trajectory.smoothTime(), m.trajectory.nextBreak(next) - next}));
      cur = next;
    }
    const std::vector<double>& steps = chunk.steps;

    std::vector<Impl::BandOutput> bands(n_threads);
    forRowBands(H, n_threads, [&](int b, int y0, int y1) { m.runBand(y0, y1, chunk, bands[b]); });

    // Merge: the events of step s from every band, sorted by (t, y, x). Steps
    // are consecutive in time, so the output stays sorted across steps.
    for (size_t s = 0; s < steps.size(); ++s) {
      const size_t first = out.size();
      for (int b = 0; b < n_threads; ++b) {
        const auto& ev = bands[b].events[s];
        out.insert(out.end(), ev.begin(), ev.end());
      }
      std::stable_sort(out.begin() + first, out.end(), eventLess);
    }
    for (const auto& b : bands) {
      m.stats.events_on += b.on;
      m.stats.events_off += b.off;
      m.stats.events_noise += b.noise;
      m.stats.refractory_dropped += b.dropped;
      m.stats.pixels_shaded += b.shaded;
    }
    m.stats.renders += static_cast<int64_t>(steps.size());
    m.t = cur;
  }
}

double RenderEventSimulator::time() const { return impl_->t; }
const RenderStats& RenderEventSimulator::stats() const { return impl_->stats; }
const std::vector<float>& RenderEventSimulator::logIntensity() const { return impl_->L; }
const std::vector<float>& RenderEventSimulator::reference() const { return impl_->ref; }
const std::vector<float>& RenderEventSimulator::thresholdOn() const { return impl_->cp; }
const std::vector<float>& RenderEventSimulator::thresholdOff() const { return impl_->cm; }
double RenderEventSimulator::imageSpeed(double t) const { return impl_->speed(t); }

}  // namespace celc

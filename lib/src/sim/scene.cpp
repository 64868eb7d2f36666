#include "celc/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "celc/geometry/so3.hpp"

namespace celc {

namespace {
constexpr int kMaxPlanes = 16;

inline double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/// What one plane contributes at a pixel.
struct PlaneShade {
  double intensity = 0.0;
  double coverage = 0.0;  ///< fraction of the pixel covered by the plane's extent
  int edge = -1;
  double edge_px = 1e30;
  double free_px = 0.0;    ///< lower bound of the distance to any edge of the plane [px]
  double free_time = 0.0;  ///< time [s] before an edge can reach the pixel, at the current rates
};

constexpr double kFreeMarginPx = 0.25;  ///< extra margin [px] beyond the ramp half-width
constexpr double kInfTime = 1e30;

/// Time to travel `dist` [px] (less the ramp half-width and a margin) at `speed` [px/s].
inline double travelTime(double dist_px, double speed, double w) {
  const double d = dist_px - 0.5 * w - kFreeMarginPx;
  if (d <= 0.0) return 0.0;
  return speed > 0.0 ? d / speed : kInfTime;
}

/// Pixel-space distance: metric distance d along a direction whose metres per
/// pixel is g. g is bounded away from 0 so that a grazing view stays finite.
inline double toPx(double d, double g) { return d / std::max(g, 1e-12); }

/// (ru, rv): rates [m/s] at which the plane coordinates seen by the pixel change.
PlaneShade shadeChessboard(const ScenePlane& pl, double u, double v, const Vec2& ju, const Vec2& jv,
                           double ru, double rv, double w, bool want_edge) {
  PlaneShade out;
  const double W = pl.width, H = pl.height, sq = pl.square;
  const double uu = u + 0.5 * W, vv = v + 0.5 * H;
  // Pixels per metre along u and v (the inverse metres-per-pixel, bounded).
  const double pu = 1.0 / std::max(ju.norm(), 1e-12), pv = 1.0 / std::max(jv.norm(), 1e-12);
  const double inv_sq = 1.0 / sq;
  const double fi = std::floor(uu * inv_sq), fj = std::floor(vv * inv_sq);
  const long i = static_cast<long>(fi), j = static_cast<long>(fj);
  const double du = std::min(uu - fi * sq, (fi + 1.0) * sq - uu) * pu;  // [px]
  const double dv = std::min(vv - fj * sq, (fj + 1.0) * sq - vv) * pv;
  // Smoothed square waves in {-1, +1}: linear ramp of width w [px] across each line.
  const double k = 2.0 / w, inv_w = 1.0 / w;
  const double su = ((i & 1) ? -1.0 : 1.0) * std::min(1.0, k * du);
  const double sv = ((j & 1) ? -1.0 : 1.0) * std::min(1.0, k * dv);
  const double checker = 0.5 * (1.0 + su * sv);  // 1 on light squares ((i + j) even)
  out.intensity = pl.dark + (pl.light - pl.dark) * checker;
  const double inside = std::min(std::min(uu, W - uu) * pu, std::min(vv, H - vv) * pv);
  out.coverage = clamp01(0.5 + inside * inv_w);
  out.free_px = std::min(std::min(du, dv), std::abs(inside));
  // Each family of lines moves across the pixel at its own normal speed [px/s];
  // the board's border lines belong to the families (virtual lines outside the
  // board are nearer than the border, so the bound stays conservative).
  out.free_time =
      std::min(travelTime(du, std::abs(ru) * pu, w), travelTime(dv, std::abs(rv) * pv, w));
  if (want_edge) {
    const double gu = 1.0 / pu, gv = 1.0 / pv;
    const long iu = std::clamp(std::lround(uu / sq), 0L, static_cast<long>(pl.columns));
    const long jv2 = std::clamp(std::lround(vv / sq), 0L, static_cast<long>(pl.rows));
    const double out_v = std::max(0.0, std::max(-vv, vv - H));
    const double out_u = std::max(0.0, std::max(-uu, uu - W));
    const double d_vert = std::hypot(toPx(std::abs(uu - iu * sq), gu), toPx(out_v, gv));
    const double d_horz = std::hypot(toPx(std::abs(vv - jv2 * sq), gv), toPx(out_u, gu));
    if (d_vert <= d_horz) {
      out.edge = pl.edge_id_offset + static_cast<int>(iu);
      out.edge_px = d_vert;
    } else {
      out.edge = pl.edge_id_offset + pl.columns + 1 + static_cast<int>(jv2);
      out.edge_px = d_horz;
    }
  }
  return out;
}

/// Signed distance [px] of (u, v) to rectangle r (negative inside) and the side
/// (0: -u', 1: +u', 2: -v', 3: +v' in the rectangle's axes) nearest to it.
inline double rectDistance(const TextureRect& r, double u, double v, const Vec2& ju, const Vec2& jv,
                           int& side) {
  const double c = r.cos_a, s = r.sin_a;
  const double du = u - r.centre.x(), dv = v - r.centre.y();
  const double qx = c * du + s * dv, qy = -s * du + c * dv;
  const double gx = (c * ju + s * jv).norm(), gy = (-s * ju + c * jv).norm();
  const double dx = toPx(std::abs(qx) - r.half_u, gx), dy = toPx(std::abs(qy) - r.half_v, gy);
  if (dx > 0.0 || dy > 0.0) {
    const double ox = std::max(dx, 0.0), oy = std::max(dy, 0.0);
    side = ox >= oy ? (qx < 0 ? 0 : 1) : (qy < 0 ? 2 : 3);
    return std::hypot(ox, oy);
  }
  side = dx > dy ? (qx < 0 ? 0 : 1) : (qy < 0 ? 2 : 3);
  return std::max(dx, dy);
}

PlaneShade shadeRects(const ScenePlane& pl, double u, double v, const Vec2& ju, const Vec2& jv,
                      double ru, double rv, double w, bool want_edge) {
  PlaneShade out;
  const double W = pl.width, H = pl.height;
  const double gu = ju.norm(), gv = jv.norm();
  const double inside_u = toPx(0.5 * W - std::abs(u), gu),
               inside_v = toPx(0.5 * H - std::abs(v), gv);
  out.coverage = clamp01(0.5 + std::min(inside_u, inside_v) / w);
  // Shapes outside a cell's list lie > grid_margin away: keep their ramp inside it.
  const double gmax = std::max(gu, gv);
  const double w_shape = std::min(w, 2.0 * pl.grid_margin / std::max(gmax, 1e-12));
  const int n = pl.grid_n;
  const int ci = std::clamp(static_cast<int>(std::floor((u / W + 0.5) * n)), 0, n - 1);
  const int cj = std::clamp(static_cast<int>(std::floor((v / H + 0.5) * n)), 0, n - 1);
  const uint32_t* first = pl.cell_items.data() + pl.cell_start[cj * n + ci];
  const uint32_t* last = pl.cell_items.data() + pl.cell_start[cj * n + ci + 1];
  double I = pl.base;
  // Shapes not listed in this cell are > grid_margin [m] away; sqrt(gu^2 + gv^2)
  // bounds the metres per pixel in any direction.
  // Distance [m] from (u, v) to the border of its cell (0 outside the grid).
  const double cw = W / n, ch = H / n;
  const double cu = u + 0.5 * W - ci * cw, cv = v + 0.5 * H - cj * ch;
  const double to_border = std::max(0.0, std::min({cu, cw - cu, cv, ch - cv}));
  double free_px = std::min({(pl.grid_margin + to_border) / std::max(std::hypot(gu, gv), 1e-12),
                             std::abs(inside_u), std::abs(inside_v)});
  for (const uint32_t* it = first; it != last; ++it) {
    const TextureRect& r = pl.rects[*it];
    int side = 0;
    const double sd = rectDistance(r, u, v, ju, jv, side);
    const double a = clamp01(0.5 - sd / w_shape);
    I += a * (r.intensity - I);
    free_px = std::min(free_px, std::abs(sd));
  }
  out.free_px = free_px;
  {
    // Image velocity of the texture at the pixel: [ju; jv] d(pixel) = d(u, v).
    const double det = ju.x() * jv.y() - ju.y() * jv.x();
    if (std::abs(det) > 1e-300) {
      const double vx = (jv.y() * ru - ju.y() * rv) / det, vy = (-jv.x() * ru + ju.x() * rv) / det;
      out.free_time = travelTime(free_px, std::hypot(vx, vy), w);
    }
  }
  out.intensity = I;
  if (want_edge) {
    bool hidden = false;
    for (const uint32_t* it = last; it != first && !hidden;) {
      --it;
      int side = 0;
      const double sd = rectDistance(pl.rects[*it], u, v, ju, jv, side);
      if (std::abs(sd) < out.edge_px) {
        out.edge_px = std::abs(sd);
        out.edge = pl.edge_id_offset + 4 + 4 * static_cast<int>(*it) + side;
      }
      hidden = sd < -0.5 * w_shape;  // fully covered: the edges below cannot be seen
    }
    if (!hidden) {
      const double d[4] = {std::abs(toPx(u + 0.5 * W, gu)), std::abs(toPx(0.5 * W - u, gu)),
                           std::abs(toPx(v + 0.5 * H, gv)), std::abs(toPx(0.5 * H - v, gv))};
      for (int k = 0; k < 4; ++k)
        if (d[k] < out.edge_px) {
          out.edge_px = d[k];
          out.edge = pl.edge_id_offset + k;
        }
    }
  }
  return out;
}

Vec3 planePoint(const ScenePlane& pl, double u, double v) {
  return pl.T_world_plane.p + pl.T_world_plane.R.col(0) * u + pl.T_world_plane.R.col(1) * v;
}
}  // namespace

TextureKind parseTextureKind(const std::string& name) {
  if (name == "chessboard") return TextureKind::Chessboard;
  if (name == "rectangles") return TextureKind::Rectangles;
  if (name == "segments") return TextureKind::Segments;
  throw std::invalid_argument("unknown texture '" + name +
                              "' (expected chessboard, rectangles or segments)");
}

std::string toString(TextureKind kind) {
  switch (kind) {
    case TextureKind::Chessboard:
      return "chessboard";
    case TextureKind::Rectangles:
      return "rectangles";
    case TextureKind::Segments:
      return "segments";
  }
  return "chessboard";
}

int ScenePlane::edgeCount() const {
  return texture == TextureKind::Chessboard ? (columns + 1) + (rows + 1)
                                            : 4 + 4 * static_cast<int>(rects.size());
}

void ScenePlane::buildGrid() {
  if (texture == TextureKind::Chessboard) return;
  for (TextureRect& r : rects) {
    r.cos_a = std::cos(r.angle);
    r.sin_a = std::sin(r.angle);
  }
  grid_n = std::clamp(static_cast<int>(std::ceil(2.0 * std::sqrt(double(rects.size())))), 1, 64);
  const int n = grid_n;
  grid_margin = std::max(0.02 * std::min(width, height), 0.5 * std::min(width, height) / n);
  std::vector<std::vector<uint32_t>> cells(static_cast<size_t>(n) * n);
  for (size_t k = 0; k < rects.size(); ++k) {
    const TextureRect& r = rects[k];
    const double c = std::abs(std::cos(r.angle)), s = std::abs(std::sin(r.angle));
    const double ex = c * r.half_u + s * r.half_v + grid_margin;
    const double ey = s * r.half_u + c * r.half_v + grid_margin;
    auto cellOf = [n](double x) {
      return std::clamp(static_cast<int>(std::floor((x + 0.5) * n)), 0, n - 1);
    };
    const int i0 = cellOf((r.centre.x() - ex) / width), i1 = cellOf((r.centre.x() + ex) / width);
    const int j0 = cellOf((r.centre.y() - ey) / height), j1 = cellOf((r.centre.y() + ey) / height);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) cells[j * n + i].push_back(static_cast<uint32_t>(k));
  }
  cell_start.assign(cells.size() + 1, 0);
  cell_items.clear();
  for (size_t c = 0; c < cells.size(); ++c) {
    cell_start[c] = static_cast<uint32_t>(cell_items.size());
    cell_items.insert(cell_items.end(), cells[c].begin(), cells[c].end());
  }
  cell_start[cells.size()] = static_cast<uint32_t>(cell_items.size());
}

Scene Scene::build(const std::vector<PlaneSpec>& specs, double background, uint64_t seed) {
  if (specs.size() > static_cast<size_t>(kMaxPlanes))
    throw std::invalid_argument("at most 16 planes are supported");
  Scene scene;
  scene.background = static_cast<float>(background);
  int offset = 0;
  for (size_t p = 0; p < specs.size(); ++p) {
    const PlaneSpec& sp = specs[p];
    const std::string err = sp.validate();
    if (!err.empty()) throw std::invalid_argument("plane " + std::to_string(p) + ": " + err);
    ScenePlane pl;
    pl.texture = sp.texture;
    pl.T_world_plane.R = so3::exp(sp.rotation);
    pl.T_world_plane.p = sp.position;
    pl.edge_id_offset = offset;
    if (sp.texture == TextureKind::Chessboard) {
      pl.square = sp.square;
      pl.columns = sp.columns;
      pl.rows = sp.rows;
      pl.width = sp.columns * sp.square;
      pl.height = sp.rows * sp.square;
      pl.dark = static_cast<float>(sp.dark);
      pl.light = static_cast<float>(sp.light);
    } else {
      pl.width = sp.width;
      pl.height = sp.height;
      pl.base = static_cast<float>(sp.base);
      const uint64_t s = sp.seed >= 0 ? static_cast<uint64_t>(sp.seed)
                                      : seed * 0x9E3779B97F4A7C15ULL + 7919ULL * (p + 1);
      std::mt19937_64 rng(s);
      std::uniform_real_distribution<double> U(0.0, 1.0);
      auto lerp = [&](const Vec2& r) { return r.x() + (r.y() - r.x()) * U(rng); };
      for (int k = 0; k < sp.count; ++k) {
        TextureRect r;
        r.centre = Vec2((U(rng) - 0.5) * sp.width, (U(rng) - 0.5) * sp.height);
        if (sp.texture == TextureKind::Rectangles) {
          r.half_u = 0.5 * lerp(sp.size_range);
          r.half_v = 0.5 * lerp(sp.size_range);
          r.angle = sp.random_angle ? U(rng) * M_PI : 0.0;
        } else {
          r.half_u = 0.5 * lerp(sp.size_range);
          r.half_v = 0.5 * lerp(sp.width_range);
          r.angle = U(rng) * M_PI;
        }
        r.intensity = static_cast<float>(lerp(sp.intensity_range));
        pl.rects.push_back(r);
      }
      pl.buildGrid();
    }
    offset += pl.edgeCount();
    scene.planes.push_back(std::move(pl));
  }
  return scene;
}

int Scene::edgeCount() const {
  int n = 0;
  for (const auto& p : planes) n += p.edgeCount();
  return n;
}

std::vector<SceneEdge> Scene::edges() const {
  std::vector<SceneEdge> out;
  for (const ScenePlane& pl : planes) {
    const double W = pl.width, H = pl.height;
    int id = pl.edge_id_offset;
    if (pl.texture == TextureKind::Chessboard) {
      for (int i = 0; i <= pl.columns; ++i) {
        const double u = i * pl.square - 0.5 * W;
        out.push_back({id++, planePoint(pl, u, -0.5 * H), planePoint(pl, u, 0.5 * H)});
      }
      for (int j = 0; j <= pl.rows; ++j) {
        const double v = j * pl.square - 0.5 * H;
        out.push_back({id++, planePoint(pl, -0.5 * W, v), planePoint(pl, 0.5 * W, v)});
      }
      continue;
    }
    out.push_back({id++, planePoint(pl, -0.5 * W, -0.5 * H), planePoint(pl, -0.5 * W, 0.5 * H)});
    out.push_back({id++, planePoint(pl, 0.5 * W, -0.5 * H), planePoint(pl, 0.5 * W, 0.5 * H)});
    out.push_back({id++, planePoint(pl, -0.5 * W, -0.5 * H), planePoint(pl, 0.5 * W, -0.5 * H)});
    out.push_back({id++, planePoint(pl, -0.5 * W, 0.5 * H), planePoint(pl, 0.5 * W, 0.5 * H)});
    for (const TextureRect& r : pl.rects) {
      const double c = std::cos(r.angle), s = std::sin(r.angle);
      auto P = [&](double qx, double qy) {
        return planePoint(pl, r.centre.x() + c * qx - s * qy, r.centre.y() + s * qx + c * qy);
      };
      const double hx = r.half_u, hy = r.half_v;
      out.push_back({id++, P(-hx, -hy), P(-hx, hy)});
      out.push_back({id++, P(hx, -hy), P(hx, hy)});
      out.push_back({id++, P(-hx, -hy), P(hx, -hy)});
      out.push_back({id++, P(-hx, hy), P(hx, hy)});
    }
  }
  return out;
}

CameraPlane toCameraFrame(const ScenePlane& plane, const RigidPose& T_world_cam) {
  const Mat3 Rc = T_world_cam.R.transpose();
  CameraPlane c;
  c.a = Rc * plane.T_world_plane.R.col(0);
  c.b = Rc * plane.T_world_plane.R.col(1);
  c.n = Rc * plane.T_world_plane.R.col(2);
  const Vec3 o = Rc * (plane.T_world_plane.p - T_world_cam.p);
  c.n_o = c.n.dot(o);
  c.a_o = c.a.dot(o);
  c.b_o = c.b.dot(o);
  return c;
}

namespace {
/// Plane hit: depth s along d = (x, y, 1), plane coordinates and their pixel Jacobian rows.
inline bool hitPlane(const CameraPlane& cp, double x, double y, double fx, double fy, double& s,
                     double& u, double& v, Vec2& ju, Vec2& jv) {
  const double nd = cp.n.x() * x + cp.n.y() * y + cp.n.z();
  if (std::abs(nd) < 1e-12) return false;
  const double inv_nd = 1.0 / nd;
  s = cp.n_o * inv_nd;
  if (!(s > 1e-6)) return false;
  const double ad = cp.a.x() * x + cp.a.y() * y + cp.a.z();
  const double bd = cp.b.x() * x + cp.b.y() * y + cp.b.z();
  u = s * ad - cp.a_o;
  v = s * bd - cp.b_o;
  // d(s d)/dx = s (e_x - d n_x / (n . d)): metres per normalised unit, then per pixel.
  const double kx = cp.n.x() * inv_nd, ky = cp.n.y() * inv_nd;
  const double sx = s / fx, sy = s / fy;
  ju = Vec2(sx * (cp.a.x() - ad * kx), sy * (cp.a.y() - ad * ky));
  jv = Vec2(sx * (cp.b.x() - bd * kx), sy * (cp.b.y() - bd * ky));
  return true;
}
}  // namespace

/// Plane coordinates seen along bearing (x, y, 1); false when the plane is not in front.
inline bool planeUV(const CameraPlane& cp, double x, double y, double& u, double& v) {
  const double nd = cp.n.x() * x + cp.n.y() * y + cp.n.z();
  if (std::abs(nd) < 1e-12) return false;
  const double s = cp.n_o / nd;
  if (!(s > 1e-6)) return false;
  u = s * (cp.a.x() * x + cp.a.y() * y + cp.a.z()) - cp.a_o;
  v = s * (cp.b.x() * x + cp.b.y() * y + cp.b.z()) - cp.b_o;
  return true;
}

PixelSample shadePixel(const Scene& scene, const std::vector<CameraPlane>& cam_planes, double x,
                       double y, double fx, double fy, double smoothing_px, bool want_edge,
                       const std::vector<CameraPlane>* ahead, double ahead_dt) {
  PixelSample out;
  const double w = std::max(smoothing_px, 1e-3);
  const size_t np = cam_planes.size();
  const bool rates = ahead != nullptr && ahead->size() == np && ahead_dt > 0.0;
  // Rates [m/s] of the plane coordinates seen by the pixel; false: unknown.
  auto rateOf = [&](size_t k, double u, double v, double& ru, double& rv) {
    double u2, v2;
    if (!rates || !planeUV((*ahead)[k], x, y, u2, v2)) return false;
    ru = (u2 - u) / ahead_dt;
    rv = (v2 - v) / ahead_dt;
    return true;
  };
  if (np == 1) {  // the common case: no sorting, no compositing of several planes
    double s, u, v, ru = 0.0, rv = 0.0;
    Vec2 ju, jv;
    if (!hitPlane(cam_planes[0], x, y, fx, fy, s, u, v, ju, jv)) {
      out.intensity = scene.background;
      return out;
    }
    const bool known = rateOf(0, u, v, ru, rv);
    const ScenePlane& pl = scene.planes[0];
    const PlaneShade sh = pl.texture == TextureKind::Chessboard
                              ? shadeChessboard(pl, u, v, ju, jv, ru, rv, w, want_edge)
                              : shadeRects(pl, u, v, ju, jv, ru, rv, w, want_edge);
    out.intensity =
        static_cast<float>(sh.coverage * sh.intensity + (1.0 - sh.coverage) * scene.background);
    out.free_px = static_cast<float>(sh.free_px);
    out.free_time = known ? static_cast<float>(std::min(sh.free_time, 1e30)) : 0.0f;
    if (want_edge && sh.coverage > 0.0) {
      out.edge = sh.edge;
      out.edge_px = static_cast<float>(sh.edge_px);
    }
    return out;
  }
  // Several planes: composite front to back.
  struct Hit {
    double s, u, v;
    Vec2 ju, jv;
    size_t k;
  };
  Hit hits[kMaxPlanes];
  size_t nh = 0;
  bool missed = false;
  for (size_t k = 0; k < np && k < static_cast<size_t>(kMaxPlanes); ++k) {
    Hit h;
    h.k = k;
    if (hitPlane(cam_planes[k], x, y, fx, fy, h.s, h.u, h.v, h.ju, h.jv))
      hits[nh++] = h;
    else
      missed = true;
  }
  double free_px = missed ? 0.0 : 1e30;
  double free_time = missed ? 0.0 : 1e30;
  std::sort(hits, hits + nh, [](const Hit& a, const Hit& b) { return a.s < b.s; });
  double I = 0.0, T = 1.0;
  for (size_t i = 0; i < nh && T > 0.0; ++i) {
    const Hit& h = hits[i];
    const ScenePlane& pl = scene.planes[h.k];
    double ru = 0.0, rv = 0.0;
    const bool known = rateOf(h.k, h.u, h.v, ru, rv);
    const PlaneShade sh = pl.texture == TextureKind::Chessboard
                              ? shadeChessboard(pl, h.u, h.v, h.ju, h.jv, ru, rv, w, want_edge)
                              : shadeRects(pl, h.u, h.v, h.ju, h.jv, ru, rv, w, want_edge);
    if (want_edge && out.edge < 0 && sh.coverage > 0.0) {
      out.edge = sh.edge;
      out.edge_px = static_cast<float>(sh.edge_px);
    }
    I += T * sh.coverage * sh.intensity;
    T *= 1.0 - sh.coverage;
    free_px = std::min(free_px, sh.free_px);
    free_time = std::min(free_time, known ? sh.free_time : 0.0);
  }
  out.intensity = static_cast<float>(I + T * scene.background);
  out.free_px = static_cast<float>(free_px);
  out.free_time = static_cast<float>(free_time);
  return out;
}

int frontHit(const Scene& scene, const std::vector<CameraPlane>& cam_planes, double x, double y,
             const RigidPose& T_world_cam, Vec3& X_world) {
  int best = -1;
  double best_s = 1e300;
  for (size_t k = 0; k < cam_planes.size(); ++k) {
    double s, u, v;
    Vec2 ju, jv;
    if (!hitPlane(cam_planes[k], x, y, 1.0, 1.0, s, u, v, ju, jv)) continue;
    const ScenePlane& pl = scene.planes[k];
    if (std::abs(u) > 0.5 * pl.width || std::abs(v) > 0.5 * pl.height) continue;
    if (s < best_s) {
      best_s = s;
      best = static_cast<int>(k);
    }
  }
  if (best >= 0) X_world = T_world_cam.R * (Vec3(x, y, 1.0) * best_s) + T_world_cam.p;
  return best;
}

}  // namespace celc

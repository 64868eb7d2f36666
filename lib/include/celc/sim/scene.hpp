#pragma once
/// \file scene.hpp
/// Scenes for the rendering event simulator: textured planar patches whose
/// textures are made of straight edges, seen by a pinhole (+ distortion) camera.
///
/// A plane is given by its centre o and rotation R_world_plane (columns a, b, n):
/// a world point X lies on it when n . (X - o) = 0 and has plane coordinates
/// (u, v) = (a . (X - o), b . (X - o)) [m]. Its texture is defined on the
/// rectangle |u| <= width/2, |v| <= height/2; outside every plane the scene has
/// the constant `background` intensity. Intensities are linear radiance in [0, 1].
///
/// Anti-aliasing is analytic: across every edge the intensity ramps linearly
/// over `smoothing_px` pixels (the plane-to-image Jacobian converts metres on
/// the plane to pixels at each pixel), i.e. the box-filter coverage of a
/// straight edge by a pixel of that width.
///
/// Every straight edge has a scene-wide id (>= 0) and known 3D end points, so
/// each event can be labelled with the edge that triggered it.
#include <cstdint>
#include <string>
#include <vector>

#include "celc/core/types.hpp"

namespace celc {

/// A rigid pose T_a_b: x_a = R x_b + p.
struct RigidPose {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  RigidPose operator*(const RigidPose& o) const { return {R * o.R, R * o.p + p}; }
  RigidPose inverse() const { return {R.transpose(), -(R.transpose() * p)}; }
};

enum class TextureKind { Chessboard, Rectangles, Segments };
/// "chessboard" | "rectangles" | "segments"; throws std::invalid_argument otherwise.
TextureKind parseTextureKind(const std::string& name);
std::string toString(TextureKind kind);

/// A filled rectangle on a plane (plane coordinates, metres): centre, half
/// sides along its own axes (rotated by `angle` [rad] from the plane's u axis).
struct TextureRect {
  Vec2 centre = Vec2::Zero();
  double half_u = 0.05, half_v = 0.05;  ///< [m]
  double angle = 0.0;                   ///< [rad]
  float intensity = 0.5f;               ///< [0, 1]
  double cos_a = 1.0, sin_a = 0.0;      ///< cos/sin of angle (set by ScenePlane::buildGrid)
};

/// How a plane's texture is generated (the SCENE.yaml `planes:` entry).
struct PlaneSpec {
  TextureKind texture = TextureKind::Chessboard;
  Vec3 position = Vec3(0.0, 0.0, 2.0);  ///< plane centre in the world [m]
  Vec3 rotation = Vec3::Zero();         ///< axis-angle of R_world_plane [rad]
  // chessboard
  double square = 0.2;             ///< side of a square [m]
  int columns = 16, rows = 12;     ///< squares along u and v
  double dark = 0.2, light = 0.8;  ///< intensities [0, 1]
  // rectangles / segments
  double width = 3.0, height = 2.0;     ///< plane extent along u and v [m]
  double base = 0.5;                    ///< intensity of the plane under its shapes
  int count = 40;                       ///< number of shapes (<= 5000)
  Vec2 size_range = Vec2(0.05, 0.4);    ///< rectangles: side; segments: length [m]
  Vec2 width_range = Vec2(0.01, 0.03);  ///< segments: thickness [m]
  Vec2 intensity_range = Vec2(0.05, 0.95);
  bool random_angle = false;     ///< rectangles: rotate each by a uniform angle
  int64_t seed = -1;             ///< shape layout seed; < 0: derived from the scene seed
  std::string validate() const;  ///< empty when valid
};

/// One textured plane, ready to render.
struct ScenePlane {
  TextureKind texture = TextureKind::Chessboard;
  RigidPose T_world_plane;           ///< columns of R: u axis, v axis, normal
  double width = 1.0, height = 1.0;  ///< extent [m] (chessboard: columns*square, rows*square)
  double square = 0.1;
  int columns = 1, rows = 1;
  float dark = 0.2f, light = 0.8f, base = 0.5f;
  std::vector<TextureRect> rects;  ///< painted in order over `base`
  int edge_id_offset = 0;          ///< ids of this plane's edges start here
  int edgeCount() const;           ///< chessboard: (columns+1)+(rows+1); else 4 + 4*rects
  // Uniform grid over the plane listing the rects near each cell (built by buildGrid()).
  int grid_n = 0;
  double grid_margin = 0.0;          ///< [m] margin used for the cell lists
  std::vector<uint32_t> cell_start;  ///< grid_n*grid_n + 1 offsets into cell_items
  std::vector<uint32_t> cell_items;
  void buildGrid();  ///< also caches each rect's cos/sin
};

/// A straight edge of the scene: id and world end points [m].
struct SceneEdge {
  int id = 0;
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();
};

struct Scene {
  std::vector<ScenePlane> planes;
  float background = 0.5f;  ///< intensity seen where no plane is
  /// Builds the planes from their specs; random layouts use `seed` (or each spec's own seed).
  static Scene build(const std::vector<PlaneSpec>& specs, double background, uint64_t seed);
  std::vector<SceneEdge> edges() const;  ///< every edge with its world end points
  int edgeCount() const;
};

/// A plane expressed in the camera frame for one render: for a bearing d =
/// (x, y, 1) the hit depth is s = n_o / (n . d) and the plane coordinates
/// are u = s (a . d) - a_o, v = s (b . d) - b_o.
struct CameraPlane {
  Vec3 a, b, n;
  double n_o = 0.0, a_o = 0.0, b_o = 0.0;
};
CameraPlane toCameraFrame(const ScenePlane& plane, const RigidPose& T_world_cam);

/// What one pixel sees.
struct PixelSample {
  float intensity = 0.0f;  ///< [0, 1]
  int edge = -1;           ///< nearest visible edge id (when asked for), -1 if none
  float edge_px = 1e30f;   ///< its distance [px]
  /// Lower bound of the distance [px] from the pixel centre to any edge (0 when
  /// unknown): while edges move less than free_px - smoothing_px / 2 the
  /// pixel's intensity cannot change.
  float free_px = 0.0f;
  /// Lower bound of the time [s] before an edge comes within smoothing_px / 2
  /// + 0.25 px of the pixel if the texture keeps its current velocity at the
  /// pixel (chessboard: per family of lines, so lines sliding along themselves
  /// do not count); 0 when unknown (no `ahead` planes, plane not hit).
  float free_time = 0.0f;
};

/// Intensity (and optionally the nearest edge) seen along bearing d = (x, y, 1)
/// [normalised camera coordinates] given the planes in the camera frame.
/// fx, fy [px] convert the plane-to-image Jacobian into pixels. With `ahead`
/// (the same planes ahead_dt [s] later) it also bounds free_time.
PixelSample shadePixel(const Scene& scene, const std::vector<CameraPlane>& cam_planes, double x,
                       double y, double fx, double fy, double smoothing_px, bool want_edge,
                       const std::vector<CameraPlane>* ahead = nullptr, double ahead_dt = 0.0);

/// Front-most plane hit along bearing d: index and world point; -1 if none.
int frontHit(const Scene& scene, const std::vector<CameraPlane>& cam_planes, double x, double y,
             const RigidPose& T_world_cam, Vec3& X_world);

}  // namespace celc

#pragma once
/// \file peer_study.hpp
/// The peer study (`celc simulate --study peers`): every method, including the
/// CVPR 2024 N-point linear solver `npt`, on the peers' scene (sim/peer_scene.hpp),
/// beside the Cramér-Rao bound (eval/crlb.hpp).
///
/// Cells: the full factorial of the peers' grid is 4*4*4*3*3*2 = 1152 cells;
/// the study runs one-factor-at-a-time sweeps around a base cell (5 lines x
/// 200 events, V = 2 m/s, sigma = 1 px, no angular-velocity error, no
/// outliers) plus the full V x sigma grid at the base's other factors:
///   grid     V in {1, 2, 5, 16} m/s x sigma in {0, 0.5, 1, 2} px
///   omega    angular-velocity error {0, 2, 5, 10} deg/s
///   lines    {2, 5, 10}
///   events   {20, 100, 200, 500} per line
///   outliers {0, 0.1}
/// (25 distinct cells). Parallax ratio V*T/z_mean = V * 0.5 / 4 = 0.125, 0.25,
/// 0.625, 2. Trial i of a cell draws from a seed derived from (seed, the cell's
/// parameters, i) only: every method sees the same events, and the results do
/// not depend on the thread count or on the other cells.
#include <functional>
#include <string>
#include <vector>

#include "celc/config/config.hpp"
#include "celc/sim/peer_scene.hpp"

namespace celc {

struct PeerCell {
  std::string groups;             ///< the sweeps the cell belongs to, ';'-separated (base;grid;...)
  double speed = 2.0;             ///< V [m/s]
  double sigma_px = 1.0;          ///< event pixel noise [px]
  double omega_error_deg_s = 0.0; ///< [deg/s]
  int lines = 5;
  int events_per_line = 200;
  double outliers = 0.0;          ///< share
  double parallaxRatio(const PeerSceneOptions& base) const;  ///< V T / mean depth
  void apply(PeerSceneOptions& scene) const;
};

/// The study's cells, in output order.
std::vector<PeerCell> peerStudyCells();

/// The cell's key in the study's seeding (pipeline/study_engine.hpp): trial i
/// of a cell draws its scene from trialRng(seed, {peerCellKey(cell)}, i), then
/// the seed of its linear rows from the same generator.
std::uint32_t peerCellKey(const PeerCell& cell);

/// One CSV row: a cell and a method.
struct PeerCellResult {
  PeerCell cell;
  Method method = Method::Celc;
  int trials = 0, n_ok = 0;
  double phi_median_deg = 0, phi_mean_deg = 0;          ///< sign-aware
  double phi_median_agn_deg = 0, phi_mean_agn_deg = 0;  ///< sign-agnostic min(phi, 180 - phi)
  double share_above_5deg = 0;   ///< of ok trials, sign-agnostic phi > 5 deg
  double rms_agn_deg = 0;        ///< RMS of the sign-agnostic phi [deg]
  double crlb_rms_deg = 0;       ///< RMS over the same trials of the bound sqrt(trace C) [deg]
  double crlb_median_deg = 0;    ///< median over the same trials of the per-trial bound [deg]
  double ratio = 0;              ///< rms_agn_deg / crlb_rms_deg (NaN when the bound is 0)
  double time_median_us = 0;     ///< median solver time [us]
};

struct PeerStudyConfig {
  PeerSceneOptions scene;         ///< base scene (the cells override their factors)
  SolverOptions solver = SolverOptions::paper();  ///< the peers' study runs the paper's preset
  std::vector<Method> methods = paperMethods();
  int trials = 200;
  std::uint64_t seed = 1;
  std::string validate() const;
};
/// PeerStudyConfig's own scalar fields with their ranges (core/fields.hpp);
/// the scene and the solver have their own.
void describe(FieldVisitor& v, PeerStudyConfig& config);

/// Runs the cells with `threads` workers (0 = all cores).
std::vector<PeerCellResult> runPeerStudy(const std::vector<PeerCell>& cells,
                                         const PeerStudyConfig& config, int threads,
                                         const std::function<void(int, int)>& progress = {});

std::string peerCsvHeader();
std::string peerCsvRow(const PeerCellResult& r, const PeerSceneOptions& base);

}  // namespace celc
